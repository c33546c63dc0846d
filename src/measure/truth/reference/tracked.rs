//! The velocity component whose sign changes the reference records: the scene's oscillation,
//! for its period and phase.

use super::rhs::{pack, RhsState};
use crate::model::{State, System, Vec3};
use serde::Serialize;

/// The velocity component tracked for period and phase: particle and axis (0 = x).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct Tracked {
    /// Particle index.
    pub particle: usize,
    /// Axis 0, 1 or 2.
    pub axis: usize,
}

/// The velocity component whose sign changes mark the scene's oscillation: the free
/// particle and axis with the largest initial acceleration (rigid-constraint forces included),
/// preferring axes across gravity when any has one (a pendulum's swing, not its bob's
/// up-and-down at twice the frequency); without acceleration, the largest initial velocity.
pub fn tracked_component(sys: &System, s0: &State) -> Option<Tracked> {
    let n = sys.len();
    let rigid: Vec<usize> = (0..sys.constraints.len())
        .filter(|&c| sys.constraints[c].compliance == 0.0)
        .collect();
    let mut st = RhsState::new(sys, rigid);
    let y = pack(&s0.x, &s0.v);
    let mut dy = vec![0.0; 6 * n];
    st.eval(0.0, &y, &mut dy);
    let a: Vec<Vec3> = (0..n)
        .map(|p| {
            Vec3::new(
                dy[3 * n + 3 * p],
                dy[3 * n + 3 * p + 1],
                dy[3 * n + 3 * p + 2],
            )
        })
        .collect();
    let g_axis = sys
        .gravity
        .and_then(|g| (0..3).find(|&k| g[k] != 0.0 && g.norm() == g[k].abs()));
    let pick = |vals: &[Vec3], skip: Option<usize>| {
        let mut best: Option<(f64, Tracked)> = None;
        for p in (0..n).filter(|&p| sys.free[p]) {
            for axis in (0..3).filter(|&k| Some(k) != skip) {
                let m = vals[p][axis].abs();
                if m > 1e-12 * vals[p].norm() && m > 0.0 && best.is_none_or(|(b, _)| m > b) {
                    best = Some((m, Tracked { particle: p, axis }));
                }
            }
        }
        best.map(|b| b.1)
    };
    pick(&a, g_axis)
        .or_else(|| pick(&a, None))
        .or_else(|| pick(&s0.v, None))
}
