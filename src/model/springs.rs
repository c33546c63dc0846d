//! Springs with optional axial dampers, stored as flat arrays (structure of arrays).
//!
//! The force law of every spring is `f = k_eff (|d| - l0)` along `d = x_j - x_i`, where
//! `k_eff` is `k` for Hooke springs and `k / l0` for strain springs (precomputed at build).
//!
//! Coincident endpoints (`|d| = 0`, documented fallback): the direction is undefined, so the
//! force is taken as `k_eff d`, which is the zero vector there; the damper is skipped and the
//! Jacobian block is `k_eff I` (isotropic). No NaN can arise from a zero-length spring, and a
//! zero rest length (`l0 = 0`) is the well-defined linear spring `f = k_eff d` everywhere.
//!
//! Large spring sets (at least [`PARALLEL_MIN_SPRINGS`]) are evaluated in parallel by
//! [`super::parallel`]; the result is bit-identical to the serial loop whatever the thread count.

use super::jacobian::Jacobian;
use super::parallel::{
    sum_partials, Incidence, ScratchPool, OWNS_BOTH, OWNS_FIRST, PARALLEL_MIN_SPRINGS,
    PARTICLE_CHUNK, SPRING_CHUNK,
};
use super::state::Vec3;
use super::term::{EnergyKind, ForceTerm};
use nalgebra::Matrix3;
use rayon::prelude::*;
use std::sync::{Arc, OnceLock};

/// All springs of a system, one entry per spring in each array.
///
/// After the first large evaluation the springs cache their particle incidence list; change
/// the arrays only through [`Springs::push`] (which drops the cache), or build a new `Springs`.
#[derive(Clone, Default)]
pub struct Springs {
    /// First particle of each spring.
    pub i: Vec<u32>,
    /// Second particle of each spring.
    pub j: Vec<u32>,
    /// Effective stiffness in N/m (already divided by l0 for strain springs).
    pub k: Vec<f64>,
    /// Rest length in m.
    pub l0: Vec<f64>,
    /// Axial damping in N·s/m.
    pub c: Vec<f64>,
    /// True when any spring has damping (so the damper loop is worth running).
    pub any_damping: bool,
    incidence: OnceLock<Option<Arc<Incidence>>>,
    /// The springs at each particle (incidence lists over one-particle chunks), built on
    /// first use by [`Springs::energy_at`].
    at: OnceLock<Option<Incidence>>,
    scratch: ScratchPool,
}

/// The springs as the scene defines them: caches and scratch buffers left out, so two
/// descriptions of the same springs are equal whatever has been evaluated (the reference
/// store and the kept solves key on it).
impl std::fmt::Debug for Springs {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Springs")
            .field("i", &self.i)
            .field("j", &self.j)
            .field("k", &self.k)
            .field("l0", &self.l0)
            .field("c", &self.c)
            .field("any_damping", &self.any_damping)
            .finish()
    }
}

impl Springs {
    /// Number of springs.
    pub fn len(&self) -> usize {
        self.i.len()
    }
    /// True when there are no springs.
    pub fn is_empty(&self) -> bool {
        self.i.is_empty()
    }
    /// Appends a spring.
    pub fn push(&mut self, i: usize, j: usize, k: f64, l0: f64, c: f64) {
        self.i.push(i as u32);
        self.j.push(j as u32);
        self.k.push(k);
        self.l0.push(l0);
        self.c.push(c);
        self.any_damping |= c > 0.0;
        self.incidence = OnceLock::new();
        self.at = OnceLock::new();
    }

    /// True when evaluations over `n` particles take the parallel path (a property of the
    /// scene's size only).
    pub fn is_parallel(&self, n: usize) -> bool {
        self.incidence(n).is_some()
    }

    /// The incidence list for `n` particles when the parallel path applies.
    fn incidence(&self, n: usize) -> Option<&Incidence> {
        if self.len() < PARALLEL_MIN_SPRINGS {
            return None;
        }
        self.incidence
            .get_or_init(|| Incidence::build(&self.i, &self.j, n).map(Arc::new))
            .as_deref()
            .filter(|inc| inc.particles == n && inc.springs == self.len())
    }

    /// The chunk lists of the parallel path for `n` particles, shared (the Jacobian of the
    /// same springs walks the same lists), or `None` where the scene is evaluated serially.
    pub fn owner_lists(&self, n: usize) -> Option<Arc<Incidence>> {
        self.incidence(n)?;
        self.incidence.get().cloned().flatten()
    }

    /// Adds to `out[p]`, for every spring at particle `p`, `k (|x_i|∞ + |x_j|∞ + l0)`: the size
    /// of the quantities whose rounding (relative error ε each) makes up the rounding error of
    /// the force on `p`. Implicit solvers use it as the floor below which a residual is noise.
    pub fn add_rounding_scale(&self, x: &[Vec3], out: &mut [f64]) {
        for s in 0..self.len() {
            let (a, b) = (self.i[s] as usize, self.j[s] as usize);
            let r = self.k[s] * (x[a].amax() + x[b].amax() + self.l0[s]);
            out[a] += r;
            out[b] += r;
        }
    }

