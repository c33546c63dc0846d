//! A stage that ran out of iterations, solved again along its root path: the backward-Euler
//! stages of steps β·k/K from the same base, k = 1 … K, each started from the last roots
//! extrapolated (natural-parameter continuation; Allgower & Georg, Introduction to Numerical
//! Continuation Methods, 2003, §1). Where the path reaches β, the stage is solved, at a root
//! of its own equation. Where it stops, the Newton matrix's lowest eigenvalue at each root on
//! the way says why: it falls to 0 where the stage's roots branch (a compressed cloth that
//! buckles within the step), and past such a point the roots lie on another branch, which
//! Newton from the path cannot be expected to find. The path allocates (its Lanczos vectors):
//! it runs only for a stage whose direct iteration failed, never in a step that converges.

use super::curvature::lowest_curvature;
use super::stage::Stage;
use super::{Failure, Newton};
use crate::error::significant;
use crate::model::{Jacobian, Vec3};

/// Pieces of the path.
pub(super) const PIECES: usize = 16;

/// How far the path got: pieces solved, and the lowest eigenvalue met on it with its piece.
#[derive(Debug, Clone, Copy)]
pub(super) struct PathEnd {
    /// Pieces whose roots were found (at most `PIECES − 1`: the last is the stage).
    pub(super) solved: usize,
    /// The Newton matrix's lowest mass-relative eigenvalue over those roots (an upper bound,
    /// see `curvature.rs`), and the piece it was met at.
    pub(super) lowest: Option<(f64, usize)>,
}

/// A fixed start for Lanczos at a root (where the residual is zero): a deterministic spread
/// over every particle and axis.
fn spread(n: usize) -> impl Iterator<Item = Vec3> {
    (0..n).map(|p| {
        let u = |k: u64| {
            let z = (p as u64 * 3 + k + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            (z >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        Vec3::new(u(0), u(1), u(2))
    })
}

impl Newton {
    /// Solves the stage `st` along its root path (module docs); `Ok` with the dissipated power
    /// at its root, or where the path stopped.
    pub(super) fn along_path(
        &mut self,
        st: &Stage<'_>,
        jac: &mut Jacobian,
        evals: &mut u64,
    ) -> std::result::Result<f64, PathEnd> {
        let (sys, n) = (st.sys, st.x0.len());
        // The stage's own error-estimate predictor, from v̂.
        self.vn.copy_from_slice(st.v0);
        let _ = self.residual(st);
        *evals += 1;
        self.predict(st);
        self.path_prev.copy_from_slice(st.v0);
        self.path_start.clear();
        self.path_start.extend(spread(n));
        let mut end = PathEnd {
            solved: 0,
            lowest: None,
        };
        for k in 1..=PIECES {
            // Pieces before the last stop at the root tolerance (an infinite κ).
            let kappa = if k == PIECES { st.kappa } else { f64::MAX };
            let piece = Stage::new(sys, st.x0, st.v0, st.h * k as f64 / PIECES as f64, kappa);
            if k >= 2 {
                for p in 0..n {
                    let step = self.vn[p] - self.path_prev[p];
                    self.path_prev[p] = self.vn[p];
                    self.vn[p] += step;
                }
            }
            let mut res = self.residual(&piece);
            *evals += 1;
            jac.shift = 0.0;
            let power = match self.iterate(&piece, jac, &mut res, evals) {
                Ok(power) => power,
                Err(_) => return Err(end),
            };
            if k == PIECES {
                return Ok(power);
            }
            end.solved = k;
            jac.clamp = 0.0;
            jac.shift = 0.0;
            sys.jacobian(&self.xn, &self.vn, jac);
            jac.prepare_newton(&sys.mass, &sys.free, piece.h);
            if let Some(l) = lowest_curvature(jac, sys, &self.path_start) {
                if end.lowest.is_none_or(|(m, _)| l < m) {
                    end.lowest = Some((l, k));
                }
            }
        }
        Err(end)
    }
}

impl PathEnd {
    /// Where the root path stopped, in words.
    pub(super) fn describe(&self) -> String {
        let solved = match self.solved {
            0 => "none of its roots were found".to_string(),
            k => format!("its roots were found up to {k}/{PIECES} of the step"),
        };
        let lowest = self.lowest.map_or(String::new(), |(l, k)| {
            format!(
                ", the Newton matrix's lowest eigenvalue on them falling to at most {} times \
                 the mass term's at {k}/{PIECES} (0 is where the roots branch, as where a \
                 compressed cloth buckles within the step)",
                significant(l, 4)
            )
        });
        format!("; followed from its base state in {PIECES} pieces of its step, {solved}{lowest}")
    }
}

impl Failure {
    /// Attaches where the root path stopped to a stage that ran out of iterations.
    pub(super) fn with_path(self, end: PathEnd) -> Failure {
        match self {
            Failure::NoConvergence { at, .. } => Failure::NoConvergence {
                at,
                path: Some(end),
            },
            other => other,
        }
    }
}
