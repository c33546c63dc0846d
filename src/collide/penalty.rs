//! The `penalty` response: a spring-dashpot force on each contact's penetration depth d,
//! f = (k d − c v_n) n, with regularised Coulomb friction on the tangential velocity. It is an
//! ordinary [`ForceTerm`], so every method handles it and its stiffness counts in stability.
//!
//! The dashpot acts for the whole contact (also pulling slightly at its end), which is the
//! linear spring-dashpot model whose restitution is e = exp(−ζπ/√(1−ζ²)), ζ = c / (2√(k m)).

use super::def::{damping_ratio_for_restitution, PenaltyDamping};
use super::obstacles::ObstacleSet;
use crate::model::{EnergyKind, ForceTerm, Jacobian, Vec3};
use nalgebra::Matrix3;
use std::sync::Arc;

/// Tangential speed (m/s) below which friction is proportional to the sliding speed
/// (regularised Coulomb: f_t = −μ f_n v_t / √(|v_t|² + V_REG²)).
pub const FRICTION_REGULARISATION: f64 = 1e-3;

/// Penalty contacts between particles and static obstacles.
#[derive(Debug)]
pub struct Penalty {
    set: Arc<ObstacleSet>,
    /// Contact stiffness k (N/m).
    pub stiffness: f64,
    damping: PenaltyDamping,
    /// Damping ratio per obstacle when derived from restitution.
    zeta: Vec<f64>,
    mass: Vec<f64>,
    radius: Vec<f64>,
    free: Vec<bool>,
}

impl Penalty {
    /// A penalty term over `set` for particles of the given masses, radii and mobility.
    pub fn new(
        set: Arc<ObstacleSet>,
        stiffness: f64,
        damping: PenaltyDamping,
        mass: Vec<f64>,
        radius: Vec<f64>,
        free: Vec<bool>,
    ) -> Self {
        let zeta = set
            .obstacles()
            .iter()
            .map(|o| match damping {
                PenaltyDamping::Restitution(e) => damping_ratio_for_restitution(e),
                PenaltyDamping::PerObstacle => damping_ratio_for_restitution(o.restitution),
                PenaltyDamping::Coefficient(_) => 0.0,
            })
            .collect();
        Penalty {
            set,
            stiffness,
            damping,
            zeta,
            mass,
            radius,
            free,
        }
    }

    /// Dashpot coefficient c (N·s/m) for particle `p` against obstacle `k`.
    pub fn dashpot(&self, k: usize, p: usize) -> f64 {
        match self.damping {
            PenaltyDamping::Coefficient(c) => c,
            _ => 2.0 * self.zeta[k] * (self.stiffness * self.mass[p]).sqrt(),
        }
    }

    /// Damping ratio ζ = c / (2√(k m)) for particle `p` against obstacle `k`.
    pub fn damping_ratio(&self, k: usize, p: usize) -> f64 {
        match self.damping {
            PenaltyDamping::Coefficient(c) => c / (2.0 * (self.stiffness * self.mass[p]).sqrt()),
            _ => self.zeta[k],
        }
    }
}

impl ForceTerm for Penalty {
    fn name(&self) -> &'static str {
        "penalty_contacts"
    }
    fn kind(&self) -> crate::model::TermKind {
        crate::model::TermKind::PenaltyContacts
    }
    fn field(&self) -> &'static str {
        "collision.stiffness"
    }
    fn energy_kind(&self) -> EnergyKind {
        EnergyKind::Elastic
    }
    fn add_forces(&self, x: &[Vec3], v: &[Vec3], f: &mut [Vec3]) -> f64 {
        let mut power = 0.0;
        for p in 0..x.len() {
            if !self.free[p] {
                continue;
            }
            self.set.for_each_near(&x[p], self.radius[p], 0.0, |c| {
                let d = -c.gap;
                let n = c.normal;
                let vn = v[p].dot(&n);
                let cdash = self.dashpot(c.obstacle, p);
                let fnorm = self.stiffness * d - cdash * vn;
                f[p] += n * fnorm;
                power += cdash * vn * vn;
                let mu = self.set.obstacles()[c.obstacle].friction;
                if mu > 0.0 && fnorm > 0.0 {
                    let vt = v[p] - n * vn;
                    let s = (vt.norm_squared() + FRICTION_REGULARISATION.powi(2)).sqrt();
                    let ft = vt * (-mu * fnorm / s);
                    f[p] += ft;
                    power -= ft.dot(&vt);
                }
            });
        }
        power
    }
    fn potential_energy(&self, x: &[Vec3]) -> f64 {
        let mut e = 0.0;
        for (p, xp) in x.iter().enumerate() {
            if !self.free[p] {
                continue;
            }
            self.set.for_each_near(xp, self.radius[p], 0.0, |c| {
                e += 0.5 * self.stiffness * c.gap * c.gap;
            });
        }
        e
    }
    fn add_jacobian(&self, x: &[Vec3], v: &[Vec3], jac: &mut Jacobian) {
        // ∂f/∂x = −k n nᵀ and ∂f/∂v = −c n nᵀ, plus the regularised friction's
        // ∂f_t/∂v_t = −μ f_n (P/s − v_t v_tᵀ/s³) with P = I − n nᵀ, s = √(|v_t|² + V²) (stiff
        // near a stop: μ f_n / V). The friction's dependence on f_n and the surface curvature
        // are neglected; every kept block is symmetric negative semi-definite, so the Newton
        // matrix stays SPD.
        for (p, xp) in x.iter().enumerate() {
            if !self.free[p] {
                continue;
            }
            self.set.for_each_near(xp, self.radius[p], 0.0, |c| {
                let n = c.normal;
                let nn: Matrix3<f64> = n * n.transpose();
                jac.diag_x[p] -= nn * self.stiffness;
                let cdash = self.dashpot(c.obstacle, p);
                jac.diag_v[p] -= nn * cdash;
                let mu = self.set.obstacles()[c.obstacle].friction;
                let vn = v[p].dot(&n);
                let fnorm = self.stiffness * (-c.gap) - cdash * vn;
                if mu > 0.0 && fnorm > 0.0 {
                    let vt = v[p] - n * vn;
                    let s2 = vt.norm_squared() + FRICTION_REGULARISATION.powi(2);
                    let s = s2.sqrt();
                    let proj = Matrix3::identity() - nn;
                    let d = proj / s - vt * vt.transpose() / (s2 * s);
                    jac.diag_v[p] -= d * (mu * fnorm);
                }
            });
        }
    }
}
