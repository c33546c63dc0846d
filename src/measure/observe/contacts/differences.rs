//! Rapier's documented contact differences ([`crate::rapier::DIFFERENCES`]) beside what a
//! run's contact metrics measured of each, for the report's collision section (the text has
//! one home in the Rapier module; the figures are read from the same [`ContactReport`]).

use super::{ContactReport, CONTACT_GAP};
use crate::error::significant;
pub use crate::rapier::{Difference, DifferenceKind, DIFFERENCES};

/// True for the methods some difference applies to (Rapier's).
pub fn is_rapier(method: &str) -> bool {
    DIFFERENCES.iter().any(|d| d.shown_by(method))
}

/// The figure `c` (a run of `method`) gives for difference `d`, `None` when the run measured
/// nothing of it (or `d` does not apply to `method`).
pub fn measured(d: &Difference, method: &str, c: &ContactReport) -> Option<String> {
    if !d.shown_by(method) || !d.applies_to(c.response) {
        return None;
    }
    match d.kind {
        DifferenceKind::SoftSpeculative => {
            let rest = c
                .bounces
                .first()
                .and_then(|b| b.heights.last())
                .map(|h| h[1])
                .filter(|g| (0.0..CONTACT_GAP).contains(g));
            Some(match rest {
                Some(g) => format!(
                    "deepest penetration {} m, resting gap at the end {} m",
                    significant(c.penetration_max(), 3),
                    significant(g, 3)
                ),
                None => format!(
                    "deepest penetration {} m",
                    significant(c.penetration_max(), 3)
                ),
            })
        }
        // Compare measures no tangential loss per impact; the test does.
        DifferenceKind::ImpactFriction => None,
        DifferenceKind::OneSidedMesh => c
            .obstacles
            .iter()
            .any(|o| o.shape == crate::collide::ShapeKind::Mesh)
            .then(|| format!("{} tunnelling events", c.tunnelling_count)),
        DifferenceKind::PenaltyHeldForce => c.events.first().and_then(|e| {
            e.restitution.map(|m| {
                format!(
                    "first impact e {m:.4} against the contact equation's {:.4}",
                    e.expected_restitution
                )
            })
        }),
        DifferenceKind::MultibodyRolling => c.slides.first().map(|s| {
            format!(
                "slide acceleration {:.4} m/s² against Coulomb's {:.4} m/s²",
                s.acceleration, s.expected_acceleration
            )
        }),
    }
}
