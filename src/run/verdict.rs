//! The one verdict on a run: **stable means bounded.** A run is unstable when its numerical
//! solution grows without bound, not when it is inaccurate; inaccuracy is what the error and
//! energy columns report. Every command (run, compare, sweep, stability's empirical search and
//! map, advise, framerate, small-steps, the report, and the library's measures) reaches this
//! rule through [`crate::run::run`], which feeds [`Verdict`] every step.
//!
//! The measure is the run's energy balance [`EnergyRecord::total`] (kinetic, gravity and
//! elastic energy, plus what was dissipated, minus what impulses injected): energy that went into dampers, drag and contacts counts, so a run
//! cannot hide a gain behind the damping it also computed. The exact solution keeps it constant;
//! its rise above the value at t = 0 is compared with the scene's energy scale E
//! ([`super::energy_scale`]). A step is judged unstable, with the first rule that fires:
//!
//! 1. **Diverged**: a position, velocity or energy term is not finite.
//! 2. **Past the cap**: the balance rose by more than `cap` × E (`--blowup-factor`, default
//!    [`DEFAULT_BLOWUP_FACTOR`] = 1000). No physical run moves more than about E, and a bounded
//!    oscillation overshoots it only by a bounded factor: symplectic Euler on x'' = −ω²x
//!    conserves a shadow energy, so its true energy swings by up to (1 + hω/2)/(1 − hω/2) times
//!    its start (19 at 0.9 of its limit hω = 2, 132 at 0.985), which passes 1000 only beyond
//!    0.998 of the limit. A run that books a thousand scenes' worth of energy is producing it
//!    without bound, even where the state itself stays bounded (a method past its linear limit
//!    that settles on a spurious cycle, pumping energy into a damper every step).
//! 3. **Growing**: the largest rise within windows of [`GROWTH_WINDOWS`] steps has at least
//!    doubled ([`GROWTH_RATIO`]) from each window to the next for [`GROWTH_RUN`] windows in a row,
//!    and is above E. An unstable linear mode multiplies its energy by ρ^2W per window (ρ > 1 the
//!    spectral radius), so it doubles in every window once W ln ρ² ≥ ln 2. A bounded oscillation
//!    cannot: its envelope rises from the start like sin², so the peaks of successive windows
//!    grow at most by (k+1)²/k² (4, 2.25, 1.78: the third fails), and a drift that grows like
//!    t^p fails by the fifth window for any p < 3.8 ((6/5)^p < 2). Windows of several lengths run side by side, so
//!    growth is seen early when ρ is large and still seen when ρ is close to 1.
//! 4. **Producing energy**: the balance stayed more than [`SUSTAINED`] × E above its start for
//!    a whole window of at least [`SUSTAINED_WINDOW`] steps. A bounded oscillation returns to
//!    its start: the energy of a stable mode swings through a range that contains its initial
//!    value within one beat of the swing (at most 25 steps for symplectic Euler up to 0.998 of its
//!    limit), so its lowest rise in such a window is at most about 0. A run whose lowest rise
//!    stays at ten scenes' energy for a whole window has produced energy no physical run has:
//!    a mode past its linear limit grew until the nonlinearity stopped it (a spurious cycle
//!    that pumps energy into a damper every step keeps climbing; a transverse mode that grew
//!    until its tension relaxed leaves its gain booked for good), or explicit Euler's steady
//!    gain on an undamped mode passed ten scales.
//! 5. **Runaway** ([`super::runaway`]): the balance's peak rise grew at least tenfold over each
//!    of the run's last three octaves (steps n/8 → n/4 → n/2 → n) and is above ten scales. Rules
//!    3 and 4 need windows of 16 to 4096 steps; a run of 40 frames has none to spare. A bounded
//!    swing rises at most like sin² from wherever it starts, which never gives three tenfold
//!    octaves in a row; a mode that grows like ρ²ⁿ gives them as soon as ρ^(n/8) ≥ 10.
//!
//! There is no separate rule on how far springs stretch: a spring's elastic energy is a term of
//! the balance, so a stretch past what the scene's energy allows (½ k Δl² above E) is a rise
//! these rules already judge, while a fixed strain threshold would call a soft spring that a
//! heavy load legitimately stretches several times its rest length unstable.
//!
//! On a linear scene this agrees with the spectral radius of each method's one-step map
//! ([`crate::measure::stability`]): below the limit every mode's energy stays within a bounded
//! factor of its start, far below the cap; above it the growth shows as rule 3 or 2 once the run
//! is long enough for ρ^2n to reach them (a run at ρ = 1.01 needs about 700 steps).
//! What follows a verdict is the runner's [`crate::run::RunPlan::stop_at_verdict`] choice: a
//! measuring command stops there, `run` computes on until the state diverges or passes the cap.

