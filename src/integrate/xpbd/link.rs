//! One XPBD constraint: a spring or a rod seen as a compliant distance constraint
//! C = |x_j − x_i| − L with compliance α = 1/k and the damping of Macklin, Müller & Chentanez
//! ("XPBD", MIG 2016, eqs. 18 and 26), and its Gauss–Seidel update.
//!
//! The paper's update, with α̃ = α/h², β̃ = h²β and γ = α̃β̃/h = αβ/h, is
//!
//!   Δλ = (−C − α̃λ − γ ∇C·(x − xₙ)) / ((1 + γ) ∇C M⁻¹ ∇Cᵀ + α̃),   x += M⁻¹ ∇Cᵀ Δλ.
//!
//! Multiplying numerator and denominator by 1/α̃ = h²k gives the stiffness form used here,
//!
//!   Δλ = (−h²k C − λ − h β ∇C·(x − xₙ)) / ((h²k + hβ) w + 1),   w = wᵢ + wⱼ,
//!
//! the same number for every finite k > 0, also defined for k = 0 (a pure damper). A rigid
//! rod (compliance 0, k = ∞) takes the limit Δλ = −C / w. β is the spring's axial damping c
//! (N·s/m): the paper's dissipation potential ½β Ċ² gives the damper force c (n·v_rel) n.

use crate::model::{System, Vec3};

/// A distance constraint in stiffness form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Link {
    /// First particle.
    pub i: usize,
    /// Second particle.
    pub j: usize,
    /// Rest length L (m).
    pub rest: f64,
    /// Stiffness 1/α (N/m): k_eff of a spring (k/L for the strain law), 1/compliance of a
    /// `[[constraint]]`, ∞ for a rigid one.
    pub k: f64,
    /// Damping β (N·s/m): the spring's damper, 0 for constraints.
    pub c: f64,
}

/// Number of links of `sys`: its springs, then its constraints.
pub(crate) fn count(sys: &System) -> usize {
    sys.springs.len() + sys.constraints.len()
}

/// Link `l` of `sys`: springs first (in their order), then `[[constraint]]`s.
#[inline(always)]
pub(crate) fn link(sys: &System, l: usize) -> Link {
    let sp = &sys.springs;
    if l < sp.len() {
        Link {
            i: sp.i[l] as usize,
            j: sp.j[l] as usize,
            rest: sp.l0[l],
            k: sp.k[l],
            c: sp.c[l],
        }
    } else {
        let c = &sys.constraints[l - sp.len()];
        Link {
            i: c.i,
            j: c.j,
            rest: c.length,
            k: if c.compliance > 0.0 {
                1.0 / c.compliance
            } else {
                f64::INFINITY
            },
            c: 0.0,
        }
    }
}

/// The Gauss–Seidel update of one link at positions `x` (start-of-substep positions `x0`,
/// substep `h`): adds Δλ to `lambda` and returns n Δλ, to apply as xᵢ −= wᵢ n Δλ,
/// xⱼ += wⱼ n Δλ. `None` when nothing can move (both ends fixed) or the direction is undefined
/// (coincident ends, where the spring force is zero too).
#[inline(always)]
pub(crate) fn solve(
    l: &Link,
    inv_mass: &[f64],
    x: &[Vec3],
    x0: &[Vec3],
    h: f64,
    lambda: &mut f64,
) -> Option<Vec3> {
    let w = inv_mass[l.i] + inv_mass[l.j];
    let d = x[l.j] - x[l.i];
    let len = d.norm();
    if w == 0.0 || len == 0.0 {
        return None;
    }
    let n = d * (1.0 / len);
    let cons = len - l.rest;
    let dl = if l.k.is_finite() {
        let moved = n.dot(&((x[l.j] - x0[l.j]) - (x[l.i] - x0[l.i])));
        let hk = h * h * l.k;
        let hc = h * l.c;
        (-hk * cons - *lambda - hc * moved) / ((hk + hc) * w + 1.0)
    } else {
        -cons / w
    };
    *lambda += dl;
    Some(n * dl)
}

/// Power (W) the dampers of springs `lo..hi` dissipate at positions `x` and velocities `v`:
/// Σ c (n·(vⱼ − vᵢ))², summed in spring order.
pub(crate) fn damper_power(sys: &System, x: &[Vec3], v: &[Vec3], lo: usize, hi: usize) -> f64 {
    let sp = &sys.springs;
    let mut p = 0.0;
    for s in lo..hi {
        let c = sp.c[s];
        if c == 0.0 {
            continue;
        }
        let (a, b) = (sp.i[s] as usize, sp.j[s] as usize);
        let d = x[b] - x[a];
        let len = d.norm();
        if len == 0.0 {
            continue;
        }
        let vrel = (v[b] - v[a]).dot(&d) / len;
        p += c * vrel * vrel;
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Oracle: the paper's compliance form (eq. 26 with α̃ = 1/(h²k), γ = αβ/h), evaluated
    /// directly; the stiffness form must give the same Δλ.
    #[test]
    fn stiffness_form_equals_the_papers_compliance_form() {
        let (k, c, h, lambda0) = (350.0, 0.7, 0.01, 0.003);
        let l = Link {
            i: 0,
            j: 1,
            rest: 1.0,
            k,
            c,
        };
        let inv = [0.5, 0.25];
        let x0 = [Vec3::zeros(), Vec3::new(1.1, 0.0, 0.0)];
        let x = [Vec3::new(0.0, 0.01, 0.0), Vec3::new(1.2, 0.05, 0.0)];
        let mut lambda = lambda0;
        let g = solve(&l, &inv, &x, &x0, h, &mut lambda).unwrap();
        let d = x[1] - x[0];
        let n = d / d.norm();
        let cons = d.norm() - 1.0;
        let (at, gamma) = (1.0 / (k * h * h), (1.0 / k) * c / h);
        let moved = n.dot(&((x[1] - x0[1]) - (x[0] - x0[0])));
        let want = (-cons - at * lambda0 - gamma * moved) / ((1.0 + gamma) * 0.75 + at);
        assert!((lambda - lambda0 - want).abs() <= 1e-15 * want.abs());
        assert!((g - n * want).norm() <= 1e-15 * want.abs());
    }

    /// Oracle: projecting a single rigid rod with one free end moves that end onto the rod
    /// length exactly (up to rounding), whatever its start.
    #[test]
    fn a_rigid_rod_is_projected_onto_its_length() {
        let l = Link {
            i: 0,
            j: 1,
            rest: 1.0,
            k: f64::INFINITY,
            c: 0.0,
        };
        let inv = [0.0, 1.0];
        let mut x = [Vec3::zeros(), Vec3::new(0.9, 0.7, -0.2)];
        let x0 = x;
        let mut lambda = 0.0;
        let g = solve(&l, &inv, &x, &x0, 0.01, &mut lambda).unwrap();
        x[1] += g;
        assert!(((x[1] - x[0]).norm() - 1.0).abs() < 1e-15);
    }
}
