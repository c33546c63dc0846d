//! Block incomplete Cholesky IC(0) of the Newton matrix A = M − h ∂f/∂v − h² ∂f/∂x, on its
//! 3×3-block pattern: L Lᵀ ≈ A with L lower block-triangular, nonzero only where A's lower
//! triangle has a block (the particles and the springs between them; zero fill), its diagonal
//! blocks lower-triangular 3×3 Cholesky factors (Meijerink & van der Vorst, Math. Comp. 31,
//! 1977, in block form). It preconditions CG ([`super::cg::Precond::Ic0`]).
//!
//! Particles are taken in their natural order (the cloth's row-major order). A fixed particle
//! keeps an identity block and no coupling, as in CG. IC(0) exists for M-matrices but not
//! for every SPD matrix; where a pivot block is not positive definite the factorisation is
//! redone on A + α·blockdiag(A) with α doubling from [`FIRST_SHIFT`] (Manteuffel, Math. Comp.
//! 34, 1980), which exists for α large enough since A's diagonal blocks are SPD.
//!
//! The pattern and the index lists of the numeric factorisation depend on the spring
//! topology only: they are built once per topology, and each refactorisation is numeric only,
//! into storage sized once, so a step does not allocate. Everything runs sequentially in a
//! fixed order: the factor and every solve give the same bits whatever the thread count.

use super::pattern::{couples, neighbours, Topology};
use crate::model::{Jacobian, Vec3};
use nalgebra::Matrix3;

/// First Manteuffel shift α tried when the unshifted IC(0) meets a non-SPD pivot block.
pub(super) const FIRST_SHIFT: f64 = 1e-3;
/// Shifts tried (α doubling) before giving up on the coupling: past 2⁴⁰·10⁻³ the factor is
/// block Jacobi to rounding anyway.
const MAX_SHIFTS: u32 = 40;

/// A block IC(0) factor of the Newton matrix with its symbolic structure.
#[derive(Debug, Default)]
pub(super) struct Ic0 {
    topo: Topology,
    /// Strictly lower blocks of row (particle) i: `row_ptr[i]..row_ptr[i + 1]`, columns
    /// ascending in `col`.
    row_ptr: Vec<u32>,
    col: Vec<u32>,
    /// Per pair: index of its off-diagonal block, or `u32::MAX` when an end is fixed or the
    /// pair joins a particle to itself (no coupling).
    pair_slot: Vec<u32>,
    /// For the off-diagonal block e = (i, k): `upd[upd_ptr[e]..upd_ptr[e + 1]]` lists the
    /// pairs of blocks ((i, j), (k, j)), j < k, both in the pattern, whose product L_ij L_kjᵀ
    /// the block's elimination subtracts.
    upd_ptr: Vec<u32>,
    upd: Vec<(u32, u32)>,
    /// A's strictly lower blocks and diagonal blocks as last assembled.
    a: Vec<Matrix3<f64>>,
    a_diag: Vec<Matrix3<f64>>,
    /// L's strictly lower blocks and the inverses of its diagonal blocks.
    l: Vec<Matrix3<f64>>,
    d_inv: Vec<Matrix3<f64>>,
    /// The Manteuffel shift α of the last factorisation (0: none needed).
    pub(super) shift: f64,
    /// Numeric factorisations so far (each Manteuffel retry of one counts apart).
    pub(super) factorizations: u64,
}

impl Ic0 {
    /// Builds the pattern and the elimination lists when the topology differs from the last
    /// one (only then does it allocate).
    fn ensure_pattern(&mut self, jac: &Jacobian, free: &[bool]) {
        if !self.row_ptr.is_empty() && self.topo.is(jac, free) {
            return;
        }
        let n = free.len();
        self.topo = Topology::of(jac, free);
        // Neighbours j < i of each particle i: the columns of row i's lower blocks.
        let lower = neighbours(jac, free, false);
        self.row_ptr.clear();
        self.col.clear();
        self.row_ptr.push(0);
        for row in &lower {
            self.col.extend_from_slice(row);
            self.row_ptr.push(self.col.len() as u32);
        }
        self.pair_slot = jac
            .pairs
            .iter()
            .map(|&[a, b]| {
                if !couples(free, a, b) {
                    return u32::MAX;
                }
                let (hi, lo) = (a.max(b) as usize, a.min(b));
                let k = lower[hi].binary_search(&lo).expect("listed");
                self.row_ptr[hi] + k as u32
            })
            .collect();
        // Elimination lists: for e = (i, k), the j < k in both row i and row k (a merge of
        // the two sorted rows).
        self.upd_ptr.clear();
        self.upd.clear();
        self.upd_ptr.push(0);
        for i in 0..n {
            let ri = self.row_ptr[i] as usize..self.row_ptr[i + 1] as usize;
            for e in ri.clone() {
                let k = self.col[e] as usize;
                let rk = self.row_ptr[k] as usize..self.row_ptr[k + 1] as usize;
                let (mut p, mut q) = (ri.start, rk.start);
                while p < e && q < rk.end {
                    match self.col[p].cmp(&self.col[q]) {
                        std::cmp::Ordering::Less => p += 1,
                        std::cmp::Ordering::Greater => q += 1,
                        std::cmp::Ordering::Equal => {
                            self.upd.push((p as u32, q as u32));
                            p += 1;
                            q += 1;
                        }
                    }
                }
                self.upd_ptr.push(self.upd.len() as u32);
            }
        }
        let nnz = self.col.len();
        self.a = vec![Matrix3::zeros(); nnz];
        self.l = vec![Matrix3::zeros(); nnz];
        self.a_diag = vec![Matrix3::zeros(); n];
        self.d_inv = vec![Matrix3::zeros(); n];
    }

