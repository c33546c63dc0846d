//! When a scene's impulses take effect relative to a run's frames (`[run] events`).
//!
//! - [`Events::Exact`]: at the impulse's own time; the runner splits the (sub)step containing
//!   it, so the run follows the physics exactly (the default).
//! - [`Events::Frame`]: at the first frame boundary at or after its time, as a game applies
//!   input between frames. The output row at that boundary shows the state *before* the kick
//!   (rows are the ends of frames; the kick starts the next frame), as an exact impulse
//!   exactly on a boundary does too.
//!
//! The reference always applies impulses at their exact times: it is the physics a run is
//! measured against, so a frame-event run's lag shows up as error.

use serde::{Deserialize, Serialize};

/// When impulses take effect (see the module docs).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Events {
    /// At their own time, splitting the step (the default).
    #[default]
    Exact,
    /// At the first frame boundary at or after their time.
    Frame,
}

impl Events {
    /// The spelling in scene files (`exact`, `frame`).
    pub fn label(self) -> &'static str {
        match self {
            Events::Exact => "exact",
            Events::Frame => "frame",
        }
    }

    /// Parses a scene file's spelling; `Err` says what is accepted.
    pub fn parse(s: &str) -> std::result::Result<Self, String> {
        match s {
            "exact" => Ok(Events::Exact),
            "frame" => Ok(Events::Frame),
            _ => Err(format!("expected \"exact\" or \"frame\", got \"{s}\"")),
        }
    }

    /// The time (s) an impulse written at `t` takes effect in a run of frame step `frame`:
    /// `t` itself, or k·`frame` for the smallest whole k with k·`frame` ≥ `t` (a time within
    /// 1e-9 of a frame of a boundary counts as on it, so round-off never delays a kick a
    /// whole frame).
    pub fn applied_at(self, t: f64, frame: f64) -> f64 {
        match self {
            Events::Exact => t,
            Events::Frame => (t / frame - 1e-9).ceil().max(0.0) * frame,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Oracle: the definition, worked by hand at 60 Hz.
    #[test]
    fn frame_events_move_to_the_next_boundary() {
        let h = 1.0 / 60.0;
        assert_eq!(Events::Frame.applied_at(0.0, h), 0.0);
        assert_eq!(Events::Frame.applied_at(0.01, h), h);
        assert_eq!(Events::Frame.applied_at(2.0 * h, h), 2.0 * h);
        assert_eq!(Events::Frame.applied_at(0.037, h), 3.0 * h);
        assert_eq!(Events::Exact.applied_at(0.037, h), 0.037);
        assert!(Events::parse("frames").is_err());
    }
}
