//! Period and phase of the tracked velocity component, from its upward zero crossings.
//!
//! A period means something only when the tracked signal has one dominant mode. The test is on
//! the reference's zero crossings, upward (period T = their mean spacing) and downward: at
//! least two upward and three in all, every interval between upward neighbours within
//! [`DOMINANT_MODE_SPREAD`]·T of T and every interval between neighbours of either kind
//! within as much of T/2. A single mode (damped or not, linear or a pendulum's swing) spaces
//! its crossings evenly, half a period apart; a second mode of velocity amplitude ε against
//! the first moves each crossing by up to about arcsin(ε)/ω, so intervals differ from their
//! due by up to about ε/π·T. The test admits a second mode up to ε ≈ 0.15 (whose mean spacing
//! still gives the first mode's period to 2·arcsin(ε)/ω over the whole record) and refuses a
//! real mix, whose crossings bunch, drop out or double (two modes of a chain at comparable
//! amplitude give intervals 20 % to 80 % off their mean). Elsewhere period and phase are
//! absent ([`DOMINANT_MODE_UNCLEAR`]).
//!
//! A run's crossings are matched to the reference's by time ([`match_crossings`]), never by
//! count: a crossing a run adds or misses (a near-tangent zero of the velocity, sampled at
//! other steps) is left unmatched instead of shifting every later pair by a period.

/// Largest deviation of an interval between neighbouring reference crossings from their mean,
/// relative to the mean, for the tracked signal to count as one dominant mode.
pub const DOMINANT_MODE_SPREAD: f64 = 0.05;

/// Why a run has no period or phase: the reference's crossings do not show one dominant mode.
pub const DOMINANT_MODE_UNCLEAR: &str = "no dominant mode: the reference's zero crossings of the tracked velocity are too few (two upward, three in all) or not evenly spaced, so a period would count the mix of modes, not one";

/// Period from a list of upward crossing times: mean spacing first to last.
pub fn period_of(c: &[f64]) -> Option<f64> {
    (c.len() >= 2).then(|| (c[c.len() - 1] - c[0]) / (c.len() - 1) as f64)
}

/// The period of upward crossings `up` when they and the downward crossings `down` show one
/// dominant mode (module docs); else the reason.
pub fn dominant_period(up: &[f64], down: &[f64]) -> Result<f64, &'static str> {
    let t = match period_of(up) {
        Some(t) if up.len() + down.len() >= 3 && t > 0.0 => t,
        _ => return Err(DOMINANT_MODE_UNCLEAR),
    };
    let mut all: Vec<f64> = up.iter().chain(down).copied().collect();
    all.sort_by(f64::total_cmp);
    let near = |c: &[f64], due: f64| {
        c.windows(2)
            .all(|w| ((w[1] - w[0]) - due).abs() <= DOMINANT_MODE_SPREAD * t)
    };
    if near(up, t) && near(&all, 0.5 * t) {
        Ok(t)
    } else {
        Err(DOMINANT_MODE_UNCLEAR)
    }
}

/// Pairs each reference crossing (index into `reference`) with the run crossing nearest to
/// where the run's last matched offset puts it, within half a `period`; reference crossings
/// without one stay unpaired, run crossings nobody chose are left out. Both lists ascend.
/// Tracking the offset lets a run drift by up to half a period per period and keeps its phase
/// unwrapped.
pub fn match_crossings(reference: &[f64], run: &[f64], period: f64) -> Vec<(usize, f64)> {
    let half = 0.5 * period;
    let (mut pairs, mut offset, mut j) = (Vec::new(), 0.0, 0);
    for (k, &r) in reference.iter().enumerate() {
        let want = r + offset;
        while j < run.len() && run[j] < want - half {
            j += 1;
        }
        let best = run[j..]
            .iter()
            .take_while(|&&c| c <= want + half)
            .enumerate()
            .min_by(|a, b| (a.1 - want).abs().total_cmp(&(b.1 - want).abs()));
        if let Some((i, &c)) = best {
            pairs.push((k, c));
            offset = c - r;
            j += i + 1;
        }
    }
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    #[test]
    fn one_mode_is_evenly_spaced_and_a_mix_is_not() {
        // Oracle: v = −sin(t) crosses zero upwards at 2πk and downwards at π + 2πk exactly;
        // v = −(sin t + sin √3t), two modes of equal velocity amplitude, at unevenly spaced
        // times (found on a fine grid).
        let up: Vec<f64> = (0..6).map(|k| TAU * k as f64).collect();
        let down: Vec<f64> = up.iter().map(|t| t + 0.5 * TAU).collect();
        assert!((dominant_period(&up, &down).unwrap() - TAU).abs() < 1e-12);
        // Two periods' worth: one upward interval, checked against the downward crossings.
        assert!((dominant_period(&up[..2], &down[..1]).unwrap() - TAU).abs() < 1e-12);
        assert!(
            dominant_period(&up[..2], &[]).is_err(),
            "one interval shows nothing"
        );
        assert!(
            dominant_period(&up[..2], &[0.3 * TAU]).is_err(),
            "not half way"
        );
        let v = |t: f64| -(t.sin() + (3f64.sqrt() * t).sin());
        let (mut mix, mut mix_down, mut prev, n) = (vec![], vec![], v(1e-3), 200_000);
        for i in 1..=n {
            let t = 1e-3 + 40.0 * i as f64 / n as f64;
            let x = v(t);
            if prev < 0.0 && x >= 0.0 {
                mix.push(t);
            } else if prev >= 0.0 && x < 0.0 {
                mix_down.push(t);
            }
            prev = x;
        }
        assert!(mix.len() >= 6, "{mix:?}");
        assert_eq!(dominant_period(&mix, &mix_down), Err(DOMINANT_MODE_UNCLEAR));
    }

    #[test]
    fn an_extra_or_a_missing_run_crossing_shifts_no_pair() {
        // Oracle: a run 0.1 s late on every crossing of period 2 s, with one crossing added
        // (a near-tangent blip) and one missing: every other crossing pairs with its own, so
        // the last pair gives the phase 2π·0.1/2 and the pairs the period 2.
        let reference: Vec<f64> = (0..8).map(|k| 1.0 + 2.0 * k as f64).collect();
        let mut run: Vec<f64> = reference.iter().map(|r| r + 0.1).collect();
        run.remove(5);
        run.insert(3, 6.5);
        let pairs = match_crossings(&reference, &run, 2.0);
        assert_eq!(pairs.len(), 7, "{pairs:?}");
        assert!(pairs
            .iter()
            .all(|&(k, c)| (c - reference[k] - 0.1).abs() < 1e-12));
        assert!(!pairs.iter().any(|&(k, _)| k == 5));
        // A run that drifts by a quarter period per period keeps its unwrapped offset.
        let drift: Vec<f64> = (0..8).map(|k| 1.0 + 2.5 * k as f64).collect();
        let pairs = match_crossings(&reference, &drift, 2.0);
        assert_eq!(pairs.len(), 8);
        assert!((pairs[7].1 - reference[7] - 3.5).abs() < 1e-12, "{pairs:?}");
    }
}