    /// Force of spring `s` on its first particle and the power its damper dissipates
    /// ([`spring_force`]).
    #[inline(always)]
    pub(crate) fn force<const DAMPED: bool>(
        &self,
        s: usize,
        x: &[Vec3],
        v: &[Vec3],
    ) -> (Vec3, f64) {
        let (a, b) = (self.i[s] as usize, self.j[s] as usize);
        spring_force::<DAMPED>(a, b, x, v, self.k[s], self.l0[s], self.c[s])
    }

    /// Serial scatter; power summed per [`SPRING_CHUNK`] and then across chunks. The spring
    /// arrays are walked together, chunk by chunk, so only the particles are looked up.
    pub(crate) fn add_forces_serial<const DAMPED: bool>(
        &self,
        x: &[Vec3],
        v: &[Vec3],
        f: &mut [Vec3],
    ) -> f64 {
        let mut power = 0.0;
        for ((((i, j), k), l0), c) in self
            .i
            .chunks(SPRING_CHUNK)
            .zip(self.j.chunks(SPRING_CHUNK))
            .zip(self.k.chunks(SPRING_CHUNK))
            .zip(self.l0.chunks(SPRING_CHUNK))
            .zip(self.c.chunks(SPRING_CHUNK))
        {
            let mut part = 0.0;
            for ((((&a, &b), &k), &l0), &c) in i.iter().zip(j).zip(k).zip(l0).zip(c) {
                let (a, b) = (a as usize, b as usize);
                let (fs, p) = spring_force::<DAMPED>(a, b, x, v, k, l0, c);
                if DAMPED {
                    part += p;
                }
                f[a] += fs;
                f[b] -= fs;
            }
            power += part;
        }
        power
    }

    /// Parallel owner-computes loop over fixed particle chunks (see [`super::parallel`]).
    fn add_forces_parallel<const DAMPED: bool>(
        &self,
        inc: &Incidence,
        x: &[Vec3],
        v: &[Vec3],
        f: &mut [Vec3],
    ) -> f64 {
        let mut scratch = self.scratch.take();
        let parts =
            &mut scratch.fit(inc.chunks(), self.len().div_ceil(SPRING_CHUNK))[..inc.chunks()];
        f.par_chunks_mut(PARTICLE_CHUNK)
            .zip(parts.par_iter_mut())
            .enumerate()
            .for_each(|(c, (fc, part))| {
                let base = c * PARTICLE_CHUNK;
                let mut sum = 0.0;
                for &e in inc.chunk(c) {
                    let s = (e >> 2) as usize;
                    let (fs, p) = self.force::<DAMPED>(s, x, v);
                    let (a, b) = (self.i[s] as usize, self.j[s] as usize);
                    match e & OWNS_BOTH {
                        OWNS_BOTH => {
                            fc[a - base] += fs;
                            fc[b - base] -= fs;
                            if DAMPED {
                                sum += p;
                            }
                        }
                        OWNS_FIRST => {
                            fc[a - base] += fs;
                            if DAMPED {
                                sum += p;
                            }
                        }
                        _ => fc[b - base] -= fs,
                    }
                }
                *part = sum;
            });
        let power = if DAMPED { sum_partials(parts) } else { 0.0 };
        self.scratch.give(scratch);
        power
    }

    /// Elastic energy ½ k_eff (|d| − l0)² of spring `s`.
    #[inline(always)]
    pub(crate) fn energy_of(&self, s: usize, x: &[Vec3]) -> f64 {
        let len = (x[self.j[s] as usize] - x[self.i[s] as usize]).norm();
        let ext = len - self.l0[s];
        0.5 * self.k[s] * ext * ext
    }

    /// Elastic energy of springs `lo..hi`, summed in spring order.
    pub(crate) fn energy_range(&self, x: &[Vec3], lo: usize, hi: usize) -> f64 {
        let mut e = 0.0;
        for s in lo..hi {
            e += self.energy_of(s, x);
        }
        e
    }

    /// Elastic energy of the springs at particle `p` (the part of the total that moving `p`
    /// alone changes), for positions `x` of all particles. The contact stage uses it to book
    /// each particle's correction on its own.
    pub fn energy_at(&self, p: usize, x: &[Vec3]) -> f64 {
        let Some(at) = self
            .at
            .get_or_init(|| Incidence::build_in_chunks(&self.i, &self.j, x.len(), 1))
        else {
            return 0.0;
        };
        if p + 1 >= at.start.len() {
            return 0.0;
        }
        at.entries[at.start[p] as usize..at.start[p + 1] as usize]
            .iter()
            .map(|&e| self.energy_of((e >> 2) as usize, x))
            .sum()
    }

