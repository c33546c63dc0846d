//! The fewest substeps per frame that pass a test: doubling, then bisection.
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
    let Some(mut hi) = hi else {
        return Ok(Search {
            fewest: None,
            tried,
        });
    };
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
}
