//! The linear theory: each method's one-step map on a linearised mode, identified by stepping
//! the method itself, and the largest step at which its spectral radius stays ≤ 1 + [`RHO_TOL`].

use super::Mode;
use crate::measure::modes::Modes;
use crate::method::Method;
use crate::method::MethodOptions;
use crate::model::{EnergyKind, ForceTerm, Jacobian, Springs, State, System, Vec3};
use nalgebra::Matrix3;
use serde::Serialize;

/// Tolerance on the spectral radius: ρ ≤ 1 + RHO_TOL counts as stable.
pub const RHO_TOL: f64 = 1e-12;
/// Smallest hω tried by the theory scan on an undamped mode (see [`scan_min`]).
pub const SCAN_MIN: f64 = 1e-2;
/// Largest hω tried by the theory scan: stable up to here means unconditionally stable.
pub const SCAN_MAX: f64 = 1e3;

/// An isotropic linear force f = −k x − c v on every particle: one linearised mode.
#[derive(Debug, Clone, Copy)]
struct LinearMode {
    k: f64,
    c: f64,
}

impl ForceTerm for LinearMode {
    fn name(&self) -> &'static str {
        "linear_mode"
    }
    fn kind(&self) -> crate::model::TermKind {
        crate::model::TermKind::LinearMode
    }
    fn field(&self) -> &'static str {
        "the linearised mode"
    }
    fn energy_kind(&self) -> EnergyKind {
        EnergyKind::Elastic
    }
    fn add_forces(&self, x: &[Vec3], v: &[Vec3], f: &mut [Vec3]) -> f64 {
        let mut p = 0.0;
        for i in 0..f.len() {
            f[i] -= x[i] * self.k + v[i] * self.c;
            p += self.c * v[i].norm_squared();
        }
        p
    }
    fn potential_energy(&self, x: &[Vec3]) -> f64 {
        x.iter().map(|x| 0.5 * self.k * x.norm_squared()).sum()
    }
    fn add_jacobian(&self, _x: &[Vec3], _v: &[Vec3], jac: &mut Jacobian) {
        for d in jac.diag_x.iter_mut() {
            *d -= Matrix3::identity() * self.k;
        }
        for d in jac.diag_v.iter_mut() {
            *d -= Matrix3::identity() * self.c;
        }
    }
}

fn mode_system(m: Mode) -> System {
    System {
        mass: vec![1.0],
        inv_mass: vec![1.0],
        free: vec![true],
        radius: vec![0.0],
        springs: Springs::default(),
        gravity: None,
        drag: None,
        constraints: vec![],
        impulses: vec![],
        events: Default::default(),
        post_step: None,
        terms: vec![Box::new(LinearMode {
            k: m.omega2,
            c: m.damping,
        })],
    }
}

/// (x, v) of a fresh instance of `method` on the one-mode system `sys`, from `start` and after
/// each of `steps` steps of `h` (`steps + 1` entries); None when it refuses the system or a
/// step fails.
fn trajectory(
    method: &Method,
    opts: &MethodOptions,
    sys: &System,
    start: (f64, f64),
    h: f64,
    steps: usize,
) -> Option<Vec<(f64, f64)>> {
    let mut stepper = method.create(opts);
    stepper.check(sys).ok()?;
    let mut s = State {
        t: 0.0,
        x: vec![Vec3::new(start.0, 0.0, 0.0)],
        v: vec![Vec3::new(start.1, 0.0, 0.0)],
    };
    stepper.reset();
    let mut ys = vec![start];
    for _ in 0..steps {
        stepper.step(sys, &mut s, h).ok()?;
        ys.push((s.x[0].x, s.v[0].x));
    }
    Some(ys)
}