use super::energy::EnergyRecord;
use super::runaway::{Runaway, OCTAVES, OCTAVE_RATIO, RUNAWAY_LEVEL};
use super::scale::energy_scale;
use crate::model::{State, System};

/// Default `--blowup-factor`: the hard cap, in scene energy scales, on the rise of the energy
/// balance (see the module doc for why 1000 is above any bounded oscillation short of 0.998 of
/// a method's linear limit).
pub const DEFAULT_BLOWUP_FACTOR: f64 = 1e3;

/// The `--help` text of `--blowup-factor`, repeated word for word in docs/energy-and-stability.md (a test checks).
pub const BLOWUP_FACTOR_HELP: &str = "Hard cap: call a run unstable (and stop it) once its energy balance (kinetic + potential + dissipated - injected) has risen by more than this multiple of the scene's energy scale; below the cap a run is unstable only when that rise keeps doubling window after window, stays ten scales high for a whole window, or passes ten scales after growing tenfold over each of the run's last three octaves";

/// Window lengths (steps) of the growth rule: short windows see fast growth early, long ones
/// see growth at a spectral radius close to 1 (a window of W steps doubles once ρ^2W ≥ 2:
/// ρ ≥ 1.0055 at W = 64, ρ ≥ 1.000085 at W = 4096).
pub const GROWTH_WINDOWS: [u64; 5] = [16, 64, 256, 1024, 4096];
/// Factor by which a window's peak rise must exceed the previous window's.
pub const GROWTH_RATIO: f64 = 2.0;
/// Consecutive windows that must each grow by [`GROWTH_RATIO`].
pub const GROWTH_RUN: usize = 5;

/// Rule 4's level, in scene energy scales, that a whole window's lowest rise must exceed.
pub const SUSTAINED: f64 = 10.0;
/// Shortest window (steps) that rule 4 reads: long enough to hold a beat of any bounded swing
/// below the cap.
pub const SUSTAINED_WINDOW: u64 = 64;

/// Relative round-off allowed on the energy terms: sums of large terms of opposite sign
/// are not gains.
const ROUNDOFF: f64 = 1e-9;

/// Which rule of the module doc fired.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rule {
    /// Rule 1: a non-finite state or energy; the state cannot be written.
    Diverged,
    /// Rule 2: the balance passed the hard cap.
    Cap,
    /// Rule 3: the balance keeps doubling window after window.
    Growing,
    /// Rule 4: the balance stayed far above its start for a whole window.
    Producing,
    /// Rule 5: the balance's peak grew tenfold over each of the last octaves of the run.
    Runaway,
}

/// A verdict that fired: which rule, and the reason in words.
#[derive(Debug, Clone, PartialEq)]
pub struct Fired {
    /// The rule.
    pub rule: Rule,
    /// What tripped, with the figures.
    pub reason: String,
}

/// Checks a blow-up factor given by a user: finite and above 0.
pub fn check_factor(f: f64) -> std::result::Result<f64, String> {
    if f.is_finite() && f > 0.0 {
        Ok(f)
    } else {
        Err(format!("must be a finite number > 0, got {f}"))
    }
}

/// The running peaks of one window length.
#[derive(Debug, Clone)]
struct Windows {
    len: u64,
    /// Peaks of the last completed windows, oldest first (at most [`GROWTH_RUN`]).
    done: Vec<f64>,
    /// Peak of the window in progress.
    peak: f64,
    /// Lowest rise of the window in progress.
    low: f64,
}

