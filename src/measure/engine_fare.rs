//! How the engines (Rapier) fare at a scene's game rate, beside springlab's answer: every
//! method of the frame-rate table as one point (cost per frame, error), and the best engine's
//! row with the cost ratio to the answer at equal error. Read off the frame-rate document, so
//! the front page's sentence, its chart and `framerate.json` are one set of numbers.

use super::answer::GameRate;
use super::framerate::Framerate;
use crate::method::Registry;
use serde::{Deserialize, Serialize};

/// One method at the game rate: its fewest substeps that meet the bound, else its run at one
/// substep.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GamePoint {
    /// Method.
    pub method: String,
    /// True for an engine (Rapier).
    pub engine: bool,
    /// Substeps per frame of the run shown.
    pub substeps: u64,
    /// Its error by the frame-rate table's metric (`None`: the run stopped).
    pub error: Option<f64>,
    /// Modelled seconds per frame ([`crate::run::cost`]).
    pub modelled_seconds_per_frame: Option<f64>,
    /// True when the error is within the bound.
    pub meets: bool,
}

/// Every method of `fr` at `hz`, in the table's order.
pub fn game_points(fr: &Framerate, hz: f64, registry: &Registry) -> Vec<GamePoint> {
    fr.entries
        .iter()
        .filter(|e| e.hz == hz)
        .map(|e| {
            let run = e
                .fewest
                .as_ref()
                .filter(|f| f.meets_tolerance)
                .unwrap_or(&e.one_substep);
            GamePoint {
                method: e.method.clone(),
                engine: registry.info(&e.method).is_ok_and(|m| m.engine),
                substeps: run.substeps,
                error: run.error.filter(|_| run.status.is_ok()),
                modelled_seconds_per_frame: run.modelled_seconds_per_frame,
                meets: run.meets_tolerance && run.status.is_ok(),
            }
        })
        .collect()
}

/// The best engine at the game rate beside the scene's answer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EngineFare {
    /// The engine's point: the cheapest engine that meets the bound, else the most accurate.
    pub best: GamePoint,
    /// Engine cost per frame over the answer's, when both meet the bound and the answer is a
    /// native method (the price of the engine at equal error).
    pub cost_ratio: Option<f64>,
}

/// The best engine among `points` beside the game-rate answer `game`; `None` when no engine
/// ran at the rate.
pub fn engine_fare(points: &[GamePoint], game: &GameRate) -> Option<EngineFare> {
    let engines = points.iter().filter(|p| p.engine);
    let cost = |p: &GamePoint| p.modelled_seconds_per_frame.unwrap_or(f64::INFINITY);
    let best = engines
        .clone()
        .filter(|p| p.meets)
        .min_by(|a, b| cost(a).total_cmp(&cost(b)).then(a.method.cmp(&b.method)))
        .or_else(|| {
            engines.filter(|p| p.error.is_some()).min_by(|a, b| {
                a.error
                    .unwrap_or(f64::INFINITY)
                    .total_cmp(&b.error.unwrap_or(f64::INFINITY))
                    .then(a.method.cmp(&b.method))
            })
        })
        .or_else(|| points.iter().find(|p| p.engine))?
        .clone();
    let answer_is_native = game
        .method
        .as_ref()
        .is_some_and(|m| points.iter().any(|p| &p.method == m && !p.engine));
    let cost_ratio = match (best.meets, game.meets, game.modelled_seconds_per_frame) {
        (true, true, Some(native)) if answer_is_native && native > 0.0 => {
            best.modelled_seconds_per_frame.map(|e| e / native)
        }
        _ => None,
    };
    Some(EngineFare { best, cost_ratio })
}