/// The one-step map of `method` on mode `m` at step `h`, as a 2×2 matrix on (x, v);
/// None when the method fails or the identification is singular.
pub fn one_step_map(
    method: &Method,
    opts: &MethodOptions,
    m: Mode,
    h: f64,
) -> Option<[[f64; 2]; 2]> {
    let sys = mode_system(m);
    let a = trajectory(method, opts, &sys, (1.0, 0.0), h, 2)?;
    let b = trajectory(method, opts, &sys, (0.0, 1.0), h, 2)?;
    // Y1 = [a1 b1], Y2 = [a2 b2] (columns), M = Y2 Y1⁻¹.
    let (p, q, r, s) = (a[1].0, b[1].0, a[1].1, b[1].1);
    let det = p * s - q * r;
    if !(det.is_finite() && det != 0.0) {
        return None;
    }
    let inv = [[s / det, -q / det], [-r / det, p / det]];
    let y2 = [[a[2].0, b[2].0], [a[2].1, b[2].1]];
    let mut mm = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            mm[i][j] = y2[i][0] * inv[0][j] + y2[i][1] * inv[1][j];
        }
    }
    mm.iter().flatten().all(|v| v.is_finite()).then_some(mm)
}

/// Spectral radius of the step map of `method` on mode `m` at step `h`: of the 2×2 one-step
/// map ([`one_step_map`]) for one-step methods, and for a k-step method (say BDF2, k = 2) of
/// the 2k×2k companion matrix of its recurrence yₙ₊₁ = Σⱼ Aⱼ yₙ₋ⱼ, identified from two
/// independent trajectories of 2k − 1 steps (the first k − 1 of which are its start: k
/// recurrence steps give the k unknown 2×2 blocks). None when the method fails or the
/// identification is singular.
pub fn step_radius(method: &Method, opts: &MethodOptions, m: Mode, h: f64) -> Option<f64> {
    let k = method.info.recurrence_steps;
    if k <= 1 {
        return one_step_map(method, opts, m, h).map(spectral_radius);
    }
    let sys = mode_system(m);
    let a = trajectory(method, opts, &sys, (1.0, 0.0), h, 2 * k - 1)?;
    let b = trajectory(method, opts, &sys, (0.0, 1.0), h, 2 * k - 1)?;
    // Y_n: columns are the two trajectories at step n.
    let y = |n: usize| nalgebra::Matrix2::new(a[n].0, b[n].0, a[n].1, b[n].1);
    let mut w = nalgebra::DMatrix::<f64>::zeros(2 * k, 2 * k);
    let mut r = nalgebra::DMatrix::<f64>::zeros(2, 2 * k);
    for (col, n) in (k - 1..2 * k - 1).enumerate() {
        r.view_mut((0, 2 * col), (2, 2)).copy_from(&y(n + 1));
        for j in 0..k {
            w.view_mut((2 * j, 2 * col), (2, 2)).copy_from(&y(n - j));
        }
    }
    // [A₀ … A_{k−1}] W = R.
    let blocks = w.transpose().lu().solve(&r.transpose())?.transpose();
    let mut c = nalgebra::DMatrix::<f64>::zeros(2 * k, 2 * k);
    c.view_mut((0, 0), (2, 2 * k)).copy_from(&blocks);
    for i in 2..2 * k {
        c[(i, i - 2)] = 1.0;
    }
    let radius = c
        .complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max);
    radius.is_finite().then_some(radius)
}

/// Spectral radius of a 2×2 matrix.
pub fn spectral_radius(m: [[f64; 2]; 2]) -> f64 {
    let tr = m[0][0] + m[1][1];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let disc = 0.25 * tr * tr - det;
    if disc >= 0.0 {
        let s = disc.sqrt();
        (0.5 * tr + s).abs().max((0.5 * tr - s).abs())
    } else {
        det.abs().sqrt()
    }
}

pub(super) fn rho(method: &Method, opts: &MethodOptions, m: Mode, h: f64) -> f64 {
    step_radius(method, opts, m, h).unwrap_or(f64::INFINITY)
}

/// A stability verdict.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// Stable for every dt below `max_stable_dt`.
    StableBelow,
    /// Stable at every dt tried.
    UnconditionallyStable,
    /// Unstable at every dt tried.
    UnstableForAllDt,
    /// Neither theory nor the empirical search was run (say, an engine with `--theory-only`).
    NotAnalysed,
}

