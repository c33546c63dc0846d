//! The benchmark baseline: one symplectic Euler step of a scene's springs, dampers
//! and gravity written as one plain loop over the same flat arrays (fill with gravity, scatter
//! spring forces, kick-drift). No force terms, no energy account, no guards: what a game
//! programmer would write by hand, and the floor springlab's own step is compared against.

use crate::model::{System, Vec3};

/// One hand-written symplectic Euler step of `sys`'s springs (with dampers) and gravity.
/// `f` is scratch of one entry per particle. Coincident spring ends give NaN here, as they
/// would in such a loop; the benchmark cloths have none.
pub fn hand_step(sys: &System, x: &mut [Vec3], v: &mut [Vec3], f: &mut [Vec3], h: f64) {
    let g = sys.gravity.unwrap_or_else(Vec3::zeros);
    let sp = &sys.springs;
    for p in 0..f.len() {
        f[p] = if sys.free[p] {
            g * sys.mass[p]
        } else {
            Vec3::zeros()
        };
    }
    for s in 0..sp.i.len() {
        let (a, b) = (sp.i[s] as usize, sp.j[s] as usize);
        let d = x[b] - x[a];
        let len = d.norm();
        let n = d / len;
        let vrel = (v[b] - v[a]).dot(&n);
        let fs = n * (sp.k[s] * (len - sp.l0[s]) + sp.c[s] * vrel);
        f[a] += fs;
        f[b] -= fs;
    }
    for p in 0..x.len() {
        v[p] += f[p] * (sys.inv_mass[p] * h);
        x[p] += v[p] * h;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::{Stepper, SymplecticEuler};

    /// Oracle: springlab's symplectic Euler on the same cloth; the hand loop must do the same
    /// physics (to rounding: its force expression groups the terms the same way, but it folds
    /// gravity into the initial fill).
    #[test]
    fn hand_loop_steps_like_symplectic_euler() {
        let scene = crate::perf::cloth(12);
        let sys = scene.build();
        let mut s = scene.initial_state();
        let (mut x, mut v) = (s.x.clone(), s.v.clone());
        let mut f = vec![Vec3::zeros(); sys.len()];
        let mut se = SymplecticEuler::default();
        for _ in 0..50 {
            se.step(&sys, &mut s, 1e-3).unwrap();
            hand_step(&sys, &mut x, &mut v, &mut f, 1e-3);
        }
        for p in 0..sys.len() {
            assert!((s.x[p] - x[p]).amax() < 1e-12, "particle {p}");
            assert!((s.v[p] - v[p]).amax() < 1e-9, "particle {p}");
        }
    }
}
