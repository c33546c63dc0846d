//! Whole steps over a span of time: the one rule every command uses to turn a duration and a
//! step into a step count.

/// The nearest whole number of steps of `dt` covering `span` (at least 1): how a run's length
/// becomes steps (a duration at a step, frames at a rate, a grid point of a sweep).
pub fn whole_steps(span: f64, dt: f64) -> u64 {
    ((span / dt).round() as u64).max(1)
}

/// The fewest whole steps of at most `dt` covering `span` (at least 1): how a largest step
/// becomes a run that reaches the horizon without exceeding it (advice's verified step, a
/// stability trial).
pub fn covering_steps(span: f64, dt: f64) -> u64 {
    ((span / dt).ceil() as u64).max(1)
}