impl Windows {
    /// Takes the rise of step `n` (1-based): the rule (3 or 4) that holds at this step, if any.
    /// `floor` is the scene's energy scale (plus round-off).
    fn push(&mut self, n: u64, rise: f64, floor: f64) -> Option<Rule> {
        self.peak = self.peak.max(rise);
        self.low = self.low.min(rise);
        let growing = self.done.len() == GROWTH_RUN
            && self.peak > floor
            && self.done[0] > 0.0
            && self.done.windows(2).all(|w| w[1] >= GROWTH_RATIO * w[0])
            && self.peak >= GROWTH_RATIO * self.done[GROWTH_RUN - 1];
        let mut sustained = false;
        if n % self.len == 0 {
            if self.done.len() == GROWTH_RUN {
                self.done.remove(0);
            }
            self.done.push(self.peak);
            sustained = self.len >= SUSTAINED_WINDOW && self.low > SUSTAINED * floor;
            self.peak = f64::NEG_INFINITY;
            self.low = f64::INFINITY;
        }
        if growing {
            Some(Rule::Growing)
        } else if sustained {
            Some(Rule::Producing)
        } else {
            None
        }
    }
}

/// The verdict of one run, fed each step's state and energy account in order.
#[derive(Debug, Clone)]
pub struct Verdict {
    e0_total: f64,
    scale: f64,
    cap: f64,
    steps: u64,
    windows: Vec<Windows>,
    runaway: Runaway,
}

/// An energy in prose: four significant digits and its unit (`402.7 J`, `3.989e4 J`).
fn joules(v: f64) -> String {
    format!("{} J", crate::error::significant(v, 4))
}

impl Verdict {
    /// The verdict of a run of `horizon` seconds from `s0` on `sys` with the hard cap `cap`
    /// (in scales), and the energy record the run starts from: the one judgment the runner and
    /// a timed loop (`perf::ratios::implicit_cost`) both make.
    pub fn for_run(sys: &System, s0: &State, horizon: f64, cap: f64) -> (Self, EnergyRecord) {
        let initial = EnergyRecord::new(sys.state_energy(s0), 0.0, 0.0);
        let verdict = Verdict::new(initial.total, energy_scale(sys, s0, horizon), cap);
        (verdict, initial)
    }

    /// A verdict for a run whose balance at t = 0 is `e0_total`, on a scene of energy scale
    /// `scale` (J), with the hard cap `cap` (in scales).
    pub fn new(e0_total: f64, scale: f64, cap: f64) -> Self {
        Verdict {
            e0_total,
            scale,
            cap,
            steps: 0,
            windows: GROWTH_WINDOWS
                .iter()
                .map(|&len| Windows {
                    len,
                    done: Vec::with_capacity(GROWTH_RUN),
                    peak: f64::NEG_INFINITY,
                    low: f64::INFINITY,
                })
                .collect(),
            runaway: Runaway::default(),
        }
    }

