//! The reference's right-hand side: the system's accelerations, compliant constraints as stiff
//! springs, rigid constraints by index reduction (Lagrange multipliers from C̈ = 0), and the
//! unilateral contact constraints of [`super::contacts`]; plus the projection onto the rigid
//! constraint manifold applied after every accepted step.

use super::contacts::ContactModel;
use crate::model::{System, Vec3};
use nalgebra::{DMatrix, DVector};

pub(super) fn pack(x: &[Vec3], v: &[Vec3]) -> Vec<f64> {
    x.iter().chain(v).flat_map(|p| [p.x, p.y, p.z]).collect()
}

pub(super) fn unpack_x(y: &[f64], n: usize) -> Vec<Vec3> {
    (0..n)
        .map(|p| Vec3::new(y[3 * p], y[3 * p + 1], y[3 * p + 2]))
        .collect()
}

/// Scratch for the reference right-hand side.
pub(super) struct RhsState<'a> {
    sys: &'a System,
    pub(super) rigid: Vec<usize>,
    /// Contact modes (impulse-response scenes): constrained particles held on surfaces.
    pub(super) contact: Option<ContactModel<'a>>,
    x: Vec<Vec3>,
    v: Vec<Vec3>,
    a: Vec<Vec3>,
}

impl<'a> RhsState<'a> {
    pub(super) fn new(sys: &'a System, rigid: Vec<usize>) -> Self {
        let n = sys.len();
        RhsState {
            sys,
            rigid,
            contact: None,
            x: vec![Vec3::zeros(); n],
            v: vec![Vec3::zeros(); n],
            a: vec![Vec3::zeros(); n],
        }
    }

    /// The system.
    pub(super) fn sys(&self) -> &'a System {
        self.sys
    }

    /// Accelerations at state `y` without the contact constraints (what the contacts must
    /// balance).
    pub(super) fn free_accelerations(&mut self, y: &[f64]) -> Vec<Vec3> {
        self.accelerations(y, false);
        self.a.clone()
    }

    /// y' = f(y): velocities and accelerations, contact constraints included.
    pub(super) fn eval(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) {
        let n = self.sys.len();
        self.accelerations(y, true);
        for p in 0..n {
            dy[3 * p..3 * p + 3].copy_from_slice(self.v[p].as_slice());
            dy[3 * n + 3 * p..3 * n + 3 * p + 3].copy_from_slice(self.a[p].as_slice());
        }
    }

    fn accelerations(&mut self, y: &[f64], with_contacts: bool) {
        let n = self.sys.len();
        for p in 0..n {
            self.x[p] = Vec3::new(y[3 * p], y[3 * p + 1], y[3 * p + 2]);
            let q = 3 * n + 3 * p;
            self.v[p] = Vec3::new(y[q], y[q + 1], y[q + 2]);
        }
        self.sys.accelerations(&self.x, &self.v, &mut self.a);
        let sys = self.sys;
        // Compliant constraints act as stiff springs of stiffness 1/compliance.
        for c in sys.constraints.iter().filter(|c| c.compliance > 0.0) {
            let d = self.x[c.j] - self.x[c.i];
            let len = d.norm();
            if len > 0.0 {
                let f = d / len * ((len - c.length) / c.compliance);
                self.a[c.i] += f * sys.inv_mass[c.i];
                self.a[c.j] -= f * sys.inv_mass[c.j];
            }
        }
        if !self.rigid.is_empty() {
            constraint_accelerations(sys, &self.rigid, &self.x, &self.v, &mut self.a);
        }
        if let Some(c) = self.contact.as_ref().filter(|_| with_contacts) {
            c.constrain(&self.x, &self.v, &mut self.a);
        }
    }
}

