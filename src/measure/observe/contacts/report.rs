//! The contact metrics' document (`contacts.json`): every contact event, the bounces and apexes
//! of the tracked particles, slides, penetration and tunnelling, and the summaries.

use super::slides::Slide;
use crate::error::Result;
use serde::Serialize;

/// One contact between a particle and an obstacle, from touching to leaving.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ContactEvent {
    /// Particle index.
    pub particle: usize,
    /// Obstacle index.
    pub obstacle: usize,
    /// Estimated time of touching (s).
    pub t_in: f64,
    /// Estimated time of leaving (s).
    pub t_out: f64,
    /// t_out − t_in (s).
    pub duration: f64,
    /// Expected duration (s): 0 for impulse and projection; for penalty the contact ODE's
    /// (absent when gravity holds the particle pressed in for good).
    pub expected_duration: Option<f64>,
    /// Normal velocity when touching (m/s, negative: approaching).
    pub v_in: f64,
    /// Normal velocity when leaving (m/s, positive: separating).
    pub v_out: f64,
    /// Measured restitution v_out / |v_in| (absent for a resting or grazing contact, see
    /// [`ContactMetrics::grazing_speed`](super::ContactMetrics::grazing_speed), and for a
    /// pass-through).
    pub restitution: Option<f64>,
    /// What the response should give (see the module docs).
    pub expected_restitution: f64,
    /// Penalty only: |g·n| / (ω |v_in|), the weight of gravity against the contact spring;
    /// the formula for e ignores gravity, so it holds when this is ≪ 1.
    pub gravity_share: Option<f64>,
    /// Largest penetration seen at an accepted state during the contact (m, ≥ 0).
    pub max_penetration: f64,
    /// Expected largest penetration (m): 0 for impulse and projection, the contact ODE's for
    /// penalty.
    pub expected_penetration: f64,
    /// Energy the run booked as dissipated from the sample before touching to the sample
    /// after leaving (J; the whole system's account over that interval).
    pub energy_dissipated: f64,
    /// Energy the run booked as created by contacts over the same interval (J).
    pub energy_created: f64,
}

/// One apex between bounces of a tracked particle.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Apex {
    /// Bounces before this apex (0: the release height).
    pub bounce: u32,
    /// Time of the apex (s).
    pub t: f64,
    /// Height of the particle's surface above the obstacle (m).
    pub height: f64,
    /// h0 · e^(2n) with the expected restitution e.
    pub predicted: f64,
    /// height / previous apex height (absent for the first).
    pub ratio: Option<f64>,
    /// e² with the expected restitution of the bounce before this apex.
    pub expected_ratio: Option<f64>,
    /// Fraction of the mechanical energy lost in the bounce: 1 − ratio.
    pub energy_lost: Option<f64>,
    /// 1 − e².
    pub expected_energy_lost: Option<f64>,
}

/// Bounce record of one tracked particle.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ParticleBounces {
    /// Particle index.
    pub particle: usize,
    /// Apexes, the release height first.
    pub apexes: Vec<Apex>,
    /// Height over time: `[t, gap]` pairs (gap < 0: penetration), decimated.
    pub heights: Vec<[f64; 2]>,
}

/// Summary statistics of a set of values.
#[derive(Debug, Clone, Default, Serialize, PartialEq)]
pub struct Stats {
    /// How many values.
    pub count: u64,
    /// Mean (0 when empty).
    pub mean: f64,
    /// Smallest (0 when empty).
    pub min: f64,
    /// Largest (0 when empty).
    pub max: f64,
}

impl Stats {
    /// Count, mean and extremes of `values` (zeros when there are none).
    pub(super) fn of(values: impl Iterator<Item = f64>) -> Self {
        let (mut count, mut sum, mut min, mut max) = (0u64, 0.0, f64::INFINITY, f64::NEG_INFINITY);
        for v in values {
            count += 1;
            sum += v;
            min = min.min(v);
            max = max.max(v);
        }
        if count == 0 {
            return Stats::default();
        }
        Stats {
            count,
            mean: sum / count as f64,
            min,
            max,
        }
    }
}