    /// Judges the next step's state `s` and account `e`: `None` while the run is bounded.
    pub fn step(&mut self, s: &State, e: &EnergyRecord) -> Option<Fired> {
        self.steps += 1;
        if let Some(p) = s.first_non_finite() {
            return Some(Fired {
                rule: Rule::Diverged,
                reason: format!("diverged: non-finite position or velocity of particle {p}"),
            });
        }
        if !e.is_finite() {
            return Some(Fired {
                rule: Rule::Diverged,
                reason: "diverged: non-finite energy".into(),
            });
        }
        let rise = e.total - self.e0_total;
        let terms = e.kinetic.abs()
            + e.gravity.abs()
            + e.elastic.abs()
            + e.dissipated.abs()
            + e.injected.abs();
        let noise = ROUNDOFF * terms;
        if rise > self.cap * self.scale + noise {
            return Some(Fired {
                rule: Rule::Cap,
                reason: format!(
                    "energy balance rose by {} ({}), past the cap of {} × the scene's energy scale of {}",
                    joules(rise),
                    self.books(e),
                    self.cap,
                    joules(self.scale)
                ),
            });
        }
        let (n, floor) = (self.steps, self.scale + noise);
        let mut fired = None;
        for w in &mut self.windows {
            if let Some(rule) = w.push(n, rise, floor) {
                fired = fired.or(Some((rule, w.len, w.done.first().copied().unwrap_or(0.0))));
            }
        }
        let octaves = self.runaway.push(n, rise, self.scale);
        let Some((rule, len, first)) = fired else {
            let o = octaves?;
            let [a, b, c, d] = o.peaks;
            return Some(Fired {
                rule: Rule::Runaway,
                reason: format!(
                    "energy balance growing without bound over the whole run: its peak rise grew at least {OCTAVE_RATIO}-fold over each of the run's last {OCTAVES} octaves (steps {}, {}, {}, {}: {}, {}, {}, {}), now {} ({}), past {RUNAWAY_LEVEL} × the scene's energy scale of {}",
                    o.steps[0],
                    o.steps[1],
                    o.steps[2],
                    o.steps[3],
                    joules(a),
                    joules(b),
                    joules(c),
                    joules(d),
                    joules(rise),
                    self.books(e),
                    joules(self.scale)
                ),
            });
        };
        let reason = match rule {
            Rule::Growing => format!(
                "energy balance growing without bound: its peak rise doubled in each of {GROWTH_RUN} windows of {len} steps, from {} to {} ({}), above the scene's energy scale of {}",
                joules(first),
                joules(rise),
                self.books(e),
                joules(self.scale)
            ),
            _ => format!(
                "energy balance producing energy: it stayed more than {SUSTAINED} × the scene's energy scale of {} above its start for a whole window of {len} steps, now {} ({})",
                joules(self.scale),
                joules(rise),
                self.books(e)
            ),
        };
        Some(Fired { rule, reason })
    }

    /// The reason a run whose step failed (an implicit solve that found no root) is unstable,
    /// judged from `last`, the account of the last step it finished: when the balance had
    /// already risen past [`SUSTAINED`] × the scene's energy scale, the method was producing
    /// energy no physical run has and the failed solve is its consequence, so the reason says
    /// so first; otherwise it is the solver's own `why`.
    pub fn failed_step(&self, last: &EnergyRecord, why: &str) -> String {
        let rise = last.total - self.e0_total;
        if last.is_finite() && rise > SUSTAINED * self.scale {
            format!(
                "energy balance rose by {} ({}), past {SUSTAINED} × the scene's energy scale of {}: the method produced that energy, and then its step failed ({why})",
                joules(rise),
                self.books(last),
                joules(self.scale)
            )
        } else {
            why.to_string()
        }
    }

    /// The account's terms in words, for a reason.
    fn books(&self, e: &EnergyRecord) -> String {
        let mechanical = e.mechanical() - self.e0_total;
        let sign = if mechanical >= 0.0 { "+" } else { "" };
        let mut books = format!("mechanical {sign}{}", joules(mechanical));
        for (what, v) in [
            ("dissipated", e.dissipated),
            ("injected", e.injected),
            ("created by contacts", e.created),
        ] {
            if v != 0.0 {
                books += &format!(", {what} {}", joules(v));
            }
        }
        books
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Energy, Vec3};

    fn state(v: f64) -> State {
        State {
            t: 0.0,
            x: vec![Vec3::zeros()],
            v: vec![Vec3::new(v, 0.0, 0.0)],
        }
    }

    fn record(kinetic: f64, dissipated: f64) -> EnergyRecord {
        EnergyRecord::new(
            Energy {
                kinetic,
                gravity: 0.0,
                elastic: 0.0,
            },
            dissipated,
            0.0,
        )
    }

    /// Feeds the kinetic energies `k(n)` for n = 1..=steps; the first verdict and its step.
    fn first_fire(k: impl Fn(f64) -> f64, steps: u64, cap: f64) -> Option<(u64, Rule)> {
        let mut v = Verdict::new(1.0, 1.0, cap);
        (1..=steps).find_map(|n| {
            v.step(&state(1.0), &record(k(n as f64), 0.0))
                .map(|f| (n, f.rule))
        })
    }

