//! What advice is asked for: the methods, the tolerance and metric, the step grid, the
//! budget, the screen and the timing rule.

use super::cost::ADVICE_TIMING;
use super::screen::SCREEN_FACTOR;
use crate::measure::case::TimingRule;
use crate::measure::statistics::Ensemble;
use crate::measure::tolerance::Metric;

/// Options of [`advise`](super::advise).
#[derive(Debug, Clone)]
pub struct AdviseConfig {
    /// Position tolerance (m); None: the scene's `[run] tolerance`, else 1 % of its motion
    /// scale ([`crate::measure::tolerance`]).
    pub tolerance: Option<f64>,
    /// Which error; None: statistics past a predictability horizon, else position
    /// ([`crate::measure::tolerance::default_metric`]).
    pub metric: Option<Metric>,
    /// Horizon (s; default the scene's duration).
    pub horizon: Option<f64>,
    /// Methods, registry, options, blow-up factor, progress and budget: what every
    /// measuring command shares.
    pub common: crate::measure::Common,
    /// Predictions aim at tolerance / safety (default 2).
    pub safety: f64,
    /// Grid points (default 10).
    pub points: usize,
    /// Smallest grid step (default: scene dt / 30).
    pub dt_min: Option<f64>,
    /// Largest grid step (default: min(10 × scene dt, horizon / 4)).
    pub dt_max: Option<f64>,
    /// How often each candidate's run is repeated to time it (default [`ADVICE_TIMING`]).
    pub timing: TimingRule,
    /// Add the game view ([`super::frame_view`]: the frame-rate table of the verified
    /// candidates at [`DEFAULT_RATES`](crate::measure::framerate::DEFAULT_RATES));
    /// `--no-frame-rates` leaves it out (the report's study measures that table once, itself).
    pub frame_rates: bool,
    /// The game's frame rate (Hz) whose answer `--write-expect` writes: added to the frame
    /// view when it is not one of its rates (the view's only rate with `--no-frame-rates`).
    pub game_hz: Option<f64>,
    /// An ensemble already made for this scene over the same horizon (the study passes
    /// compare's); None: made here when the statistics metric needs it.
    pub ensemble: Option<Ensemble>,
    /// A candidate, or a grid step of one, modelled above this many times the cheapest
    /// verified answer's cost is not run (default [`SCREEN_FACTOR`]; infinity runs them all).
    pub screen_factor: f64,
}

impl Default for AdviseConfig {
    fn default() -> Self {
        AdviseConfig {
            tolerance: None,
            metric: None,
            horizon: None,
            safety: 2.0,
            points: 10,
            dt_min: None,
            dt_max: None,
            timing: ADVICE_TIMING,
            frame_rates: true,
            game_hz: None,
            ensemble: None,
            screen_factor: SCREEN_FACTOR,
            common: crate::measure::Common::default(),
        }
    }
}
