//! Accuracy on bouncing scenes, judged bounce by bounce rather than instant by instant.
//!
//! On a scene with obstacles and gravity, a method that strikes the floor a little early or
//! late is a little ahead or behind from then on, and its position error at equal times is
//! about twice the impact speed times that lag: one impact's timing dominates the number. What a
//! viewer sees of a bounce is how high it goes. So each free particle's *apex heights* (local
//! maxima of its height along −g) are compared with the reference's, the k-th with the k-th:
//! an early or late bounce that reaches the right height costs nothing, a wrong restitution or
//! a lost bounce does.
//!
//! Both trajectories are read at the same compared samples; an apex is a sample higher than
//! the one before and at least as high as the one after, its height refined by the parabola
//! through the three (exact for a ballistic arc). A bounce counts when its apex rises more
//! than [`crate::measure::tolerance::RELATIVE_TOLERANCE`] of the motion scale above the lowest
//! point since the previous one (smaller ones are the contact settling, which the reference
//! holds still). The two sequences of a particle are aligned in order, the alignment chosen to
//! make the largest cost smallest: a matched pair costs |apex − reference apex|, a bounce one
//! side has and the other lacks costs its rise (so an extra small bounce costs what it shows,
//! and does not shift every later pairing). The apex error is the largest cost over particles.
//! What this metric does not see is motion across gravity (sliding); `--metric position`
//! judges that.

use crate::model::Vec3;

/// Apex heights of every free particle along a sequence of equally spaced samples.
#[derive(Debug, Clone)]
pub struct Apexes {
    up: Vec3,
    free: Vec<bool>,
    /// Per particle: the two previous heights.
    prev: Vec<[f64; 2]>,
    /// Per particle: the lowest height since the last counted apex.
    low: Vec<f64>,
    samples: usize,
    threshold: f64,
    /// Per particle: (apex height, rise above the low before it).
    pub found: Vec<Vec<(f64, f64)>>,
}

impl Apexes {
    /// A tracker for particles `free` under gravity `g`, counting bounces that rise more than
    /// `threshold` (m).
    pub fn new(g: Vec3, free: &[bool], threshold: f64) -> Self {
        let n = free.len();
        Apexes {
            up: -g / g.norm(),
            free: free.to_vec(),
            prev: vec![[0.0; 2]; n],
            low: vec![f64::INFINITY; n],
            samples: 0,
            threshold,
            found: vec![Vec::new(); n],
        }
    }

    /// Adds the next sample's positions.
    pub fn push(&mut self, x: &[Vec3]) {
        for p in 0..x.len() {
            if !self.free[p] {
                continue;
            }
            let y2 = x[p].dot(&self.up);
            let [y0, y1] = self.prev[p];
            if self.samples >= 2 && y1 > y0 && y1 >= y2 {
                let curv = y0 - 2.0 * y1 + y2;
                let apex = if curv < 0.0 {
                    y1 - (y0 - y2).powi(2) / (8.0 * curv)
                } else {
                    y1
                };
                let rise = apex - self.low[p];
                if rise > self.threshold {
                    self.found[p].push((apex, rise));
                    self.low[p] = f64::INFINITY;
                }
            }
            self.low[p] = self.low[p].min(y2);
            self.prev[p] = [y1, y2];
        }
        self.samples += 1;
    }

    /// The apex error against `reference` (tracked over the same samples): per particle, the
    /// two apex sequences aligned in order so that the largest cost is smallest (a matched pair
    /// costs |apex − reference apex|, a bounce left unmatched on either side its rise), the
    /// largest over particles; None when neither side bounced.
    pub fn error(&self, reference: &Apexes) -> Option<f64> {
        let mut worst: Option<f64> = None;
        for (a, r) in self.found.iter().zip(&reference.found) {
            if a.is_empty() && r.is_empty() {
                continue;
            }
            worst = Some(worst.unwrap_or(0.0).max(bottleneck(a, r)));
        }
        worst
    }
}

