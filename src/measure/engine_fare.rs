//! How the engines (Rapier) fare at a scene's game rate, beside springlab's answer: every
//! method of the frame-rate table as one point (cost per frame, error), and the best engine's
//! row with the cost ratio to the answer at equal error. Read off the frame-rate document, so
//! the front page's sentence, its chart and `framerate.json` are one set of numbers.

use super::advise::cost::{rank, CostKey};
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
    // The cheapest meeting engine by the answer's own cost rule (ties within its band broken
    // the same way), so an answer that is an engine is also the best engine.
    let meeting: Vec<&GamePoint> = engines
        .clone()
        .filter(|p| p.meets && p.modelled_seconds_per_frame.is_some())
        .collect();
    let keys: Vec<CostKey> = meeting
        .iter()
        .map(|p| CostKey {
            method: p.method.clone(),
            modelled_per_second: p.modelled_seconds_per_frame.unwrap_or(f64::NAN) * game.hz,
            force_evals_per_second: None,
        })
        .collect();
    let cheapest = rank(&keys, "")
        .ok()
        .and_then(|(order, _)| order.first().map(|&i| meeting[i]));
    let best = cheapest
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::tolerance::Metric;

    fn point(
        method: &str,
        engine: bool,
        substeps: u64,
        error: f64,
        cost: f64,
        meets: bool,
    ) -> GamePoint {
        GamePoint {
            method: method.into(),
            engine,
            substeps,
            error: Some(error),
            modelled_seconds_per_frame: Some(cost),
            meets,
        }
    }

    fn answer(method: &str, substeps: u64, cost: f64, meets: bool) -> GameRate {
        GameRate {
            hz: 60.0,
            method: Some(method.into()),
            substeps: Some(substeps),
            metric: Metric::Position,
            tolerance: 0.01,
            position_tolerance: 0.01,
            error: Some(0.005),
            modelled_seconds_per_frame: Some(cost),
            wall_seconds_per_frame: None,
            meets,
            verified: String::new(),
        }
    }

    // Oracle: the rule in the docs. The best engine is the one the answer's own cost rule
    // picks among those that meet the bound (so an engine answer is the best engine), else the
    // most accurate; the ratio is given only at equal standing (both meet, the answer native).
    #[test]
    fn the_best_engine_is_picked_by_the_answers_rule_and_priced_only_at_equal_standing() {
        let pts = [
            point("velocity_verlet", false, 2, 0.004, 1e-6, true),
            point("rapier_impulse", true, 8, 0.006, 4e-6, true),
            point("rapier_soft", true, 4, 0.008, 3e-6, true),
            point("rapier_multibody", true, 1, 0.5, 1e-6, false),
        ];
        let fare = engine_fare(&pts, &answer("velocity_verlet", 2, 1e-6, true)).unwrap();
        assert_eq!(fare.best.method, "rapier_soft");
        assert!((fare.cost_ratio.unwrap() - 3.0).abs() < 1e-12);
        // The twin: when no engine meets, the most accurate engine, and no ratio.
        let missing = [
            point("velocity_verlet", false, 2, 0.004, 1e-6, true),
            point("rapier_impulse", true, 1, 0.2, 4e-6, false),
            point("rapier_soft", true, 1, 0.1, 3e-6, false),
        ];
        let fare = engine_fare(&missing, &answer("velocity_verlet", 2, 1e-6, true)).unwrap();
        assert_eq!(fare.best.method, "rapier_soft");
        assert_eq!(fare.cost_ratio, None);
        // An engine answer has no ratio to itself.
        let fare = engine_fare(&pts, &answer("rapier_soft", 4, 3e-6, true)).unwrap();
        assert_eq!(
            (fare.best.method.as_str(), fare.cost_ratio),
            ("rapier_soft", None)
        );
        // No engine at the rate: nothing to say.
        assert!(engine_fare(&pts[..1], &answer("velocity_verlet", 2, 1e-6, true)).is_none());
    }
}