    /// Jacobian blocks (∂f_i/∂x_j, ∂f_i/∂v_j) of spring `s`.
    #[inline(always)]
    fn jacobian_blocks(&self, s: usize, x: &[Vec3], clamp: f64) -> (Matrix3<f64>, Matrix3<f64>) {
        let (a, b) = (self.i[s] as usize, self.j[s] as usize);
        let d = x[b] - x[a];
        let len = d.norm();
        let k = self.k[s];
        if len > 0.0 {
            let n = d / len;
            let nn = n * n.transpose();
            let r = self.l0[s] / len;
            // k(1 - r)(I - nnᵀ) + k nnᵀ; the transverse part is negative when compressed.
            let transverse = if r > 1.0 {
                (1.0 - r) * (1.0 - clamp)
            } else {
                1.0 - r
            };
            let kx = (Matrix3::identity() - nn) * (k * transverse) + nn * k;
            (kx, nn * self.c[s])
        } else {
            (Matrix3::identity() * k, Matrix3::zeros())
        }
    }
}

/// Force of the spring from particle `a` to particle `b` (effective stiffness `k`, rest length
/// `l0`, damping `c`) on `a`, and the power its damper dissipates:
/// `n (k (|d| − l0) + c n·(v_b − v_a))` with `d = x_b − x_a`, `n = d/|d|`, and zero at `|d| = 0`.
#[inline(always)]
fn spring_force<const DAMPED: bool>(
    a: usize,
    b: usize,
    x: &[Vec3],
    v: &[Vec3],
    k: f64,
    l0: f64,
    c: f64,
) -> (Vec3, f64) {
    let d = x[b] - x[a];
    let len = d.norm();
    if len == 0.0 {
        // Coincident endpoints: k_eff d is the zero vector, the damper is skipped.
        return (Vec3::zeros(), 0.0);
    }
    let n = d * (1.0 / len);
    let mut mag = k * (len - l0);
    let mut power = 0.0;
    if DAMPED {
        let vrel = (v[b] - v[a]).dot(&n);
        let cv = c * vrel;
        mag += cv;
        power = cv * vrel;
    }
    (n * mag, power)
}

impl ForceTerm for Springs {
    fn field(&self) -> &'static str {
        "stiffness and damping of [[spring]], [[chain]] or [[cloth]]"
    }
    fn kind(&self) -> super::term::TermKind {
        super::term::TermKind::Springs
    }
    fn name(&self) -> &'static str {
        if self.any_damping {
            "springs+dampers"
        } else {
            "springs"
        }
    }

    fn energy_kind(&self) -> EnergyKind {
        EnergyKind::Elastic
    }

    fn add_forces(&self, x: &[Vec3], v: &[Vec3], f: &mut [Vec3]) -> f64 {
        match (self.incidence(f.len()), self.any_damping) {
            (Some(inc), true) => self.add_forces_parallel::<true>(inc, x, v, f),
            (Some(inc), false) => self.add_forces_parallel::<false>(inc, x, v, f),
            (None, true) => self.add_forces_serial::<true>(x, v, f),
            (None, false) => self.add_forces_serial::<false>(x, v, f),
        }
    }

    fn potential_energy(&self, x: &[Vec3]) -> f64 {
        let m = self.len();
        if let Some(inc) = self.incidence(x.len()) {
            let mut scratch = self.scratch.take();
            let parts = &mut scratch.fit(m.div_ceil(SPRING_CHUNK), inc.chunks())
                [..m.div_ceil(SPRING_CHUNK)];
            parts.par_iter_mut().enumerate().for_each(|(c, part)| {
                let lo = c * SPRING_CHUNK;
                *part = self.energy_range(x, lo, (lo + SPRING_CHUNK).min(m));
            });
            let e = sum_partials(parts);
            self.scratch.give(scratch);
            e
        } else {
            let mut e = 0.0;
            let mut lo = 0;
            while lo < m {
                let hi = (lo + SPRING_CHUNK).min(m);
                e += self.energy_range(x, lo, hi);
                lo = hi;
            }
            e
        }
    }

    fn add_jacobian(&self, x: &[Vec3], _v: &[Vec3], jac: &mut Jacobian) {
        // For f_i = k(1 - l0/L) d + c (n·v_rel) n with d = x_j - x_i:
        // ∂f_i/∂x_j = k[(1 - l0/L) I + (l0/L) n nᵀ] + damper geometric terms (dropped: they are
        // O(c·|v_rel|/L) and vanish at rest; Newton still converges to the same root),
        // ∂f_i/∂v_j = c n nᵀ. The blocks for (i,i) are the negatives.
        // Each block depends on its spring only, so the parallel fill is trivially deterministic.
        let clamp = jac.clamp;
        if self.incidence(x.len()).is_some() {
            let m = self.len();
            jac.kx[..m]
                .par_chunks_mut(SPRING_CHUNK)
                .zip(jac.kv[..m].par_chunks_mut(SPRING_CHUNK))
                .enumerate()
                .for_each(|(c, (kx, kv))| {
                    let base = c * SPRING_CHUNK;
                    for k in 0..kx.len() {
                        (kx[k], kv[k]) = self.jacobian_blocks(base + k, x, clamp);
                    }
                });
        } else {
            for s in 0..self.len() {
                let (kx, kv) = self.jacobian_blocks(s, x, clamp);
                jac.set_pair(s, kx, kv);
            }
        }
    }
}