impl Verdict {
    /// The verdict in words, as every table prints it (the JSON keeps the snake_case name).
    pub fn words(self) -> &'static str {
        match self {
            Verdict::StableBelow => "stable below its limit",
            Verdict::UnconditionallyStable => "stable at every step",
            Verdict::UnstableForAllDt => "unstable at every step",
            Verdict::NotAnalysed => "not analysed",
        }
    }
}

/// A verdict with its step limit (s) when `stable_below`.
pub type Limit = (Verdict, Option<f64>);

/// Largest stable step on one mode: (verdict, limit).
pub fn mode_limit(method: &Method, opts: &MethodOptions, m: Mode) -> (Verdict, Option<f64>) {
    let w = m.omega2.sqrt().max(m.damping);
    if w <= 0.0 {
        return (Verdict::UnconditionallyStable, None);
    }
    let lo = scan_min(m);
    let n = (24.0 * (SCAN_MAX / lo).log10()).ceil() as usize + 1;
    let hs: Vec<f64> = (0..n)
        .map(|i| lo * (SCAN_MAX / lo).powf(i as f64 / (n - 1) as f64) / w)
        .collect();
    // A step the method cannot take (say, Newton fails at enormous hω) ends the scan: it
    // says nothing about stability, so the verdict rests on the steps that ran.
    let state = |h: f64| step_radius(method, opts, m, h).map(|r| r <= 1.0 + RHO_TOL);
    let stable = |h: f64| state(h).unwrap_or(false);
    match state(hs[0]) {
        Some(true) => {}
        _ => return (Verdict::UnstableForAllDt, None),
    }
    let mut first_bad = None;
    for (i, &h) in hs.iter().enumerate() {
        match state(h) {
            Some(true) => {}
            Some(false) => {
                first_bad = Some(i);
                break;
            }
            None => break,
        }
    }
    let Some(first_bad) = first_bad else {
        return (Verdict::UnconditionallyStable, None);
    };
    let (mut lo, mut hi) = (hs[first_bad - 1], hs[first_bad]);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if stable(mid) {
            lo = mid
        } else {
            hi = mid
        }
    }
    (Verdict::StableBelow, Some(lo))
}

/// The smallest hω the scan of mode `m` tries: [`SCAN_MIN`], or for a damped mode two decades
/// below its damping ratio ζ = c/(2ω) when that is smaller. A damped mode's explicit limits
/// scale with ζ (explicit Euler is stable iff |1 + hλ| < 1 for λ = ω(−ζ ± i√(1 − ζ²)), that
/// is hω < 2ζ), so a lightly damped mode has a limit below [`SCAN_MIN`] that a scan starting
/// there would miss and call unstable at every step. An undamped mode keeps [`SCAN_MIN`]: its
/// explicit methods are unstable at every step, by ρ − 1 ≈ (hω)²/2 (explicit Euler) or
/// (hω)⁴/8 (RK2), which a smaller hω would push below [`RHO_TOL`].
pub fn scan_min(m: Mode) -> f64 {
    let w = m.omega2.sqrt();
    if m.damping > 0.0 && w > 0.0 {
        SCAN_MIN.min(1e-2 * m.damping / (2.0 * w))
    } else {
        SCAN_MIN
    }
}

/// Theory for a method over all modes: the tightest mode decides.
pub fn theory_limit(method: &Method, opts: &MethodOptions, ms: &Modes) -> (Verdict, Option<f64>) {
    let mut best = (Verdict::UnconditionallyStable, None::<f64>);
    for &m in &ms.modes {
        match mode_limit(method, opts, m) {
            (Verdict::UnstableForAllDt, _) => return (Verdict::UnstableForAllDt, None),
            (Verdict::StableBelow, Some(h)) if best.1.is_none_or(|b| h < b) => {
                best = (Verdict::StableBelow, Some(h));
            }
            _ => {}
        }
    }
    best
}
