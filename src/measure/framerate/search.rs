//! The fewest substeps per frame that pass a test: from one substep, or from the count the
//! linear stability theory says is the fewest stable, upwards until a count passes, then
//! down to the boundary between the last failing and the first passing count.
//!
//! Upwards, each next count doubles the last one unless the runs so far say better: where
//! two failing runs that covered every frame show their error falling as a power of the
//! substeps, the next count is the one that power predicts meets the bound; where it does
//! not fall (or the power predicts more than the limit), the next is the limit itself; where
//! three unstable runs in a row blew up no later for their doubled substeps (an instability
//! that substeps do not cure), the next is the limit too. Downwards, a count predicted the
//! same way from the bracket's two ends, then its neighbour, alternates with plain
//! bisection, so a wrong prediction costs at most one run per halving. A run costs in
//! proportion to its substeps, so each prediction that holds saves the doubling and halving
//! runs above the answer.
//!
//! Assumes the test is monotone in the substeps (more substeps never turn a pass into a
//! failure), as it is for a smooth scene's error and for a stability limit: then the answer
//! is the same whatever order the counts are tried in. Where it is not, the answer is still a
//! count that passes, with the count just below it failing, but which such count depends on
//! the order: a scene with contacts or kicks, whose error moves with the step in and out of
//! an impact's timing, is searched unguided (doubling and bisection only), so its answer is
//! the one plain doubling finds.

use crate::error::Result;

/// One count's outcome, with what the search may predict from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Probe {
    /// The count passed.
    pub passes: bool,
    /// The run's error over the bound, for a run that covered every frame (`None` otherwise).
    pub excess: Option<f64>,
    /// When an unstable run blew up (s); `None` for a stable one.
    pub blew_up: Option<f64>,
}

impl Probe {
    /// A pass or failure with nothing to predict from.
    pub fn bare(passes: bool) -> Self {
        Probe {
            passes,
            excess: None,
            blew_up: None,
        }
    }
}

/// What the search found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Search {
    /// The fewest substeps that passed (`None`: none up to the limit did).
    pub fewest: Option<u64>,
    /// Every count tried, in order, with its outcome.
    pub tried: Vec<(u64, bool)>,
}

/// Least power of the substeps the error must fall by for a prediction to be trusted (a
/// first-order method's error falls as the first power; a flatter fall is a floor the
/// substeps do not lower).
const MIN_POWER: f64 = 0.25;

/// How much later an unstable run must blow up at twice the substeps to count as cured by
/// them (as a factor of its time).
const LATER: f64 = 1.25;

/// The counts tried so far, in order, and what each showed (a count the test refused inside
/// the bracket as a bare failure); `lo` the largest failing count known (0: none), `hi` the
/// smallest passing one.
struct Tracker<F> {
    passes: F,
    guided: bool,
    probes: Vec<(u64, Probe)>,
    lo: u64,
    hi: Option<u64>,
}

impl<F: FnMut(u64) -> Result<Option<Probe>>> Tracker<F> {
    /// Runs count `n`; `None` when the test refused it (over a cost cap).
    fn probe(&mut self, n: u64) -> Result<Option<bool>> {
        let Some(p) = (self.passes)(n)? else {
            return Ok(None);
        };
        self.probes.push((n, p));
        if p.passes {
            self.hi = Some(self.hi.map_or(n, |h| h.min(n)));
        } else {
            self.lo = self.lo.max(n);
        }
        Ok(Some(p.passes))
    }

    fn of(&self, n: u64) -> Option<Probe> {
        self.probes.iter().find(|(m, _)| *m == n).map(|(_, p)| *p)
    }

    fn done(self) -> Result<Search> {
        Ok(Search {
            fewest: self.hi,
            tried: self.probes.iter().map(|(n, p)| (*n, p.passes)).collect(),
        })
    }

    /// The count the error's power law through the runs at `a` and `b` (a < b) predicts is
    /// the fewest to meet the bound, when both covered every frame and the error falls by at
    /// least [`MIN_POWER`] between them; `Some(None)` when it does not fall so.
    fn predicted(&self, a: u64, b: u64) -> Option<Option<f64>> {
        let ea = self.of(a)?.excess.filter(|e| *e > 0.0)?;
        let eb = self.of(b)?.excess.filter(|e| *e > 0.0)?;
        let power = (ea / eb).ln() / (b as f64 / a as f64).ln();
        Some((power >= MIN_POWER).then(|| b as f64 * eb.powf(1.0 / power)))
    }