/// One path through an obstacle between two accepted states.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Tunnelling {
    /// Particle index.
    pub particle: usize,
    /// Obstacle passed through.
    pub obstacle: usize,
    /// Time of the state after the crossing (s).
    pub t: f64,
}

/// An obstacle as the report lists it.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ObstacleInfo {
    /// Shape kind.
    pub shape: crate::collide::ShapeKind,
    /// Coefficient of restitution.
    pub restitution: f64,
    /// Friction coefficient.
    pub friction: f64,
}

/// `contacts.json`: everything the collision metrics measured in one run.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ContactReport {
    /// `impulse`, `penalty` or `projection`.
    pub response: crate::collide::ResponseKind,
    /// Output step (s).
    pub dt: f64,
    /// Obstacles in file order.
    pub obstacles: Vec<ObstacleInfo>,
    /// Penalty only: contact stiffness (N/m).
    pub penalty_stiffness: Option<f64>,
    /// Penalty only: steps per contact, π/(ω dt) with ω = √(k/m) of the lightest free particle;
    /// below about 10 the contact is not resolved and the measured restitution is an artefact
    /// (explicit methods need ω dt < 2 to stay stable on the contact spring at all).
    pub penalty_steps_per_contact: Option<f64>,
    /// Completed contact events (touch and leave), all of them.
    pub events_total: u64,
    /// Contacts still open at the end of the run (resting contacts).
    pub open_contacts: u64,
    /// The first [`MAX_LISTED_EVENTS`](super::MAX_LISTED_EVENTS) completed events.
    pub events: Vec<ContactEvent>,
    /// Approach speed (m/s) above which impacts enter the restitution summary:
    /// [`IMPACT_SPEED_SHARE`](super::IMPACT_SPEED_SHARE) of the fastest approach, at least the
    /// grazing speed.
    pub impact_speed_floor: f64,
    /// Measured restitution over the impacts above `impact_speed_floor`.
    pub restitution: Stats,
    /// Expected restitution over the same impacts.
    pub expected_restitution: Stats,
    /// Measured minus expected restitution over the same impacts.
    pub restitution_deviation: Stats,
    /// The deviation of largest magnitude among them (signed; 0 without impacts).
    pub restitution_worst_deviation: f64,
    /// Per-event maximum penetration (m), over completed and open events.
    pub penetration: Stats,
    /// Penetration (m) over every accepted state of every particle in contact.
    pub penetration_samples: Stats,
    /// Number of tunnelling events.
    pub tunnelling_count: u64,
    /// The first 100 tunnelling events.
    pub tunnelling: Vec<Tunnelling>,
    /// Apexes and heights of the tracked particles.
    pub bounces: Vec<ParticleBounces>,
    /// Slides of the lone particles in resting contact (friction against Coulomb's law).
    pub slides: Vec<Slide>,
    /// Why no slide was measured at all when the scene has no lone particle (null otherwise).
    pub slides_unmeasured: Option<&'static str>,
    /// Parry narrow-phase queries made on this thread during the run (responses and metrics).
    pub parry_queries: u64,
}

impl ContactReport {
    /// Deepest penetration into any obstacle over the run (m, ≥ 0; 0 without contact): the
    /// largest per-event maximum, which is the largest penetration of any accepted state in
    /// contact. The one number every document and page shows as the run's penetration.
    pub fn penetration_max(&self) -> f64 {
        self.penetration.max
    }

    /// The listed impacts the restitution summary covers (approaching at least as fast as
    /// `impact_speed_floor`, with a measured e), each with its measured e, in listing order.
    pub fn summary_impacts(&self) -> impl Iterator<Item = (&ContactEvent, f64)> + '_ {
        self.events
            .iter()
            .filter(|e| e.v_in.abs() >= self.impact_speed_floor)
            .filter_map(|e| e.restitution.map(|m| (e, m)))
    }
}

/// Writes `contacts.json` into `dir` atomically.
pub fn write_report(dir: &std::path::Path, report: &ContactReport) -> Result<std::path::PathBuf> {
    let json = serde_json::to_vec_pretty(report).expect("contact report serialises");
    crate::output::write_atomic(dir.join("contacts.json"), &json)
}
