//! Sparse force Jacobians for implicit methods: 3×3 blocks per spring pair and per particle.

use super::parallel::{
    each_particle, Incidence, OWNS_BOTH, OWNS_FIRST, PARALLEL_MIN_SPRINGS, PARTICLE_CHUNK,
};
use super::state::Vec3;
use nalgebra::Matrix3;
use rayon::prelude::*;
use std::sync::Arc;

/// ∂f/∂x and ∂f/∂v in block form.
///
/// For pair `s` joining particles `a = pairs[s][0]`, `b = pairs[s][1]`, `kx[s]` is
/// ∂f_a/∂x_b (= ∂f_b/∂x_a), and ∂f_a/∂x_a = ∂f_b/∂x_b = `-kx[s]`; likewise `kv` for velocities.
/// `diag_x`/`diag_v` hold extra per-particle blocks (drag, penalty contacts). Pair blocks must
/// be symmetric (a spring's are): the Newton matrix keeps their upper triangles ([`Sym3`]).
#[derive(Debug, Clone)]
pub struct Jacobian {
    /// Particle pairs, one per spring, in spring order.
    pub pairs: Vec<[u32; 2]>,
    /// Position blocks per pair.
    pub kx: Vec<Matrix3<f64>>,
    /// Velocity blocks per pair.
    pub kv: Vec<Matrix3<f64>>,
    /// Position blocks per particle.
    pub diag_x: Vec<Matrix3<f64>>,
    /// Velocity blocks per particle.
    pub diag_v: Vec<Matrix3<f64>>,
    /// Fraction (0…1) of the indefinite geometric stiffness of compressed springs that terms
    /// drop: 0 is the exact Jacobian, 1 fills positive semi-definite blocks only, so the
    /// Newton matrix is SPD.
    pub clamp: f64,
    /// Levenberg–Marquardt shift μ: the Newton matrix's mass term is (1 + μ) M, so that
    /// M(1 + μ) − h ∂f/∂v − h² ∂f/∂x is positive definite where the unshifted one is not.
    pub shift: f64,
    /// Per-pair Newton blocks h·kv + h²·kx, filled by [`Jacobian::prepare_newton`]; symmetric
    /// (a spring's blocks are), so stored as upper triangles: the product CG takes most often
    /// reads two thirds of the bytes.
    newton_pair: Vec<Sym3>,
    /// Per-particle Newton blocks m I − h·diag_v − h²·diag_x (identity for fixed particles).
    newton_self: Vec<Matrix3<f64>>,
    /// Chunk lists of the pairs for the parallel owner-computes products of large systems
    /// (as for spring forces: bit-identical to the serial loop whatever the thread count).
    owners: Option<Arc<Incidence>>,
}

impl Jacobian {
    /// An all-zero Jacobian with the given pair topology over `n` particles (building the
    /// parallel chunk lists itself when the pairs are many).
    pub fn new(n: usize, pairs: Vec<[u32; 2]>) -> Self {
        let owners = if pairs.len() >= PARALLEL_MIN_SPRINGS {
            let (i, j): (Vec<u32>, Vec<u32>) = pairs.iter().map(|p| (p[0], p[1])).unzip();
            Incidence::build(&i, &j, n).map(Arc::new)
        } else {
            None
        };
        Self::with_owners(n, pairs, owners)
    }

