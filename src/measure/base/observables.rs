//! The one definition of each quantity every measure compares a run with: position error,
//! strain, whether a scene bounces, and the default tolerance relative to the motion scale.
//! A leaf: references, metrics, statistics and judging all read these.

use crate::model::{System, Vec3};

/// Default tolerance relative to the motion scale.
pub const RELATIVE_TOLERANCE: f64 = 0.01;

/// Position error e = max over particles |x_i − y_i| (m) between two configurations of the
/// same particles: the one definition every measure compares positions with.
pub fn position_error(x: &[Vec3], y: &[Vec3]) -> f64 {
    x.iter()
        .zip(y)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max)
}

/// Largest strain |l/l0 − 1| at positions `x` over every spring with a rest length l0 > 0 and
/// every distance constraint (l0 its length), l = |x_j − x_i|; 0 without either. A serial
/// loop in index order, so the value is the same bits whatever the thread count.
pub fn strain_max(sys: &System, x: &[Vec3]) -> f64 {
    let sp = &sys.springs;
    let springs = (0..sp.len()).map(|s| (sp.i[s] as usize, sp.j[s] as usize, sp.l0[s]));
    let rods = sys.constraints.iter().map(|c| (c.i, c.j, c.length));
    springs
        .chain(rods)
        .filter(|&(_, _, l0)| l0 > 0.0)
        .map(|(i, j, l0)| ((x[j] - x[i]).norm() / l0 - 1.0).abs())
        .fold(0.0, f64::max)
}

/// True for a scene whose accuracy is judged bounce by bounce ([`crate::measure::apexes`]): it has
/// obstacles and gravity.
pub fn bouncing(sys: &System) -> bool {
    crate::collide::of(sys).is_some() && sys.gravity.is_some_and(|g| g.norm() > 0.0)
}
