//! The known schemes Rapier's behaviour matches, as predicted curves to plot next to the
//! measured ones.
//!
//! Identified by reading Rapier 0.36's solver and confirmed by experiment (tests/physics/rapier_scheme.rs):
//! a frame of step h is `substeps` = N substeps of h/N (`num_solver_iterations`); each substep
//! applies gravity to the velocities, solves every joint once as a soft constraint, then moves
//! the positions with the new velocities (symplectic Euler). A force-based spring motor with
//! stiffness k and damping c is solved with erp/dt = k/(h_s k + c) and cfm = 1/(h_s² k + h_s c):
//! that impulse is exactly the backward-Euler step of the spring along its current axis,
//! m(v⁺ − v) = −h_s (k (e + h_s v⁺) + c v⁺). So:
//! - free fall: symplectic Euler at h/N, x_M = x₀ + v₀ M h_s + g h_s² M(M+1)/2 after M substeps;
//! - one spring: linearly-implicit (backward) Euler at h/N along the spring axis; on a 1-D
//!   oscillator its energy ½(v² + ω²e²) decays by exactly 1/(1 + (ω h/N)²) per substep.
//!
//! Being first order in h/N, the scheme's deviation is small but shows late and suddenly on
//! motions that amplify any deviation. On the hanging chain (scenarios/hanging_chain.toml) at
//! h = 1/60 s with N = 1024, `rapier_impulse` is 3.4e-4 m from the exact motion at t = 1.0 s
//! and 1.0e-2 m at 1.1 s: over that window the free end recoils, its last springs compress by
//! up to 27 %, and the chain itself multiplies a deviation by ~29 (rk4 restarted from Rapier's
//! state at 1.0 s lands within 1.4e-4 m of Rapier at 1.1 s, so Rapier adds no event of its
//! own). 4× the substeps divide the deviation by 4 (1.0 s) to 3.75 (1.1 s): 8.3e-4 m at 1.1 s
//! with N = 16384 (tests/physics/rapier_hanging_chain.rs).
//!
//! `rapier_multibody` matches the free-fall scheme (bodies without joints are plain rigid
//! bodies) but its springs are Rapier's implicit joint springs in reduced coordinates, solved
//! with the generalized mass matrix once per frame; measured on an anchored oscillator their
//! energy decay matches neither backward Euler at h nor at h/N, so no prediction is claimed.

use crate::model::{State, System, Vec3};

/// A scheme's predicted curve of a quantity for comparison with a measured run.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Prediction {
    /// The scheme, in words.
    pub scheme: String,
    /// The quantity on the curve (always the mechanical energy K + G + E, in J).
    pub quantity: &'static str,
    /// (t, value) at every frame, t = 0 first.
    pub curve: Vec<(f64, f64)>,
}

/// The curve predicted for the Rapier method of `mode` on `sys` from `s0` over `steps` frames of `h` with `substeps`
/// substeps, when Rapier matches a known scheme there: free fall (no springs, constraints or
/// drag) and single-spring scenes without constraints or drag. `None` otherwise: with several
/// joints Rapier's sequential (Gauss–Seidel) joint sweep is not one textbook scheme.
pub fn scheme_prediction(
    mode: super::Mode,
    sys: &System,
    s0: &State,
    h: f64,
    substeps: usize,
    steps: u64,
) -> Option<Prediction> {
    if !sys.constraints.is_empty() || sys.drag.is_some() || sys.springs.len() > 1 {
        return None;
    }
    // A multibody joint is not a soft-constraint spring: only its free fall is known.
    if mode == super::Mode::Multibody && !sys.springs.is_empty() {
        return None;
    }
    let n = substeps.max(1);
    let hs = h / n as f64;
    let scheme = if sys.springs.is_empty() {
        format!("symplectic Euler at h/{n} (free fall)")
    } else {
        format!("backward Euler at h/{n} along the spring axis (soft-constraint spring)")
    };
    let g = sys.gravity.unwrap_or_else(Vec3::zeros);
    let mut x = s0.x.clone();
    let mut v = s0.v.clone();
    let mut curve = Vec::with_capacity(steps as usize + 1);
    curve.push((s0.t, sys.energy(&x, &v).mechanical()));
    for f in 1..=steps {
        for _ in 0..n {
            substep(sys, &mut x, &mut v, g, hs);
        }
        curve.push((s0.t + f as f64 * h, sys.energy(&x, &v).mechanical()));
    }
    Some(Prediction {
        scheme,
        quantity: "mechanical energy (J)",
        curve,
    })
}

/// One substep: gravity kick, backward-Euler spring impulses, drift.
fn substep(sys: &System, x: &mut [Vec3], v: &mut [Vec3], g: Vec3, hs: f64) {
    for (vp, _) in v.iter_mut().zip(&sys.free).filter(|(_, &f)| f) {
        *vp += g * hs;
    }
    let sp = &sys.springs;
    for s in 0..sp.len() {
        let (a, b) = (sp.i[s] as usize, sp.j[s] as usize);
        let d = x[b] - x[a];
        let len = d.norm();
        if len == 0.0 {
            continue;
        }
        let nrm = d / len;
        let (wa, wb) = (sys.inv_mass[a], sys.inv_mass[b]);
        let soft = hs * hs * sp.k[s] + hs * sp.c[s];
        if soft == 0.0 || wa + wb == 0.0 {
            continue;
        }
        let vrel = (v[b] - v[a]).dot(&nrm);
        let bias = hs * sp.k[s] * (len - sp.l0[s]) / soft;
        let lambda = -(vrel + bias) / (wa + wb + 1.0 / soft);
        v[a] -= nrm * (lambda * wa);
        v[b] += nrm * (lambda * wb);
    }
    for ((xp, vp), _) in x
        .iter_mut()
        .zip(v.iter())
        .zip(&sys.free)
        .filter(|(_, &f)| f)
    {
        *xp += *vp * hs;
    }
}