    // Oracle: the rule's own level, SUSTAINED = 10 scales: a step that fails after the balance
    // rose 25 scales is blamed on the energy (the solver's words kept after it); its twin, a
    // failure with the balance within one scale, keeps the solver's reason alone.
    #[test]
    fn a_failed_step_after_an_energy_gain_is_blamed_on_the_energy() {
        let v = Verdict::new(0.0, 14.0, DEFAULT_BLOWUP_FACTOR);
        let why = "implicit_midpoint: Newton did not converge in 50 iterations";
        let gained = v.failed_step(&record(350.0, 0.0), why);
        assert!(
            gained.starts_with("energy balance rose by 350.0 J")
                && gained.ends_with(&format!("({why})")),
            "{gained}"
        );
        assert_eq!(v.failed_step(&record(10.0, 0.0), why), why);
    }

    /// Oracle: the prose rule of every reason, at least four significant digits (as many as
    /// the scientific form it replaces), whole joules below 10⁵ J, and the account's terms
    /// that moved: a run from 1 J to 40 001 J kinetic with 402.7 J dissipated reads "rose by
    /// 40403 J (mechanical +40000 J, dissipated 402.7 J)"; its twin with nothing dissipated
    /// names no term but the mechanical one.
    #[test]
    fn reasons_print_significant_digits_and_the_terms_that_moved() {
        let mut v = Verdict::new(1.0, 2.0, 1.0);
        let why = v.step(&state(1.0), &record(40_001.0, 402.7)).unwrap();
        assert!(
            why.reason.starts_with(
                "energy balance rose by 40403 J (mechanical +40000 J, dissipated 402.7 J), past the cap of 1 × the scene's energy scale of 2.000 J"
            ),
            "{}",
            why.reason
        );
        let mut v = Verdict::new(1.0, 2.0, 1.0);
        let why = v.step(&state(1.0), &record(40_001.0, 0.0)).unwrap();
        assert!(
            why.reason.contains("(mechanical +40000 J), past"),
            "{}",
            why.reason
        );
    }

    #[test]
    fn a_gain_hidden_behind_dissipation_still_counts() {
        // Oracle: the balance definition. Mechanical energy unchanged (1 J → 1 J) while the
        // method booked 3 J into its dampers: the balance rose by 3 J, past a cap of 1 × 2 J.
        let mut v = Verdict::new(1.0, 2.0, 1.0);
        let why = v.step(&state(1.0), &record(1.0, 3.0)).unwrap();
        assert_eq!(why.rule, Rule::Cap);
        assert!(why.reason.contains("rose by 3.000 J"));
        let mut v = Verdict::new(1.0, 2.0, 1.0);
        assert_eq!(v.step(&state(1.0), &record(1.0, 1.5)), None);
    }

    #[test]
    fn non_finite_states_diverge_and_bad_factors_are_refused() {
        let mut v = Verdict::new(1.0, 1.0, 1.0);
        let f = v.step(&state(f64::NAN), &record(1.0, 0.0)).unwrap();
        assert!(f.rule == Rule::Diverged && f.reason.starts_with("diverged"));
        assert!(check_factor(0.0).is_err() && check_factor(f64::INFINITY).is_err());
        assert_eq!(check_factor(DEFAULT_BLOWUP_FACTOR), Ok(1e3));
    }

    #[test]
    fn geometric_growth_fires_and_a_bounded_swing_does_not() {
        // Oracle: an unstable mode's energy grows like ρ^2n. At ρ = 1.05 (×4.8 per 16-step
        // window) the growth rule fires once the rise passes the scale, before the cap.
        let rho2 = 1.05f64.powi(2);
        let fired = first_fire(|n| 1.0 + 1e-6 * (rho2.powf(n) - 1.0), 2000, 1e3);
        assert!(matches!(fired, Some((_, Rule::Growing))), "{fired:?}");
    }

    /// The first verdict on symplectic Euler (v += −hω²x, then x += hv) on x'' = −ω²x with
    /// ω = 1 at h = 2a (a: the fraction of its limit hω = 2), from x = 1, v = 0, over `steps`.
    fn symplectic_euler(a: f64, steps: u64) -> Option<(u64, Rule)> {
        let (h, mut x, mut v) = (2.0 * a, 1.0f64, 0.0f64);
        let mut verdict = Verdict::new(0.5, 0.5, DEFAULT_BLOWUP_FACTOR);
        (1..=steps).find_map(|n| {
            v -= h * x;
            x += h * v;
            let s = State {
                t: 0.0,
                x: vec![Vec3::new(x, 0.0, 0.0)],
                v: vec![Vec3::new(v, 0.0, 0.0)],
            };
            let e = EnergyRecord::new(
                Energy {
                    kinetic: 0.5 * v * v,
                    gravity: 0.0,
                    elastic: 0.5 * x * x,
                },
                0.0,
                0.0,
            );
            verdict.step(&s, &e).map(|f| (n, f.rule))
        })
    }

