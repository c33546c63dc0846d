//! Linearised natural modes of a scene: stiffness K = −∂f/∂x and damping C = −∂f/∂v at the
//! initial state, mass-normalised (M^{-1/2} K M^{-1/2}), over the free particles' coordinates.
//!
//! Up to [`DENSE_LIMIT`] coordinates: a dense symmetric eigen-decomposition (nalgebra) gives
//! every mode with its modal damping cᵢ = qᵢᵀ C̃ qᵢ (the off-diagonal modal damping, which
//! this decoupling ignores, is reported). Larger scenes: power iteration on the sparse
//! stiffness for the highest natural frequency only.

use crate::model::{Jacobian, State, System, Vec3};
use nalgebra::{DMatrix, SymmetricEigen};
use serde::Serialize;

/// Largest number of coordinates analysed densely.
pub const DENSE_LIMIT: usize = 900;

/// One linearised mode: ω² (rad²/s²) and its mass-normalised damping c (1/s); the mode obeys
/// q'' + c q' + ω² q = 0.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Mode {
    /// Squared natural frequency.
    pub omega2: f64,
    /// Modal damping rate (2ζω).
    pub damping: f64,
}

/// The linearised modes of a scene.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Modes {
    /// Distinct modes with ω² > 0 or damping > 0 (neutral rigid-body modes are dropped).
    pub modes: Vec<Mode>,
    /// Highest natural frequency (rad/s), 0 without stiffness.
    pub omega_max: f64,
    /// How they were found.
    pub found_by: String,
    /// Largest off-diagonal modal damping relative to the largest diagonal one (0: exact
    /// decoupling); None for the power-iteration path.
    pub damping_coupling: Option<f64>,
    /// Modes with ω² < 0 (the initial state is not a stable equilibrium along them).
    pub negative_modes: usize,
    /// Number of free coordinates.
    pub dofs: usize,
}

struct Lin {
    jac: Jacobian,
    free: Vec<usize>,
    index: Vec<Option<usize>>,
    sqrt_inv_m: Vec<f64>,
}

impl Lin {
    fn new(sys: &System, s0: &State) -> Self {
        let mut jac = sys.new_jacobian();
        sys.jacobian(&s0.x, &s0.v, &mut jac);
        let free: Vec<usize> = (0..sys.len()).filter(|&p| sys.free[p]).collect();
        let mut index = vec![None; sys.len()];
        for (k, &p) in free.iter().enumerate() {
            index[p] = Some(k);
        }
        let sqrt_inv_m = free.iter().map(|&p| 1.0 / sys.mass[p].sqrt()).collect();
        Lin {
            jac,
            free,
            index,
            sqrt_inv_m,
        }
    }

    /// Dense mass-normalised K̃ and C̃.
    fn dense(&self) -> (DMatrix<f64>, DMatrix<f64>) {
        let n = 3 * self.free.len();
        let mut k = DMatrix::zeros(n, n);
        let mut c = DMatrix::zeros(n, n);
        let add =
            |m: &mut DMatrix<f64>, a: usize, b: usize, blk: &nalgebra::Matrix3<f64>, sign: f64| {
                for r in 0..3 {
                    for q in 0..3 {
                        m[(3 * a + r, 3 * b + q)] += sign * blk[(r, q)];
                    }
                }
            };
        for (s, pr) in self.jac.pairs.iter().enumerate() {
            let (a, b) = (self.index[pr[0] as usize], self.index[pr[1] as usize]);
            for (m, blk) in [(&mut k, &self.jac.kx[s]), (&mut c, &self.jac.kv[s])] {
                if let Some(a) = a {
                    add(m, a, a, blk, 1.0);
                }
                if let Some(b) = b {
                    add(m, b, b, blk, 1.0);
                }
                if let (Some(a), Some(b)) = (a, b) {
                    add(m, a, b, blk, -1.0);
                    add(m, b, a, blk, -1.0);
                }
            }
        }
        for (kf, &p) in self.free.iter().enumerate() {
            add(&mut k, kf, kf, &self.jac.diag_x[p], -1.0);
            add(&mut c, kf, kf, &self.jac.diag_v[p], -1.0);
        }
        for m in [&mut k, &mut c] {
            for r in 0..n {
                for q in 0..n {
                    m[(r, q)] *= self.sqrt_inv_m[r / 3] * self.sqrt_inv_m[q / 3];
                }
            }
            let sym = (&*m + m.transpose()) * 0.5;
            *m = sym;
        }
        (k, c)
    }

    /// y = K̃ x (or C̃ x with `damping`) without assembling the matrix.
    fn apply(&self, x: &[Vec3], y: &mut [Vec3], damping: bool) {
        y.iter_mut().for_each(|v| *v = Vec3::zeros());
        let xs: Vec<Vec3> = x
            .iter()
            .zip(&self.sqrt_inv_m)
            .map(|(v, s)| v * *s)
            .collect();
        let blocks = if damping { &self.jac.kv } else { &self.jac.kx };
        for (s, pr) in self.jac.pairs.iter().enumerate() {
            let (a, b) = (self.index[pr[0] as usize], self.index[pr[1] as usize]);
            let xa = a.map_or(Vec3::zeros(), |a| xs[a]);
            let xb = b.map_or(Vec3::zeros(), |b| xs[b]);
            let q = blocks[s] * (xa - xb);
            if let Some(a) = a {
                y[a] += q;
            }
            if let Some(b) = b {
                y[b] -= q;
            }
        }
        let diag = if damping {
            &self.jac.diag_v
        } else {
            &self.jac.diag_x
        };
        for (k, &p) in self.free.iter().enumerate() {
            y[k] -= diag[p] * xs[k];
        }
        for (v, s) in y.iter_mut().zip(&self.sqrt_inv_m) {
            *v *= *s;
        }
    }
}