/// The smallest possible largest cost of an order-keeping alignment of `a` with `r`
/// ((apex, rise) each): a pair costs the apexes' difference, a skip the skipped rise. Dynamic
/// programming over prefixes, O(|a|·|r|).
fn bottleneck(a: &[(f64, f64)], r: &[(f64, f64)]) -> f64 {
    let (n, m) = (a.len(), r.len());
    let mut d = vec![vec![f64::INFINITY; m + 1]; n + 1];
    d[0][0] = 0.0;
    for i in 0..=n {
        for j in 0..=m {
            let mut v = d[i][j];
            if i > 0 && j > 0 {
                v = v.min(d[i - 1][j - 1].max((a[i - 1].0 - r[j - 1].0).abs()));
            }
            if i > 0 {
                v = v.min(d[i - 1][j].max(a[i - 1].1));
            }
            if j > 0 {
                v = v.min(d[i][j - 1].max(r[j - 1].1));
            }
            d[i][j] = v;
        }
    }
    d[n][m]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Heights of a ball dropped from `h0` bouncing with restitution `e` on y = 0 under g,
    /// sampled every `dt` for `t_end` (before the bounces accumulate), started `lag` s late.
    fn bounces(h0: f64, e: f64, dt: f64, t_end: f64, lag: f64) -> Vec<Vec3> {
        let g = 9.81;
        let mut out = Vec::new();
        let mut k = 0;
        loop {
            let t = k as f64 * dt - lag;
            if k as f64 * dt > t_end {
                break;
            }
            // Closed form: flight n starts at impact time t_n with speed v_n.
            let (mut t0, mut v, mut y) = (0.0, 0.0, h0);
            let yt;
            loop {
                let tf = (v + (v * v + 2.0 * g * y).sqrt()) / g;
                if t.max(0.0) < t0 + tf || tf < 1e-9 {
                    let s = t.max(0.0) - t0;
                    yt = y + v * s - 0.5 * g * s * s;
                    break;
                }
                t0 += tf;
                v = e * (v * v + 2.0 * g * y).sqrt();
                y = 0.0;
            }
            out.push(Vec3::new(0.0, yt, 0.0));
            k += 1;
        }
        out
    }

    fn track(xs: &[Vec3]) -> Apexes {
        let mut a = Apexes::new(Vec3::new(0.0, -9.81, 0.0), &[true], 1e-3);
        for x in xs {
            a.push(std::slice::from_ref(x));
        }
        a
    }

    // Oracle: a ball's apexes are h0·e^(2n) (energy lost per bounce is 1 − e²); a copy lagging
    // by 3 ms has the same apexes (error at the parabola fit's round-off), while its position
    // error at equal times is near twice the impact speed times the lag.
    #[test]
    fn a_late_bounce_of_the_right_height_costs_nothing() {
        let (h0, e) = (1.0, 0.5);
        let r = track(&bounces(h0, e, 1e-3, 1.2, 0.0));
        let apexes: Vec<f64> = r.found[0].iter().map(|a| a.0).collect();
        assert!(apexes.len() >= 2, "{apexes:?}");
        for (n, a) in apexes.iter().enumerate() {
            let want = h0 * e.powi(2 * (n as i32 + 1));
            assert!((a - want).abs() < 1e-6, "apex {n}: {a} vs {want}");
        }
        let late = track(&bounces(h0, e, 1e-3, 1.2, 3e-3));
        assert!(late.error(&r).unwrap() < 1e-6);
        // Twin: a restitution 10 % off changes the first apex by 1 − 1.1² of 0.25 m.
        let wrong = track(&bounces(h0, 0.55, 1e-3, 1.2, 0.0));
        let err = wrong.error(&r).unwrap();
        assert!((err - (0.55f64.powi(2) - 0.25)).abs() < 1e-3, "{err}");
    }

    // Oracle: worked by hand. An extra low bounce (rise 0.02) in the middle of an otherwise
    // equal sequence costs its rise, not a misalignment of every later apex (0.3 here).
    #[test]
    fn an_extra_bounce_costs_its_rise() {
        let r = [(1.0, 1.0), (0.5, 0.5), (0.2, 0.2)];
        let a = [(1.0, 1.0), (0.5, 0.5), (0.02, 0.02), (0.2, 0.2)];
        assert!((bottleneck(&a, &r) - 0.02).abs() < 1e-15);
        assert_eq!(bottleneck(&r, &r), 0.0);
        assert!((bottleneck(&[], &r) - 1.0).abs() < 1e-15);
    }
}
