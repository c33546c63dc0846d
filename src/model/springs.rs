//! Springs with optional axial dampers, stored as flat arrays (structure of arrays).
//!
//! The force law of every spring is `f = k_eff (|d| - l0)` along `d = x_j - x_i`, where
//! `k_eff` is `k` for Hooke springs and `k / l0` for strain springs (precomputed at build).
//! Coincident endpoints (`|d| = 0`): the direction is undefined; the elastic force is taken as
//! `k_eff (d - l0 d/|d|)` with the second part dropped, i.e. zero, and the damper is skipped,
//! so no NaN can arise. That is the documented fallback.

use super::jacobian::Jacobian;
use super::state::Vec3;
use super::term::{EnergyKind, ForceTerm};
use nalgebra::Matrix3;

/// All springs of a system, one entry per spring in each array.
#[derive(Debug, Clone, Default)]
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
    }
}

/// Elastic force coefficient `k (1 - l0/len)` so that `f_i = coeff * d`, with the fallback above.
#[inline(always)]
fn elastic_coeff(k: f64, l0: f64, len: f64) -> f64 {
    if len > 0.0 {
        k * (1.0 - l0 / len)
    } else {
        k
    }
}

impl ForceTerm for Springs {
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
        let mut power = 0.0;
        for s in 0..self.i.len() {
            let (a, b) = (self.i[s] as usize, self.j[s] as usize);
            let d = x[b] - x[a];
            let len = d.norm();
            let mut fs = d * elastic_coeff(self.k[s], self.l0[s], len);
            if self.any_damping && self.c[s] > 0.0 && len > 0.0 {
                let n = d / len;
                let vrel = (v[b] - v[a]).dot(&n);
                fs += n * (self.c[s] * vrel);
                power += self.c[s] * vrel * vrel;
            }
            f[a] += fs;
            f[b] -= fs;
        }
        power
    }

    fn potential_energy(&self, x: &[Vec3]) -> f64 {
        let mut e = 0.0;
        for s in 0..self.i.len() {
            let len = (x[self.j[s] as usize] - x[self.i[s] as usize]).norm();
            let ext = len - self.l0[s];
            e += 0.5 * self.k[s] * ext * ext;
        }
        e
    }

    fn add_jacobian(&self, x: &[Vec3], _v: &[Vec3], jac: &mut Jacobian) {
        // For f_i = k(1 - l0/L) d + c (n·v_rel) n with d = x_j - x_i:
        // ∂f_i/∂x_j = k[(1 - l0/L) I + (l0/L) n nᵀ] + damper geometric terms (dropped: they are
        // O(c·|v_rel|/L) and vanish at rest; Newton still converges to the same root),
        // ∂f_i/∂v_j = c n nᵀ. The blocks for (i,i) are the negatives.
        for s in 0..self.i.len() {
            let (a, b) = (self.i[s] as usize, self.j[s] as usize);
            let d = x[b] - x[a];
            let len = d.norm();
            let k = self.k[s];
            let (kx, kv) = if len > 0.0 {
                let n = d / len;
                let nn = n * n.transpose();
                let r = self.l0[s] / len;
                // k(1 - r)(I - nnᵀ) + k nnᵀ; the transverse part is negative when compressed.
                let transverse = if jac.definite {
                    (1.0 - r).max(0.0)
                } else {
                    1.0 - r
                };
                let kx = (Matrix3::identity() - nn) * (k * transverse) + nn * k;
                let kv = nn * self.c[s];
                (kx, kv)
            } else {
                (Matrix3::identity() * k, Matrix3::zeros())
            };
            jac.set_pair(s, kx, kv);
        }
    }
}