    /// The next count upwards after a failure at `lo`: the limit, a predicted count, or
    /// `default`.
    fn next_up(&self, default: u64, max: u64) -> u64 {
        if !self.guided {
            return default;
        }
        let fails: Vec<u64> = self
            .probes
            .iter()
            .filter(|(_, p)| !p.passes)
            .map(|(n, _)| *n)
            .collect();
        let lo = self.lo;
        if let Some(&prev) = fails.iter().filter(|&&n| n < lo).max() {
            match self.predicted(prev, lo) {
                Some(None) => return max,
                Some(Some(n)) if n > max as f64 => return max,
                Some(Some(n)) => return (n.ceil() as u64).clamp(lo + 1, max),
                None => {}
            }
        }
        let blew: Vec<f64> = fails
            .iter()
            .rev()
            .take(3)
            .filter_map(|&n| self.of(n).and_then(|p| p.blew_up))
            .collect();
        if blew.len() == 3 && blew[0] <= LATER * blew[1] && blew[1] <= LATER * blew[2] {
            return max;
        }
        default
    }

    /// Closes the bracket between `lo` (failing; 0: none) and `hi` (passing): a predicted
    /// count and its neighbour, alternating with bisection.
    fn close(mut self) -> Result<Search> {
        let mut guided = self.guided;
        while let Some(hi) = self.hi.filter(|&h| h - self.lo > 1) {
            let lo = self.lo;
            let guess = guided
                .then(|| self.predicted(lo, hi).flatten())
                .flatten()
                .map(|n| (n.ceil() as u64).clamp(lo + 1, hi - 1));
            guided = self.guided && !guided;
            let Some(g) = guess else {
                let mid = lo + (hi - lo) / 2;
                if self.probe(mid)?.is_none() {
                    self.refused(mid);
                }
                continue;
            };
            let neighbour = match self.probe(g)? {
                Some(true) => g - 1,
                Some(false) => g + 1,
                None => {
                    self.refused(g);
                    continue;
                }
            };
            if neighbour > self.lo
                && self.hi.is_some_and(|h| neighbour < h)
                && self.probe(neighbour)?.is_none()
            {
                self.refused(neighbour);
            }
        }
        self.done()
    }

    /// A count the test refused inside the bracket counts as failing.
    fn refused(&mut self, n: u64) {
        self.probes.push((n, Probe::bare(false)));
        self.lo = self.lo.max(n);
    }
}

/// Tries 1, 2, 4, … (and finally `max` itself) until `passes` holds or `max` is passed, with
/// the jumps the runs predict when `guided` (module docs), then closes in on the boundary.
/// `passes(n)` may return `Ok(None)` for a count it refuses to run (over a cost cap): the
/// search then stops there as if nothing larger passed.
pub fn fewest_substeps(
    max: u64,
    guided: bool,
    passes: impl FnMut(u64) -> Result<Option<Probe>>,
) -> Result<Search> {
    fewest_substeps_from(1, max, guided, passes)
}

