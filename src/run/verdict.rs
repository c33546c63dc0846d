//! The one verdict on a run's step: is the state finite, and has the run's energy balance risen
//! by more than the scene allows? Every command (run, compare, stability, sweep, advise, report,
//! and the library's measures) reaches it through [`crate::run::run`], with the one threshold
//! [`DEFAULT_BLOWUP_FACTOR`] unless the user gives `--blowup-factor`.
//!
//! The balance is [`EnergyRecord::total`] = kinetic + gravity + elastic + dissipated − injected:
//! energy that went into dampers, drag and contacts counts, so a run cannot hide a gain behind
//! the damping it also computed. The exact solution keeps the balance constant; a rise above
//! `factor` × [`super::energy_scale`] is a blow-up.

use super::energy::EnergyRecord;
use crate::model::State;

/// Default `--blowup-factor`: a run is unstable once its energy balance has risen by more than
/// one energy scale of its scene.
pub const DEFAULT_BLOWUP_FACTOR: f64 = 1.0;

/// The `--help` text of `--blowup-factor`, repeated word for word in the README (a test checks).
pub const BLOWUP_FACTOR_HELP: &str = "Call a run unstable once its energy balance (kinetic + potential + dissipated - injected) has risen by more than this multiple of the scene's energy scale";

/// Relative round-off allowed on the energy terms: sums of large terms of opposite sign
/// are not gains.
const ROUNDOFF: f64 = 1e-9;

/// Checks a blow-up factor given by a user: finite and above 0.
pub fn check_factor(f: f64) -> std::result::Result<f64, String> {
    if f.is_finite() && f > 0.0 {
        Ok(f)
    } else {
        Err(format!("must be a finite number > 0, got {f}"))
    }
}

/// Why the state `s` with energy account `e` (balance `e0_total` at t = 0) is a blow-up, or
/// `None` when it is fine. `scale` is the scene's energy scale (J), `factor` the threshold.
pub fn judge(
    s: &State,
    e: &EnergyRecord,
    e0_total: f64,
    scale: f64,
    factor: f64,
) -> Option<String> {
    if let Some(p) = s.first_non_finite() {
        return Some(format!(
            "diverged: non-finite position or velocity of particle {p}"
        ));
    }
    if !e.is_finite() {
        return Some("diverged: non-finite energy".into());
    }
    let rise = e.total - e0_total;
    let terms =
        e.kinetic.abs() + e.gravity.abs() + e.elastic.abs() + e.dissipated.abs() + e.injected.abs();
    if rise > factor * scale + ROUNDOFF * terms {
        return Some(format!(
            "energy balance rose by {rise:.3e} J (mechanical {:+.3e} J, dissipated {:.3e} J, injected {:.3e} J{}), above {factor} × the scene's energy scale of {scale:.3e} J",
            e.mechanical() - e0_total,
            e.dissipated,
            e.injected,
            if e.created > 0.0 {
                format!(", created by contacts {:.3e} J", e.created)
            } else {
                String::new()
            }
        ));
    }
    None
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

    #[test]
    fn a_gain_hidden_behind_dissipation_still_counts() {
        // Oracle: the balance definition. Mechanical energy unchanged (1 J → 1 J) while the
        // method booked 3 J into its dampers: the balance rose by 3 J, above a 2 J scale.
        let why = judge(&state(1.0), &record(1.0, 3.0), 1.0, 2.0, 1.0);
        assert!(why.is_some_and(|w| w.contains("rose by 3.000e0 J")));
        assert_eq!(judge(&state(1.0), &record(1.0, 1.5), 1.0, 2.0, 1.0), None);
    }

    #[test]
    fn non_finite_states_diverge_and_bad_factors_are_refused() {
        assert!(judge(&state(f64::NAN), &record(1.0, 0.0), 1.0, 1.0, 1.0)
            .is_some_and(|w| w.starts_with("diverged")));
        assert!(check_factor(0.0).is_err() && check_factor(f64::INFINITY).is_err());
        assert_eq!(check_factor(DEFAULT_BLOWUP_FACTOR), Ok(1.0));
    }
}