    /// An all-zero Jacobian over `n` particles whose pairs are walked in parallel through
    /// `owners` (chunk lists built for exactly these pairs, e.g. the springs' own), or serially
    /// when `None`.
    pub fn with_owners(n: usize, pairs: Vec<[u32; 2]>, owners: Option<Arc<Incidence>>) -> Self {
        let m = pairs.len();
        Jacobian {
            pairs,
            kx: vec![Matrix3::zeros(); m],
            kv: vec![Matrix3::zeros(); m],
            diag_x: vec![Matrix3::zeros(); n],
            diag_v: vec![Matrix3::zeros(); n],
            clamp: 0.0,
            shift: 0.0,
            newton_pair: vec![Sym3::default(); m],
            newton_self: vec![Matrix3::zeros(); n],
            owners,
        }
    }
    /// Resets every block to zero, keeping the topology and storage.
    pub fn clear(&mut self) {
        self.kx
            .iter_mut()
            .chain(self.kv.iter_mut())
            .for_each(|b| *b = Matrix3::zeros());
        self.diag_x
            .iter_mut()
            .chain(self.diag_v.iter_mut())
            .for_each(|b| *b = Matrix3::zeros());
    }
    /// Sets pair `s`'s blocks.
    pub fn set_pair(&mut self, s: usize, kx: Matrix3<f64>, kv: Matrix3<f64>) {
        self.kx[s] = kx;
        self.kv[s] = kv;
    }
    /// Precomputes the blocks of the backward-Euler Newton matrix M − h ∂f/∂v − h² ∂f/∂x for
    /// step `h`, so that each matrix-vector product costs one 3×3 product per pair and particle.
    pub fn prepare_newton(&mut self, mass: &[f64], free: &[bool], h: f64) {
        let (kv, kx) = (&self.kv, &self.kx);
        let pair = |s: usize, out: &mut Sym3| *out = Sym3::upper(&(kv[s] * h + kx[s] * (h * h)));
        if self.owners.is_some() {
            self.newton_pair
                .par_iter_mut()
                .enumerate()
                .for_each(|(s, o)| pair(s, o));
        } else {
            self.newton_pair
                .iter_mut()
                .enumerate()
                .for_each(|(s, o)| pair(s, o));
        }
        let (dv, dx) = (&self.diag_v, &self.diag_x);
        let grow = 1.0 + self.shift;
        each_particle(&mut self.newton_self, |i, o| {
            *o = if free[i] {
                Matrix3::identity() * (mass[i] * grow) - dv[i] * h - dx[i] * (h * h)
            } else {
                Matrix3::identity()
            };
        });
    }

    /// y = A p for the Newton matrix A prepared by [`Jacobian::prepare_newton`]. Rows of fixed
    /// particles are left as p and never coupled.
    pub fn newton_matvec(&self, free: &[bool], p: &[Vec3], y: &mut [Vec3]) {
        let pair = |s: usize, a: usize, b: usize, ya: Option<&mut Vec3>, yb: Option<&mut Vec3>| {
            let q = self.newton_pair[s].mul(&(p[b] - p[a]));
            if let Some(ya) = ya.filter(|_| free[a]) {
                *ya -= q;
            }
            if let Some(yb) = yb.filter(|_| free[b]) {
                *yb += q;
            }
        };
        if !self.owner_pass(y, |i| self.newton_self[i] * p[i], pair) {
            // Serial: the same updates in the same order, without the chunk bookkeeping.
            for i in 0..p.len() {
                y[i] = self.newton_self[i] * p[i];
            }
            self.newton_pairs_serial(free, p, y);
        }
    }

    /// Applies `update(i, &mut p[i])` to every particle, then y = A p as
    /// [`Jacobian::newton_matvec`] does; on the serial path within the product's own pass over
    /// the particles, so that an iteration updating p just before its product (CG's
    /// p = z + βp) makes one pass fewer. The same bits as the update followed by the product.
    pub fn newton_matvec_updated(
        &self,
        free: &[bool],
        p: &mut [Vec3],
        y: &mut [Vec3],
        update: impl Fn(usize, &mut Vec3) + Sync,
    ) {
        if self.owners_for(y.len()).is_some() {
            each_particle(p, update);
            self.newton_matvec(free, p, y);
            return;
        }
        for i in 0..p.len() {
            update(i, &mut p[i]);
            y[i] = self.newton_self[i] * p[i];
        }
        self.newton_pairs_serial(free, p, y);
    }