    #[test]
    fn symplectic_euler_is_stable_below_its_limit_and_unstable_above() {
        // Oracle: the textbook limit hω < 2 (Hairer, Lubich & Wanner, GNI §I.1). Below it the
        // energy swings by up to (1 + a)/(1 − a) (132 times at a = 0.985, 998 at 0.998) and
        // stays bounded: stable, however far it swings under the cap.
        for a in [0.5, 0.9, 0.985, 0.998] {
            assert_eq!(symplectic_euler(a, 100_000), None, "a = {a}");
        }
        // Twin: just above the limit ρ > 1 and the run is unstable within a few hundred steps.
        for a in [1.001, 1.01, 1.1] {
            assert!(
                symplectic_euler(a, 100_000).is_some_and(|(n, _)| n < 2000),
                "a = {a}"
            );
        }
    }

    #[test]
    fn a_balance_that_climbs_for_good_is_producing_energy() {
        // Oracle: rule 4's statement. A spurious cycle: the mechanical energy swings by 50
        // scales every 10 steps while the damper books 0.2 scales a step (the balance climbs
        // and never comes back): unstable once a 64-step window sits wholly above 10 scales,
        // long before the cap.
        let cycle = |n: f64| 1.0 + 50.0 * (0.2 * std::f64::consts::PI * n).sin().powi(2) + 0.2 * n;
        let fired = first_fire(cycle, 2000, 1e3);
        assert!(
            matches!(fired, Some((n, Rule::Producing)) if n <= 192),
            "{fired:?}"
        );
        // Twin: the same swing without the climb, started mid-swing (so it dips below its start
        // every beat): bounded, never unstable, over 100 000 steps.
        let swing = |n: f64| {
            1.0 + 50.0
                * ((0.2 * std::f64::consts::PI * n + 0.7).sin().powi(2) - 0.7f64.sin().powi(2))
        };
        assert_eq!(first_fire(swing, 100_000, 1e3), None);
    }

    #[test]
    fn a_slow_geometric_growth_below_the_cap_is_unstable() {
        // Oracle: ρ²ⁿ growth. A balance rising ×1500 over 2000 steps (×2.5 per 256 steps)
        // from 0.65 of a 0.065 J scale, to 980 scales, just under the cap: growing.
        let mut v = Verdict::new(0.0425, 0.065, DEFAULT_BLOWUP_FACTOR);
        let fired = (1..=2000u64).find_map(|n| {
            let k = 0.0425 * 1500f64.powf(n as f64 / 2000.0);
            v.step(&state(1.0), &record(k, 0.0)).map(|f| (n, f.rule))
        });
        assert!(
            matches!(fired, Some((_, Rule::Growing | Rule::Producing))),
            "{fired:?}"
        );
    }

    #[test]
    fn polynomial_drifts_are_not_growth() {
        // Oracle: t^p drifts grow by (k+1)^p/k^p per window, below 2 by the 5th for p < 3.8.
        for p in [1.0, 2.0, 3.0, 3.7] {
            let drift = |n: f64| 1.0 + 1e-6 * n.powf(p);
            // Rule 4 may call such a drift unstable once it sits at 100 scales; rule 3 never.
            let fired = first_fire(drift, 100_000, 1e30);
            assert!(
                !matches!(fired, Some((_, Rule::Growing))),
                "t^{p}: {fired:?}"
            );
        }
        // Twin: the same t³ drift, climbing to the cap, is unstable (by rule 4, then the cap).
        let drift = |n: f64| 1.0 + 1e-6 * n.powi(3);
        assert!(matches!(
            first_fire(drift, 100_000, 1e3),
            Some((_, Rule::Producing | Rule::Cap))
        ));
    }
}
