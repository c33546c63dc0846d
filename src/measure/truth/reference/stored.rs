//! A sampled reference and a made ensemble as entries of the reference store ([`super::store`]):
//! what is written, and how it is read back into the same values, bit for bit.
//!
//! A reference entry holds everything [`Reference::compute_within`] fills in (the record, the
//! positions and uncertainty at every sample, the crossings, the motion scale, the member
//! solver), so a reference read back is the reference the solve gave; an ensemble entry holds
//! the members' observables and how they were made. Closed forms are not stored: they cost
//! less than reading them.

use super::ensemble::MemberSolver;
use super::{store, Reference, ReferenceInfo, Tracked};
use crate::measure::grid::TimeGrid;
use crate::measure::statistics::{window_times, Ensemble, Observed};
use crate::model::{State, System, Vec3};
use serde::{Deserialize, Serialize};

/// The store's key of a reference: everything the computed values depend on.
pub(super) fn reference_key(
    sys: &System,
    s0: &State,
    grids: &[TimeGrid],
    horizon: f64,
    solver: super::ReferenceSolver,
    limit: Option<f64>,
) -> String {
    format!("{sys:?}|{s0:?}|{grids:?}|{horizon:?}|{solver:?}|{limit:?}")
}

/// What a reference entry holds besides its floats.
#[derive(Debug, PartialEq, Serialize, Deserialize)]
struct Header {
    info: ReferenceInfo,
    grids: Vec<TimeGrid>,
    /// Particles in each sample of each grid (a sample may be empty).
    lens: Vec<Vec<u32>>,
    tracked: Option<Tracked>,
    crossings: usize,
    down_crossings: usize,
    member_solver: Option<MemberSolver>,
    /// Sampled from a kept solve (so it gets a solve id, as a fresh one would).
    kept: bool,
}

/// The header's JSON when it parses back equal (a value JSON cannot carry, such as an
/// infinite uncertainty, is not stored).
fn header_bytes<T: Serialize + for<'a> Deserialize<'a> + PartialEq>(h: &T) -> Option<Vec<u8>> {
    let bytes = serde_json::to_vec(h).ok()?;
    let back: T = serde_json::from_slice(&bytes).ok()?;
    (back == *h).then_some(bytes)
}

/// Writes `r`, computed for `key`, to the store in use (the caller stores no closed form).
pub(super) fn save_reference(key: &str, r: &Reference) {
    if store::dir().is_none() {
        return;
    }
    let header = Header {
        info: r.info.clone(),
        grids: r.grids.clone(),
        lens: r
            .samples
            .iter()
            .map(|g| g.iter().map(|x| x.len() as u32).collect())
            .collect(),
        tracked: r.tracked,
        crossings: r.crossings.len(),
        down_crossings: r.down_crossings.len(),
        member_solver: r.member_solver,
        kept: r.solve_id.is_some(),
    };
    let Some(bytes) = header_bytes(&header) else {
        return;
    };
    let mut floats = Vec::new();
    for x in r.samples.iter().flatten().flatten() {
        floats.extend_from_slice(&[x[0], x[1], x[2]]);
    }
    for u in &r.unc {
        floats.extend_from_slice(u);
    }
    floats.extend_from_slice(&r.crossings);
    floats.extend_from_slice(&r.down_crossings);
    floats.push(r.motion);
    store::save("reference", key, &bytes, &floats);
}

/// The reference stored for `key`, held to `limit` like the one it stands for; None when the
/// store has none (or none that passes its checks).
pub(super) fn load_reference(key: &str, limit: Option<f64>) -> Option<Reference> {
    let (bytes, floats) = store::load("reference", key)?;
    let h: Header = serde_json::from_slice(&bytes).ok()?;
    let points: usize = h.lens.iter().flatten().map(|&n| n as usize).sum();
    let uncs: usize = h.grids.iter().map(|g| g.sample_count()).sum();
    if h.lens.len() != h.grids.len()
        || h.lens
            .iter()
            .zip(&h.grids)
            .any(|(l, g)| l.len() != g.sample_count())
        || floats.len() != 3 * points + uncs + h.crossings + h.down_crossings + 1
    {
        return None;
    }
    let mut at = floats.iter().copied();
    let mut take = |n: usize| -> Vec<f64> { at.by_ref().take(n).collect() };
    let samples = h
        .lens
        .iter()
        .map(|g| {
            g.iter()
                .map(|&n| {
                    take(3 * n as usize)
                        .chunks_exact(3)
                        .map(|c| Vec3::new(c[0], c[1], c[2]))
                        .collect()
                })
                .collect()
        })
        .collect();
    let unc = h.grids.iter().map(|g| take(g.sample_count())).collect();
    let crossings = take(h.crossings);
    let down_crossings = take(h.down_crossings);
    let motion = take(1)[0];
    Some(Reference {
        info: h.info,
        strain_until: h.grids.iter().map(|_| std::sync::OnceLock::new()).collect(),
        grids: h.grids,
        samples,
        tracked: h.tracked,
        crossings,
        down_crossings,
        motion,
        unc,
        ensemble: None,
        member_solver: h.member_solver,
        solve_id: h.kept.then(super::solution::new_id),
        limit,
    })
}

/// What an ensemble entry holds besides its members' observables.
#[derive(Debug, PartialEq, Serialize, Deserialize)]
struct EnsembleHeader {
    /// The ensemble's window, or None when none could be made.
    window: Option<(f64, f64)>,
    /// How the members were made, or why there is no ensemble.
    text: String,
    members: usize,
}

/// Writes `made`, the ensemble (or why none) for `key`, to the store in use.
pub(super) fn save_ensemble(key: &str, made: &Result<Ensemble, String>) {
    if store::dir().is_none() {
        return;
    }
    let (header, floats) = match made {
        Ok(e) => (
            EnsembleHeader {
                window: Some((e.start, e.end)),
                text: e.made_by.clone(),
                members: e.members.len(),
            },
            e.members.iter().flatten().copied().collect::<Vec<f64>>(),
        ),
        Err(why) => (
            EnsembleHeader {
                window: None,
                text: why.clone(),
                members: 0,
            },
            Vec::new(),
        ),
    };
    if let Some(bytes) = header_bytes(&header) {
        store::save("ensemble", key, &bytes, &floats);
    }
}

/// The ensemble (or why none) stored for `key`, its tolerances left at 0 as a fresh one's.
pub(super) fn load_ensemble(key: &str) -> Option<Result<Ensemble, String>> {
    let (bytes, floats) = store::load("ensemble", key)?;
    let h: EnsembleHeader = serde_json::from_slice(&bytes).ok()?;
    let width = std::mem::size_of::<Observed>() / 8;
    if floats.len() != h.members * width {
        return None;
    }
    let Some((start, end)) = h.window else {
        return Some(Err(h.text));
    };
    let members = floats
        .chunks_exact(width)
        .map(|c| c.try_into().expect("one member's observables"))
        .collect();
    Some(Ok(Ensemble {
        start,
        end,
        times: window_times(start, end),
        members,
        tolerance: 0.0,
        relative_tolerance: 0.0,
        made_by: h.text,
        grid: None,
    }))
}