    /// The pairs' part of the serial Newton product: y += the pair blocks' couplings, in pair
    /// order.
    fn newton_pairs_serial(&self, free: &[bool], p: &[Vec3], y: &mut [Vec3]) {
        for (s, pr) in self.pairs.iter().enumerate() {
            let (a, b) = (pr[0] as usize, pr[1] as usize);
            let q = self.newton_pair[s].mul(&(p[b] - p[a]));
            if free[a] {
                y[a] -= q;
            }
            if free[b] {
                y[b] += q;
            }
        }
    }

    /// y = (∂f/∂x) p on the free particles' rows (fixed rows are zero), as filled (with the
    /// current [`Jacobian::clamp`]): the position part of a linearisation, which linearly
    /// implicit Euler needs on its right-hand side. Bit-identical for any thread count.
    pub fn position_matvec(&self, free: &[bool], p: &[Vec3], y: &mut [Vec3]) {
        let pair = |s: usize, a: usize, b: usize, ya: Option<&mut Vec3>, yb: Option<&mut Vec3>| {
            let q = self.kx[s] * (p[b] - p[a]);
            if let Some(ya) = ya.filter(|_| free[a]) {
                *ya += q;
            }
            if let Some(yb) = yb.filter(|_| free[b]) {
                *yb -= q;
            }
        };
        let own = |i: usize| {
            if free[i] {
                self.diag_x[i] * p[i]
            } else {
                Vec3::zeros()
            }
        };
        if !self.owner_pass(y, own, pair) {
            for i in 0..p.len() {
                y[i] = own(i);
            }
            for (s, pr) in self.pairs.iter().enumerate() {
                let (a, b) = (pr[0] as usize, pr[1] as usize);
                let q = self.kx[s] * (p[b] - p[a]);
                if free[a] {
                    y[a] += q;
                }
                if free[b] {
                    y[b] -= q;
                }
            }
        }
    }

    /// For large systems, in parallel over the owning particle chunks: `out[i] = init(i)` for
    /// the chunk's particles, then for every pair `s` (a, b) touching the chunk, in pair order,
    /// `pair(s, a, b, oa, ob)` with `Some` for the ends the chunk owns. Every particle sees
    /// the updates the serial loop makes, in the same order, so results are bit-identical to it
    /// whatever the thread count. Returns false (doing nothing) for small systems.
    /// The owner lists a pass over `n` particles runs in parallel by: `None` for small systems
    /// (or lists of another size), whose passes run serially.
    fn owners_for(&self, n: usize) -> Option<&Incidence> {
        self.owners.as_deref().filter(|inc| inc.particles == n)
    }

    fn owner_pass<T: Send>(
        &self,
        out: &mut [T],
        init: impl Fn(usize) -> T + Sync,
        pair: impl Fn(usize, usize, usize, Option<&mut T>, Option<&mut T>) + Sync,
    ) -> bool {
        let Some(inc) = self.owners_for(out.len()) else {
            return false;
        };
        out.par_chunks_mut(PARTICLE_CHUNK)
            .enumerate()
            .for_each(|(c, oc)| {
                let base = c * PARTICLE_CHUNK;
                for (k, o) in oc.iter_mut().enumerate() {
                    *o = init(base + k);
                }
                for &e in inc.chunk(c) {
                    let s = (e >> 2) as usize;
                    let (a, b) = (self.pairs[s][0] as usize, self.pairs[s][1] as usize);
                    match e & OWNS_BOTH {
                        OWNS_BOTH if a == b => {
                            // A pair on one particle: its two ends in turn, as the serial loop.
                            pair(s, a, b, Some(&mut oc[a - base]), None);
                            pair(s, a, b, None, Some(&mut oc[b - base]));
                        }
                        OWNS_BOTH => {
                            let (lo, hi) = (a.min(b) - base, a.max(b) - base);
                            let (x, y) = oc.split_at_mut(hi);
                            let (oa, ob) = if a < b {
                                (&mut x[lo], &mut y[0])
                            } else {
                                (&mut y[0], &mut x[lo])
                            };
                            pair(s, a, b, Some(oa), Some(ob));
                        }
                        OWNS_FIRST => pair(s, a, b, Some(&mut oc[a - base]), None),
                        _ => pair(s, a, b, None, Some(&mut oc[b - base])),
                    }
                }
            });
        true
    }

