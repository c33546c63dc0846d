//! The fewest substeps per frame that pass a test: doubling, then bisection; from one
//! substep, or from the count the linear stability theory says is the fewest stable.
//!
//! Assumes the test is monotone in the substeps (more substeps never turn a pass into a
//! failure), as it is for a stable method's error and for a stability limit; where it is not,
//! the answer is still a count that passes, with every count below it that was tried failing.

use crate::error::Result;

/// What the search found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Search {
    /// The fewest substeps that passed (`None`: none up to the limit did).
    pub fewest: Option<u64>,
    /// Every count tried, in order, with its outcome.
    pub tried: Vec<(u64, bool)>,
}

/// Tries 1, 2, 4, … (and finally `max` itself) until `passes` holds or `max` is passed, then
/// bisects between the last failing and the first passing count. `passes(n)` may return
/// `Ok(None)` for a count it refuses to run (over a cost cap): the search then stops there as
/// if nothing larger passed.
pub fn fewest_substeps(
    max: u64,
    mut passes: impl FnMut(u64) -> Result<Option<bool>>,
) -> Result<Search> {
    let mut tried = Vec::new();
    let mut lo = 0; // largest count known to fail (0: none tried)
    let mut hi = None;
    let mut n = 1;
    while n <= max.max(1) {
        match passes(n)? {
            None => break,
            Some(ok) => {
                tried.push((n, ok));
                if ok {
                    hi = Some(n);
                    break;
                }
                lo = n;
            }
        }
        n = if n == max { max + 1 } else { (2 * n).min(max) };
    }
    let Some(hi) = hi else {
        return Ok(Search {
            fewest: None,
            tried,
        });
    };
    bisect((lo, hi), &mut passes, tried)
}

/// Bisects between `lo`, a count known to fail (0: none), and `hi`, one known to pass, adding
/// each count tried to `tried`.
fn bisect(
    (mut lo, mut hi): (u64, u64),
    passes: &mut impl FnMut(u64) -> Result<Option<bool>>,
    mut tried: Vec<(u64, bool)>,
) -> Result<Search> {
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        match passes(mid)? {
            Some(true) => {
                tried.push((mid, true));
                hi = mid;
            }
            Some(false) | None => {
                tried.push((mid, false));
                lo = mid;
            }
        }
    }
    Ok(Search {
        fewest: Some(hi),
        tried,
    })
}

/// As [`fewest_substeps`], starting from `start`, the fewest substeps the linear stability
/// theory says are stable: one substep first (the table's row), then `start − 1` (which the
/// theory says fails; should it pass, the answer lies below it and is bisected there), then
/// `start`, 2·`start`, … to `max`, and bisection. A test monotone in the substeps gets the same
/// answer as [`fewest_substeps`], without the doubling runs below the theory's count.
pub fn fewest_substeps_from(
    start: u64,
    max: u64,
    mut passes: impl FnMut(u64) -> Result<Option<bool>>,
) -> Result<Search> {
    let max = max.max(1);
    let start = start.min(max);
    if start <= 2 {
        return fewest_substeps(max, passes);
    }
    let mut tried = Vec::new();
    let none = |tried| {
        Ok(Search {
            fewest: None,
            tried,
        })
    };
    match passes(1)? {
        None => return none(tried),
        Some(ok) => {
            tried.push((1, ok));
            if ok {
                return bisect((0, 1), &mut passes, tried);
            }
        }
    }
    let below = start - 1;
    let mut lo = below;
    match passes(below)? {
        None => return none(tried),
        Some(ok) => {
            tried.push((below, ok));
            if ok {
                return bisect((1, below), &mut passes, tried);
            }
        }
    }
    let mut n = start;
    loop {
        match passes(n)? {
            None => return none(tried),
            Some(true) => {
                tried.push((n, true));
                return bisect((lo, n), &mut passes, tried);
            }
            Some(false) => {
                tried.push((n, false));
                lo = n;
            }
        }
        if n == max {
            return none(tried);
        }
        n = (2 * n).min(max);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Oracle: a threshold test passes exactly from its threshold on; the search must find it
    // for every threshold, and report none past the limit.
    #[test]
    fn finds_every_threshold() {
        for need in 1..=70u64 {
            let s = fewest_substeps(64, |n| Ok(Some(n >= need))).unwrap();
            assert_eq!(s.fewest, (need <= 64).then_some(need), "need {need}");
        }
        let s = fewest_substeps(64, |n| Ok((n <= 8).then_some(false))).unwrap();
        assert_eq!(s.fewest, None);
        assert_eq!(s.tried.last(), Some(&(8, false)));
    }

    // Oracle: the same threshold tests; from any start, right or wrong, the search finds what
    // the doubling search finds, and from a right start it runs nothing between 1 and it but
    // the count just below.
    #[test]
    fn from_any_start_finds_what_doubling_finds() {
        for need in 1..=70u64 {
            let plain = fewest_substeps(64, |n| Ok(Some(n >= need))).unwrap();
            for start in 1..=70u64 {
                let s = fewest_substeps_from(start, 64, |n| Ok(Some(n >= need))).unwrap();
                assert_eq!(s.fewest, plain.fewest, "need {need}, start {start}");
                if start == need && start > 2 && need <= 64 {
                    let below: Vec<u64> =
                        s.tried.iter().map(|t| t.0).filter(|&n| n < start).collect();
                    assert_eq!(below, [1, start - 1], "need {need}");
                }
            }
        }
    }
}