    /// Assembles the Newton matrix prepared in `jac` (see [`Jacobian::prepare_newton`]; it
    /// should be SPD, e.g. clamped) and factors it, shifted if need be (module docs).
    pub(super) fn factor(&mut self, jac: &Jacobian, free: &[bool]) {
        self.ensure_pattern(jac, free);
        jac.newton_diagonal(free, &mut self.a_diag);
        for (d, &f) in self.a_diag.iter_mut().zip(free) {
            if !f {
                *d = Matrix3::identity();
            }
        }
        self.a.iter_mut().for_each(|b| *b = Matrix3::zeros());
        let (pair_blocks, _) = jac.newton_blocks();
        for (&slot, b) in self.pair_slot.iter().zip(pair_blocks) {
            if slot != u32::MAX {
                self.a[slot as usize] -= b.full();
            }
        }
        let mut alpha = 0.0;
        for _ in 0..MAX_SHIFTS {
            if self.factor_shifted(alpha) {
                self.shift = alpha;
                return;
            }
            alpha = if alpha == 0.0 {
                FIRST_SHIFT
            } else {
                2.0 * alpha
            };
        }
        // Not reached for an SPD matrix: block Jacobi on the SPD parts of the diagonal.
        self.shift = f64::INFINITY;
        self.l.iter_mut().for_each(|b| *b = Matrix3::zeros());
        for (di, a) in self.d_inv.iter_mut().zip(&self.a_diag) {
            *di = a
                .cholesky()
                .and_then(|c| c.l().try_inverse())
                .unwrap_or_else(Matrix3::identity);
        }
    }

    /// IC(0) of A + α·blockdiag(A), row by row; false on a non-SPD pivot block.
    fn factor_shifted(&mut self, alpha: f64) -> bool {
        self.factorizations += 1;
        for i in 0..self.a_diag.len() {
            let row = self.row_ptr[i] as usize..self.row_ptr[i + 1] as usize;
            let mut d = self.a_diag[i] * (1.0 + alpha);
            for e in row {
                // L_ik L_kkᵀ = A_ik − Σ_j L_ij L_kjᵀ over the pattern's j < k.
                let mut s = self.a[e];
                let u = self.upd_ptr[e] as usize..self.upd_ptr[e + 1] as usize;
                for &(ij, kj) in &self.upd[u] {
                    s -= self.l[ij as usize] * self.l[kj as usize].transpose();
                }
                let lik = s * self.d_inv[self.col[e] as usize].transpose();
                d -= lik * lik.transpose();
                self.l[e] = lik;
            }
            let Some(c) = d.cholesky() else {
                return false;
            };
            let Some(inv) = c.l().try_inverse() else {
                return false;
            };
            self.d_inv[i] = inv;
        }
        true
    }

