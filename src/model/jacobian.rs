//! Sparse force Jacobians for implicit methods: 3×3 blocks per spring pair and per particle.

use super::state::Vec3;
use nalgebra::Matrix3;

/// ∂f/∂x and ∂f/∂v in block form.
///
/// For pair `s` joining particles `a = pairs[s][0]`, `b = pairs[s][1]`, `kx[s]` is
/// ∂f_a/∂x_b (= ∂f_b/∂x_a), and ∂f_a/∂x_a = ∂f_b/∂x_b = -kx[s]; likewise `kv` for velocities.
/// `diag_x`/`diag_v` hold extra per-particle blocks (drag, penalty contacts).
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
    /// Per-pair Newton blocks h·kv + h²·kx, filled by [`Jacobian::prepare_newton`].
    newton_pair: Vec<Matrix3<f64>>,
    /// Per-particle Newton blocks m I − h·diag_v − h²·diag_x (identity for fixed particles).
    newton_self: Vec<Matrix3<f64>>,
}

impl Jacobian {
    /// An all-zero Jacobian with the given pair topology over `n` particles.
    pub fn new(n: usize, pairs: Vec<[u32; 2]>) -> Self {
        let m = pairs.len();
        Jacobian {
            pairs,
            kx: vec![Matrix3::zeros(); m],
            kv: vec![Matrix3::zeros(); m],
            diag_x: vec![Matrix3::zeros(); n],
            diag_v: vec![Matrix3::zeros(); n],
            clamp: 0.0,
            newton_pair: vec![Matrix3::zeros(); m],
            newton_self: vec![Matrix3::zeros(); n],
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
        for s in 0..self.pairs.len() {
            self.newton_pair[s] = self.kv[s] * h + self.kx[s] * (h * h);
        }
        for i in 0..mass.len() {
            self.newton_self[i] = if free[i] {
                Matrix3::identity() * mass[i] - self.diag_v[i] * h - self.diag_x[i] * (h * h)
            } else {
                Matrix3::identity()
            };
        }
    }

    /// y = A p for the Newton matrix A prepared by [`Jacobian::prepare_newton`]. Rows of fixed
    /// particles are left as p and never coupled.
    pub fn newton_matvec(&self, free: &[bool], p: &[Vec3], y: &mut [Vec3]) {
        for i in 0..p.len() {
            y[i] = self.newton_self[i] * p[i];
        }
        for (s, pr) in self.pairs.iter().enumerate() {
            let (a, b) = (pr[0] as usize, pr[1] as usize);
            let q = self.newton_pair[s] * (p[b] - p[a]);
            if free[a] {
                y[a] -= q;
            }
            if free[b] {
                y[b] += q;
            }
        }
    }

    /// The 3×3 diagonal blocks of the prepared Newton matrix, for a block-Jacobi preconditioner.
    pub fn newton_diagonal(&self, free: &[bool], out: &mut [Matrix3<f64>]) {
        out.copy_from_slice(&self.newton_self);
        for (s, pr) in self.pairs.iter().enumerate() {
            for &q in pr {
                if free[q as usize] {
                    out[q as usize] += self.newton_pair[s];
                }
            }
        }
    }
}