/// The linearised modes of `sys` at `s0`.
///
/// Computed once per system and state in a process (the study asks for a scene's modes in
/// several places: a dense eigen-decomposition of a 16×16 cloth takes about 0.3 s).
pub fn modes(sys: &System, s0: &State) -> Modes {
    /// Most analyses kept.
    static KEPT: crate::measure::kept::Kept<Modes> = crate::measure::kept::Kept::new(64);
    let Ok(made) = KEPT.get_or_make::<std::convert::Infallible>(format!("{sys:?}|{s0:?}"), || {
        Ok(analyse(sys, s0))
    });
    made
}

/// [`modes`], analysed afresh.
fn analyse(sys: &System, s0: &State) -> Modes {
    let lin = Lin::new(sys, s0);
    let dofs = 3 * lin.free.len();
    if dofs == 0 {
        return Modes {
            modes: vec![],
            omega_max: 0.0,
            found_by: "no free particles".into(),
            damping_coupling: None,
            negative_modes: 0,
            dofs,
        };
    }
    if dofs <= DENSE_LIMIT {
        dense_modes(&lin, dofs)
    } else {
        power_modes(&lin, dofs)
    }
}

/// Every distinct mode of `lin` (`dofs` coordinates) by a dense symmetric eigen-solve of the
/// mass-normalised stiffness, with the damping projected on the eigenvectors.
fn dense_modes(lin: &Lin, dofs: usize) -> Modes {
    let (k, c) = lin.dense();
    let eig = SymmetricEigen::new(k);
    let q = &eig.eigenvectors;
    let cm = q.transpose() * c * q;
    let wmax2 = eig.eigenvalues.iter().fold(0.0f64, |a, &b| a.max(b));
    let cmax = (0..dofs).map(|i| cm[(i, i)].abs()).fold(0.0, f64::max);
    let mut off: f64 = 0.0;
    for i in 0..dofs {
        for j in 0..dofs {
            if i != j {
                off = off.max(cm[(i, j)].abs());
            }
        }
    }
    let tiny = 1e-10 * wmax2.max(f64::MIN_POSITIVE);
    let mut negative = 0;
    let mut list: Vec<Mode> = Vec::new();
    for i in 0..dofs {
        let (w2, d) = (eig.eigenvalues[i], cm[(i, i)].max(0.0));
        if w2 < -tiny {
            negative += 1;
            continue;
        }
        let w2 = w2.max(0.0);
        if w2 <= tiny && d <= 1e-12 * cmax.max(f64::MIN_POSITIVE) {
            continue;
        }
        let m = Mode {
            omega2: if w2 <= tiny { 0.0 } else { w2 },
            damping: d,
        };
        let same = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs());
        if !list
            .iter()
            .any(|o| same(o.omega2, m.omega2) && same(o.damping, m.damping))
        {
            list.push(m);
        }
    }
    list.sort_by(|a, b| {
        a.omega2
            .total_cmp(&b.omega2)
            .then(a.damping.total_cmp(&b.damping))
    });
    Modes {
        modes: list,
        omega_max: wmax2.max(0.0).sqrt(),
        found_by: format!("dense symmetric eigen-decomposition of the mass-normalised stiffness ({dofs} coordinates), linearised at the initial state"),
        damping_coupling: Some(if cmax > 0.0 { off / cmax } else { 0.0 }),
        negative_modes: negative,
        dofs,
    }
}

/// The highest mode of `lin` (`dofs` coordinates) by power iteration on the sparse
/// mass-normalised stiffness, for systems too big for the dense solve.
fn power_modes(lin: &Lin, dofs: usize) -> Modes {
    // Power iteration from a fixed, deterministic start vector.
    let n = lin.free.len();
    let mut x: Vec<Vec3> = (0..n)
        .map(|i| {
            Vec3::new(
                1.0 + (i % 7) as f64,
                1.0 + (i % 5) as f64 * 0.5,
                1.0 + (i % 3) as f64 * 0.25,
            )
        })
        .collect();
    let mut y = vec![Vec3::zeros(); n];
    let norm = |v: &[Vec3]| v.iter().map(|a| a.norm_squared()).sum::<f64>().sqrt();
    let mut lambda = 0.0;
    let mut iters = 0;
    for it in 0..3000 {
        let nx = norm(&x);
        x.iter_mut().for_each(|v| *v /= nx);
        lin.apply(&x, &mut y, false);
        let rq: f64 = x.iter().zip(&y).map(|(a, b)| a.dot(b)).sum();
        iters = it + 1;
        let done = it > 20 && (rq - lambda).abs() <= 1e-10 * rq.abs();
        lambda = rq;
        std::mem::swap(&mut x, &mut y);
        if done {
            break;
        }
    }
    let nx = norm(&x);
    x.iter_mut().for_each(|v| *v /= nx);
    lin.apply(&x, &mut y, true);
    let c: f64 = x.iter().zip(&y).map(|(a, b)| a.dot(b)).sum();
    let w2 = lambda.max(0.0);
    Modes {
        modes: vec![Mode {
            omega2: w2,
            damping: c.max(0.0),
        }],
        omega_max: w2.sqrt(),
        found_by: format!("power iteration on the sparse mass-normalised stiffness ({dofs} coordinates, {iters} iterations): highest mode only, linearised at the initial state"),
        damping_coupling: None,
        negative_modes: 0,
        dofs,
    }
}