    /// z = (L Lᵀ)⁻¹ r: a forward and a backward block substitution (fixed particles' rows of
    /// `r` are ignored: zero in z).
    pub(super) fn solve(&self, free: &[bool], r: &[Vec3], z: &mut [Vec3]) {
        for i in 0..r.len() {
            if !free[i] {
                z[i] = Vec3::zeros();
                continue;
            }
            let mut s = r[i];
            for e in self.row_ptr[i] as usize..self.row_ptr[i + 1] as usize {
                s -= self.l[e] * z[self.col[e] as usize];
            }
            z[i] = self.d_inv[i] * s;
        }
        for i in (0..r.len()).rev() {
            if !free[i] {
                continue;
            }
            let zi = self.d_inv[i].tr_mul(&z[i]);
            z[i] = zi;
            for e in self.row_ptr[i] as usize..self.row_ptr[i + 1] as usize {
                z[self.col[e] as usize] -= self.l[e].tr_mul(&zi);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    //! Oracles: (1) on a tree-shaped block graph elimination creates no fill, so IC(0) is the
    //! exact Cholesky factor and its solve must equal nalgebra's dense Cholesky solve of the
    //! Newton matrix (assembled column by column from the matrix-free product CG uses) to
    //! rounding; (2) on the crumpled cloth (fill dropped), CG preconditioned by it must reach
    //! the dense solve of the clamped system to CG tolerance, and P = L Lᵀ must be SPD
    //! (rᵀ P⁻¹ r > 0).
    use super::super::cg::tests::{crumpled, dense_newton as dense, flat};
    use super::super::cg::{Cg, CgOutcome, CgStop, Precond};
    use super::super::ImplicitSettings;
    use super::*;

    /// A pseudo-random vector field (a fixed LCG: the test's bits do not depend on anything).
    fn field(n: usize, seed: u64) -> Vec<Vec3> {
        let mut s = seed;
        let mut next = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        (0..n).map(|_| Vec3::new(next(), next(), next())).collect()
    }

    #[test]
    fn ic0_on_a_tree_is_the_exact_cholesky_factor() {
        // A branching tree over 12 particles, a chain 0-1-…-8 and a branch 9-10 both hanging
        // from 11, each particle's parent of higher index (so natural order eliminates leaves
        // first: no fill); pairs shuffled and in both orientations, one pair doubled (two
        // springs), particle 0 fixed; SPD blocks G Gᵀ so the Newton matrix M + (Laplacian of
        // the pair blocks) is SPD.
        let n = 12;
        let mut pairs: Vec<[u32; 2]> = vec![
            [5, 4],
            [0, 1],
            [11, 8],
            [2, 1],
            [6, 7],
            [3, 2],
            [10, 9],
            [4, 3],
            [7, 8],
            [11, 10],
            [5, 6],
        ];
        pairs.push([6, 5]);
        let mut jac = Jacobian::new(n, pairs.clone());
        let g = field(3 * pairs.len(), 7);
        for s in 0..pairs.len() {
            let m = Matrix3::from_columns(&[g[3 * s], g[3 * s + 1], g[3 * s + 2]]);
            let k = m * m.transpose() * 400.0;
            jac.set_pair(s, k * 0.5, k * 0.01);
        }
        let mut free = vec![true; n];
        free[0] = false;
        let mass = vec![1e-3; n];
        jac.prepare_newton(&mass, &free, 1.0 / 60.0);
        let dofs: Vec<usize> = (0..3 * n).filter(|&d| free[d / 3]).collect();
        let a = dense(&jac, &free, &dofs);
        let mut ic = Ic0::default();
        ic.factor(&jac, &free);
        assert_eq!(ic.shift, 0.0);
        let r = field(n, 3);
        let mut z = vec![Vec3::zeros(); n];
        ic.solve(&free, &r, &mut z);
        let want = a.cholesky().expect("SPD").solve(&flat(&r, &dofs));
        let got = flat(&z, &dofs);
        assert!(
            (&got - &want).amax() <= 1e-12 * want.amax(),
            "{}",
            (&got - &want).amax() / want.amax()
        );
        assert_eq!(z[0], Vec3::zeros(), "a fixed particle's update is zero");
    }

    #[test]
    fn ic0_preconditioned_cg_solves_the_clamped_crumpled_cloth() {
        let h = 1.0 / 60.0;
        let (sys, jac, a, dofs) = crumpled(h, 1.0);
        let n = sys.len();
        let mut ic = Ic0::default();
        ic.factor(&jac, &sys.free);
        // P = L Lᵀ is SPD: rᵀ P⁻¹ r > 0 for any r nonzero on the free particles.
        let mut z = vec![Vec3::zeros(); n];
        for seed in 0..20 {
            let r = field(n, seed);
            ic.solve(&sys.free, &r, &mut z);
            let rz = flat(&r, &dofs).dot(&flat(&z, &dofs));
            assert!(rz > 0.0, "seed {seed}: rᵀz = {rz}");
        }
        let b: Vec<Vec3> = field(n, 99).iter().map(|v| v * 1e-3).collect();
        let want = a.clone().cholesky().expect("SPD").solve(&flat(&b, &dofs));
        let set = ImplicitSettings {
            cg_tol: 1e-12,
            ..ImplicitSettings::default()
        };
        let run = |pre: Precond<'_>| {
            let mut x = vec![Vec3::zeros(); n];
            let stop = CgStop {
                max_it: 500,
                rel_tol: set.cg_tol,
                abs_tol2: 0.0,
            };
            let out = Cg::default().solve(&jac, &sys, &b, &mut x, pre, stop);
            let CgOutcome::Converged(it) = out else {
                panic!("CG did not converge");
            };
            (it, flat(&x, &dofs))
        };
        let (it_ic, x) = run(Precond::Ic0(&ic));
        assert!(
            (&x - &want).amax() <= 1e-9 * want.amax(),
            "{}",
            (&x - &want).amax() / want.amax()
        );
        // Not an oracle, a sanity check: IC(0) keeps more of A than its diagonal blocks.
        let (it_bj, _) = run(Precond::BlockJacobi);
        assert!(it_ic < it_bj, "IC(0) {it_ic} vs block Jacobi {it_bj}");
    }
}