    /// The prepared Newton matrix's blocks (per pair h·kv + h²·kx as upper triangles, per
    /// particle m I − h·diag_v − h²·diag_x), for assembling it into a sparse matrix: pair `s`
    /// (a, b) adds its block to the diagonal blocks of its free ends and its negative to (a, b)
    /// and (b, a) when both are free, as [`Jacobian::newton_matvec`] applies it.
    pub fn newton_blocks(&self) -> (&[Sym3], &[Matrix3<f64>]) {
        (&self.newton_pair, &self.newton_self)
    }

    /// The 3×3 diagonal blocks of the prepared Newton matrix, for a block-Jacobi preconditioner.
    pub fn newton_diagonal(&self, free: &[bool], out: &mut [Matrix3<f64>]) {
        let pair = |s: usize,
                    a: usize,
                    b: usize,
                    oa: Option<&mut Matrix3<f64>>,
                    ob: Option<&mut Matrix3<f64>>| {
            if let Some(oa) = oa.filter(|_| free[a]) {
                *oa += self.newton_pair[s].full();
            }
            if let Some(ob) = ob.filter(|_| free[b]) {
                *ob += self.newton_pair[s].full();
            }
        };
        if !self.owner_pass(out, |i| self.newton_self[i], pair) {
            out.copy_from_slice(&self.newton_self);
            for (s, pr) in self.pairs.iter().enumerate() {
                for &q in pr {
                    if free[q as usize] {
                        out[q as usize] += self.newton_pair[s].full();
                    }
                }
            }
        }
    }
}

/// A symmetric 3×3 block stored as its upper triangle (xx, xy, xz, yy, yz, zz).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Sym3([f64; 6]);

impl Sym3 {
    /// The upper triangle of `m` (its lower one must mirror it, which debug builds check).
    pub fn upper(m: &Matrix3<f64>) -> Self {
        debug_assert!(
            m[(1, 0)] == m[(0, 1)] && m[(2, 0)] == m[(0, 2)] && m[(2, 1)] == m[(1, 2)],
            "a pair block of the Newton matrix must be symmetric: {m}"
        );
        Sym3([
            m[(0, 0)],
            m[(0, 1)],
            m[(0, 2)],
            m[(1, 1)],
            m[(1, 2)],
            m[(2, 2)],
        ])
    }

    /// The full block.
    pub fn full(&self) -> Matrix3<f64> {
        let [xx, xy, xz, yy, yz, zz] = self.0;
        Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz)
    }

    /// The product with `v`, each row summed in column order as nalgebra's product of the
    /// full block does, so the two give the same bits.
    #[inline(always)]
    pub fn mul(&self, v: &Vec3) -> Vec3 {
        let [xx, xy, xz, yy, yz, zz] = self.0;
        Vec3::new(
            xx * v[0] + xy * v[1] + xz * v[2],
            xy * v[0] + yy * v[1] + yz * v[2],
            xz * v[0] + yz * v[1] + zz * v[2],
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Oracle: nalgebra's product of the full symmetric block, which the packed product must
    /// match bit for bit (the Newton matrix's products are bit-identical to the full blocks').
    #[test]
    fn a_packed_symmetric_block_multiplies_as_the_full_block() {
        let n = Vec3::new(0.3, -0.8, 0.52).normalize();
        let m = Matrix3::identity() * 0.37 + n * n.transpose() * 1.9e3;
        let packed = Sym3::upper(&m);
        assert_eq!(packed.full(), m);
        for v in [Vec3::new(1.0, 2.0, 3.0), Vec3::new(-0.1, 1e-7, 4.2e3), n] {
            let (want, got) = (m * v, packed.mul(&v));
            for d in 0..3 {
                assert_eq!(want[d].to_bits(), got[d].to_bits());
            }
        }
    }
}