/// Unit direction of each rigid constraint and the Gram matrix J M⁻¹ Jᵀ.
fn gram(sys: &System, rigid: &[usize], x: &[Vec3]) -> (Vec<Vec3>, DMatrix<f64>) {
    let m = rigid.len();
    let dirs: Vec<Vec3> = rigid
        .iter()
        .map(|&k| {
            let c = &sys.constraints[k];
            (x[c.j] - x[c.i]).try_normalize(0.0).unwrap_or_else(Vec3::x)
        })
        .collect();
    let mut g = DMatrix::zeros(m, m);
    for a in 0..m {
        let ca = &sys.constraints[rigid[a]];
        for b in 0..m {
            let cb = &sys.constraints[rigid[b]];
            // ∇_p C = -n for p = i, +n for p = j.
            let grad = |c: &crate::model::DistanceConstraint, n: Vec3, p: usize| {
                let mut gp = Vec3::zeros();
                if c.i == p {
                    gp -= n;
                }
                if c.j == p {
                    gp += n;
                }
                gp
            };
            let mut s = 0.0;
            for p in [ca.i, ca.j] {
                if (p == cb.i || p == cb.j) && !(p == ca.j && ca.i == ca.j) {
                    s += sys.inv_mass[p] * grad(ca, dirs[a], p).dot(&grad(cb, dirs[b], p));
                }
            }
            g[(a, b)] = s;
        }
    }
    (dirs, g)
}

/// Adds M⁻¹ Jᵀ λ with λ solving J M⁻¹ Jᵀ λ = -(J a + J̇ v): the accelerations that keep
/// C̈ = 0 for every rigid distance constraint.
fn constraint_accelerations(sys: &System, rigid: &[usize], x: &[Vec3], v: &[Vec3], a: &mut [Vec3]) {
    let (dirs, g) = gram(sys, rigid, x);
    let m = rigid.len();
    let mut rhs = DVector::zeros(m);
    for (r, &k) in rigid.iter().enumerate() {
        let c = &sys.constraints[k];
        let n = dirs[r];
        let len = (x[c.j] - x[c.i]).norm().max(f64::MIN_POSITIVE);
        let vr = v[c.j] - v[c.i];
        let jdot_v = (vr.norm_squared() - n.dot(&vr).powi(2)) / len;
        rhs[r] = -(n.dot(&(a[c.j] - a[c.i])) + jdot_v);
    }
    if let Some(lambda) = g.lu().solve(&rhs) {
        for (r, &k) in rigid.iter().enumerate() {
            let c = &sys.constraints[k];
            let f = dirs[r] * lambda[r];
            a[c.j] += f * sys.inv_mass[c.j];
            a[c.i] -= f * sys.inv_mass[c.i];
        }
    }
}

/// Projects positions (Gauss-Newton, a few sweeps) and velocities onto the rigid constraints.
pub(super) fn project(sys: &System, rigid: &[usize], y: &mut [f64]) {
    let n = sys.len();
    let mut x = unpack_x(y, n);
    for _ in 0..4 {
        let (dirs, g) = gram(sys, rigid, &x);
        let viol = DVector::from_iterator(
            rigid.len(),
            rigid.iter().map(|&k| {
                let c = &sys.constraints[k];
                (x[c.j] - x[c.i]).norm() - c.length
            }),
        );
        if viol.amax() < 1e-15 {
            break;
        }
        let Some(mu) = g.lu().solve(&(-viol)) else {
            break;
        };
        for (r, &k) in rigid.iter().enumerate() {
            let c = &sys.constraints[k];
            let d = dirs[r] * mu[r];
            x[c.j] += d * sys.inv_mass[c.j];
            x[c.i] -= d * sys.inv_mass[c.i];
        }
    }
    let mut v: Vec<Vec3> = (0..n)
        .map(|p| {
            let q = 3 * n + 3 * p;
            Vec3::new(y[q], y[q + 1], y[q + 2])
        })
        .collect();
    let (dirs, g) = gram(sys, rigid, &x);
    let jv = DVector::from_iterator(
        rigid.len(),
        rigid.iter().enumerate().map(|(r, &k)| {
            let c = &sys.constraints[k];
            dirs[r].dot(&(v[c.j] - v[c.i]))
        }),
    );
    if let Some(mu) = g.lu().solve(&(-jv)) {
        for (r, &k) in rigid.iter().enumerate() {
            let c = &sys.constraints[k];
            let d = dirs[r] * mu[r];
            v[c.j] += d * sys.inv_mass[c.j];
            v[c.i] -= d * sys.inv_mass[c.i];
        }
    }
    y.copy_from_slice(&pack(&x, &v));
}
