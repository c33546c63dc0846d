//! Rule 5 of [`super::verdict`]: growth over the run's own length. A run shorter than the
//! growth windows of rule 3 (a game's 40 frames) still shows an instability by how its peak
//! rise grows across the octaves of its own length: steps n/8 → n/4 → n/2 → n.
//!
//! Let P(m) be the largest rise of the energy balance over steps 1..=m. The rule fires at step
//! n when P(n) is above [`RUNAWAY_LEVEL`] × the scene's energy scale E and P grew at least
//! [`OCTAVE_RATIO`]-fold over each of the last [`OCTAVES`] octaves. Why this separates growth
//! from a bounded swing:
//!
//! - An unstable mode's energy grows like ρ²ⁿ, so the octave ending at n multiplies it by
//!   ρⁿ, which passes 10 once n ln ρ ≥ ln 10 and keeps growing: every late octave qualifies.
//! - A bounded swing rises from where it starts at most quadratically: its energy envelope
//!   above its starting value is sin²(εm) (a stable mode's energy beats between its start and
//!   a bounded maximum), and sin²(2x)/sin²(x) = 4cos²x ≤ 4. Started at a later step t₀ (a
//!   kick, a contact), (m − t₀)² gives one octave of any ratio (the one holding t₀), the next
//!   ((2x − 1)/(x − 1))² with x = m/t₀ ∈ [1, 2) (≥ 10 only for x ≤ 1.86), and the one after at
//!   most 9: never three in a row. A polynomial drift tᵖ gives 2ᵖ per octave, ≥ 10 only for
//!   p ≥ 3.32 (such a drift is unbounded and past 10 E unstable by rule 4 anyway).
//! - Before the balance rises at all, a rise from 0 to round-off is not growth: P is floored at
//!   [`NOISE_FLOOR`] × E.
//!
//! The peaks are kept at log-spaced checkpoints (every `CHECKPOINT_GROWTH` in steps), and the
//! octave ends are read at the first checkpoint at or after m: a checkpoint's peak is at least
//! P(m), so the ratios read are at most the true ones (the rule errs towards "bounded").

/// The rise, in scene energy scales, that the peak must exceed: ten scenes' worth of energy,
/// which no physical run books.
pub const RUNAWAY_LEVEL: f64 = 10.0;
/// The growth of the peak rise over each octave of the run's length.
pub const OCTAVE_RATIO: f64 = 10.0;
/// Consecutive octaves (ending at the current step) that must each grow by [`OCTAVE_RATIO`].
pub const OCTAVES: u32 = 3;
/// Peaks below this fraction of the scene's energy scale count as this fraction (round-off).
pub const NOISE_FLOOR: f64 = 1e-9;
/// Relative spacing of the checkpoints.
const CHECKPOINT_GROWTH: f64 = 1.02;

/// The running peak of one run, at log-spaced checkpoints.
#[derive(Debug, Clone, Default)]
pub struct Runaway {
    /// (step, peak rise over steps 1..=step), steps increasing.
    marks: Vec<(u64, f64)>,
    peak: f64,
}

/// What rule 5 saw when it fired: the peaks at n/8, n/4, n/2 and n (J).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Octaves {
    /// Steps at which the peaks were read, oldest first.
    pub steps: [u64; 4],
    /// The peaks there.
    pub peaks: [f64; 4],
}

impl Runaway {
    /// Takes the rise of step `n` (1-based, in order) on a scene of energy scale `scale`:
    /// `Some` when the rule fires.
    pub fn push(&mut self, n: u64, rise: f64, scale: f64) -> Option<Octaves> {
        self.peak = if n == 1 { rise } else { self.peak.max(rise) };
        let due = self
            .marks
            .last()
            .is_none_or(|&(s, _)| n as f64 >= (s as f64 * CHECKPOINT_GROWTH).max(s as f64 + 1.0));
        if due {
            self.marks.push((n, self.peak));
        }
        let step = 1u64 << OCTAVES;
        if n < step || self.peak <= RUNAWAY_LEVEL * scale {
            return None;
        }
        let floor = NOISE_FLOOR * scale;
        let mut steps = [0u64; 4];
        let mut peaks = [0f64; 4];
        for k in 0..=OCTAVES {
            let m = n.div_ceil(1 << (OCTAVES - k));
            let (s, p) = self
                .marks
                .iter()
                .copied()
                .find(|&(s, _)| s >= m)
                .unwrap_or((n, self.peak));
            steps[k as usize] = s;
            peaks[k as usize] = p.max(floor);
        }
        let grew = peaks.windows(2).all(|w| w[1] >= OCTAVE_RATIO * w[0]);
        grew.then_some(Octaves { steps, peaks })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first step at which rule 5 fires on rises `r(n)`, over `steps` steps, scale 1.
    fn first(r: impl Fn(f64) -> f64, steps: u64) -> Option<u64> {
        let mut w = Runaway::default();
        (1..=steps).find(|&n| w.push(n, r(n as f64), 1.0).is_some())
    }

    #[test]
    fn geometric_growth_fires_within_a_short_run() {
        // Oracle: ρ²ⁿ growth. ×1.5 a step from 1e-3 scales: past 10 scales by step 23, and
        // the shortest octave, about n/8 steps, multiplies by 1.5^(n/8) ≥ 10 from n ≈ 45.
        let n = first(|n| 1e-3 * 1.5f64.powf(n), 1000).expect("fires");
        assert!((41..=48).contains(&n), "{n}");
        // Twin: the same growth stopped at 8 scales never passes the level.
        assert_eq!(first(|n| (1e-3 * 1.5f64.powf(n)).min(8.0), 10_000), None);
    }

    #[test]
    fn a_quadratic_swing_from_any_start_never_fires() {
        // Oracle: the octave argument of the module doc. A swing of 1000 scales that rises
        // like sin² from step t0 (flat at 0, then round-off, before), over many periods.
        for t0 in [0.0, 3.0, 7.0, 13.0, 50.0, 333.0] {
            for eps in [0.001, 0.01, 0.1, 0.5] {
                let swing = |n: f64| {
                    if n <= t0 {
                        1e-16 * n
                    } else {
                        1000.0 * (eps * (n - t0)).sin().powi(2)
                    }
                };
                assert_eq!(first(swing, 20_000), None, "t0 = {t0}, ε = {eps}");
            }
        }
    }

    #[test]
    fn polynomial_drifts_fire_only_past_a_cube_and_a_third() {
        // Oracle: tᵖ grows 2ᵖ per octave, ≥ 10 only for p ≥ log2 10 = 3.32.
        assert_eq!(first(|n| 1e-6 * n.powi(3), 1_000_000), None);
        assert!(first(|n| 1e-6 * n.powi(4), 1_000_000).is_some());
    }
}