/// As [`fewest_substeps`], starting from `start`, the fewest substeps the linear stability
/// theory says are stable: one substep first (the table's row), then `start − 1` (which the
/// theory says fails; should it pass, the answer lies below it and is found there), then
/// `start` and upwards. A test monotone in the substeps gets the same answer from any start,
/// without the doubling runs below the theory's count.
pub fn fewest_substeps_from(
    start: u64,
    max: u64,
    guided: bool,
    passes: impl FnMut(u64) -> Result<Option<Probe>>,
) -> Result<Search> {
    let max = max.max(1);
    let start = start.min(max);
    let mut t = Tracker {
        passes,
        guided,
        probes: Vec::new(),
        lo: 0,
        hi: None,
    };
    match t.probe(1)? {
        None | Some(true) => return t.done(),
        Some(false) => {}
    }
    let mut n = 2;
    if start > 2 {
        match t.probe(start - 1)? {
            None => return t.done(),
            Some(true) => return t.close(),
            Some(false) => n = t.next_up(start, max),
        }
    }
    while n <= max && n > t.lo {
        match t.probe(n)? {
            None => return t.done(),
            Some(true) => return t.close(),
            Some(false) => {}
        }
        if n == max {
            break;
        }
        n = t.next_up((2 * n).min(max), max);
    }
    t.done()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn threshold(need: u64) -> impl FnMut(u64) -> Result<Option<Probe>> {
        move |n| Ok(Some(Probe::bare(n >= need)))
    }

    // Oracle: a threshold test passes exactly from its threshold on; the search must find it
    // for every threshold, and report none past the limit.
    #[test]
    fn finds_every_threshold() {
        for need in 1..=70u64 {
            let s = fewest_substeps(64, true, threshold(need)).unwrap();
            assert_eq!(s.fewest, (need <= 64).then_some(need), "need {need}");
        }
        let s = fewest_substeps(64, true, |n| Ok((n <= 8).then_some(Probe::bare(false)))).unwrap();
        assert_eq!(s.fewest, None);
        assert_eq!(s.tried.last(), Some(&(8, false)));
    }

    // Oracle: the same threshold tests; from any start, right or wrong, the search finds what
    // the doubling search finds, and from a right start it runs nothing between 1 and it but
    // the count just below.
    #[test]
    fn from_any_start_finds_what_doubling_finds() {
        for need in 1..=70u64 {
            let plain = fewest_substeps(64, true, threshold(need)).unwrap();
            for start in 1..=70u64 {
                let s = fewest_substeps_from(start, 64, true, threshold(need)).unwrap();
                assert_eq!(s.fewest, plain.fewest, "need {need}, start {start}");
                if start == need && start > 2 && need <= 64 {
                    let below: Vec<u64> =
                        s.tried.iter().map(|t| t.0).filter(|&n| n < start).collect();
                    assert_eq!(below, [1, start - 1], "need {need}");
                }
            }
        }
    }

    /// A method whose error over the bound is `c / n^p` at `n` substeps (a stable run's
    /// global error, order p), unstable below `stable` substeps.
    fn power_law(c: f64, p: f64, stable: u64) -> impl FnMut(u64) -> Result<Option<Probe>> {
        move |n| {
            Ok(Some(if n < stable {
                Probe {
                    passes: false,
                    excess: None,
                    blew_up: Some(0.1 * n as f64),
                }
            } else {
                let e = c / (n as f64).powf(p);
                Probe {
                    passes: e <= 1.0,
                    excess: Some(e),
                    blew_up: None,
                }
            }))
        }
    }

    // Oracle: the fewest count a power law passes at, found by trying every count. The
    // predicted counts must find that very answer, from starts 1 to 8, for orders 1 to 4 and
    // constants across three decades; and where the law holds, the runs the search makes from
    // one substep cost (in substeps, summed over the cases) at least a third less than plain
    // doubling and bisection's.
    #[test]
    fn predictions_find_the_power_laws_threshold_for_less() {
        let (mut guided_cost, mut plain_cost) = (0u64, 0u64);
        for p in [1.0, 2.0, 3.0, 4.0] {
            for c in [3.0, 17.0, 150.0, 900.0, 4000.0] {
                for stable in [1, 3, 6] {
                    let want = (1..=64u64).find(|&n| n >= stable && c / (n as f64).powf(p) <= 1.0);
                    let s = fewest_substeps(64, true, power_law(c, p, stable)).unwrap();
                    let plain = fewest_substeps(64, false, power_law(c, p, stable)).unwrap();
                    assert_eq!(s.fewest, want, "c {c}, p {p}, stable {stable}");
                    assert_eq!(plain.fewest, want);
                    for start in 2..=8 {
                        let from = fewest_substeps_from(start, 64, true, power_law(c, p, stable));
                        assert_eq!(from.unwrap().fewest, want, "start {start}");
                    }
                    let cost = |s: &Search| s.tried.iter().map(|t| t.0).sum::<u64>();
                    guided_cost += cost(&s);
                    plain_cost += cost(&plain);
                }
            }
        }
        assert!(
            3 * guided_cost <= 2 * plain_cost,
            "guided {guided_cost} substeps against plain {plain_cost}"
        );
    }

    // Oracle: an error that stops falling (a floor the substeps do not lower, as an engine's
    // constraint softness) can never meet the bound: the search answers none after the two
    // runs that show the floor and the limit itself. Twin: a floor below the bound (passing
    // from 3 substeps on) is found.
    #[test]
    fn a_floor_above_the_bound_jumps_to_the_limit() {
        let floor = |level: f64| {
            move |n: u64| {
                let e = level * (1.0 + 1.0 / n as f64);
                Ok(Some(Probe {
                    passes: e <= 1.0,
                    excess: Some(e),
                    blew_up: None,
                }))
            }
        };
        let s = fewest_substeps(64, true, floor(3.0)).unwrap();
        assert_eq!(s.fewest, None);
        assert_eq!(s.tried, [(1, false), (2, false), (64, false)]);
        let s = fewest_substeps(64, true, floor(0.7)).unwrap();
        assert_eq!(s.fewest, Some(3));
    }

    // Oracle: an instability that substeps do not cure blows up at the same time whatever the
    // count: after three such runs the search tries the limit and answers none. Twin: a
    // blow-up that comes later with each doubling keeps doubling and finds the stable count.
    #[test]
    fn an_uncured_instability_jumps_to_the_limit() {
        let unstable = |later: f64, stable: u64| {
            move |n: u64| {
                Ok(Some(if n < stable {
                    Probe {
                        passes: false,
                        excess: None,
                        blew_up: Some(0.2 * later.powf((n as f64).log2())),
                    }
                } else {
                    Probe::bare(true)
                }))
            }
        };
        let s = fewest_substeps(64, true, unstable(1.0, 100)).unwrap();
        assert_eq!(s.fewest, None);
        assert_eq!(s.tried, [(1, false), (2, false), (4, false), (64, false)]);
        let s = fewest_substeps(64, true, unstable(2.0, 20)).unwrap();
        assert_eq!(s.fewest, Some(20));
        assert!(
            s.tried.iter().any(|t| t.0 == 8),
            "kept doubling: {:?}",
            s.tried
        );
    }
}
