//! A stage that ran out of iterations, solved again along its root path: the backward-Euler
//! stages of steps β·k/K from the same base, k = 1 … K, each started from the last roots
//! extrapolated (natural-parameter continuation; Allgower & Georg, Introduction to Numerical
//! Continuation Methods, 2003, §1). Where the path reaches β, the stage is solved, at a root
//! of its own equation. Where it stops, the Newton matrix's lowest eigenvalue at each root on
//! the way says why: it falls to 0 where the stage's roots branch (a compressed cloth that
//! buckles within the step), and past such a point the roots lie on another branch, which
//! Newton from the path cannot be expected to find. The eigenvalues are estimated only once
//! the path has failed too, so a path that succeeds costs its pieces alone. The path
//! allocates (the roots it keeps, and Lanczos' vectors): it runs only for a stage whose direct
//! iteration failed, never in a step that converges.

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
    /// at its root, or `Err` with the pieces solved before it stopped, their roots in
    /// `path_roots`. Nothing is estimated here: a path that succeeds costs its pieces only.
    pub(super) fn along_path(
        &mut self,
        st: &Stage<'_>,
        jac: &mut Jacobian,
        evals: &mut u64,
    ) -> std::result::Result<f64, usize> {
        let (sys, n) = (st.sys, st.x0.len());
        // The last piece's error estimate reads the stage's own predictor, which `start` set
        // and no iteration changes.
        self.vn.copy_from_slice(st.v0);
        self.path_prev.copy_from_slice(st.v0);
        self.path_roots.clear();
        let mut last = Err(0);
        for k in 1..=PIECES {
            // Pieces before the last stop at the root tolerance (an infinite κ).
            let kappa = if k == PIECES { st.kappa } else { f64::MAX };
            let piece = Stage::new(sys, st.x0, st.v0, piece_step(st.h, k), kappa);
            if k >= 2 {
                for p in 0..n {
                    let step = self.vn[p] - self.path_prev[p];
                    self.path_prev[p] = self.vn[p];
                    self.vn[p] += step;
                }
            }
            last = self
                .iterate_from_here(&piece, jac, evals, usize::MAX)
                .0
                .map_err(|_| k - 1);
            match last {
                Ok(_) if k < PIECES => self.path_roots.extend_from_slice(&self.vn),
                Ok(_) => {}
                Err(_) => break,
            }
        }
        last
    }

    /// The failure of a stage whose direct iteration (`failure`, stopped at `stop_v` with
    /// residual `stop_r`) and root path (`solved` pieces, roots in `path_roots`) both stopped,
    /// with the Newton matrix's lowest eigenvalue at the stop and on the path's roots.
    pub(super) fn explain(
        &mut self,
        st: &Stage<'_>,
        jac: &mut Jacobian,
        failure: Failure,
        solved: usize,
    ) -> Failure {
        let Failure::NoConvergence { mut at, .. } = failure else {
            return failure;
        };
        let (sys, n) = (st.sys, st.x0.len());
        self.vn.copy_from_slice(&self.stop_v);
        self.exact_matrix(st, st.h, jac);
        at.curvature = lowest_curvature(jac, sys, &self.stop_r);
        self.path_start.clear();
        self.path_start.extend(spread(n));
        let mut lowest: Option<(f64, usize)> = None;
        for k in 1..=solved {
            self.vn
                .copy_from_slice(&self.path_roots[(k - 1) * n..k * n]);
            self.exact_matrix(st, piece_step(st.h, k), jac);
            if let Some(l) = lowest_curvature(jac, sys, &self.path_start) {
                if lowest.is_none_or(|(m, _)| l < m) {
                    lowest = Some((l, k));
                }
            }
        }
        Failure::NoConvergence {
            at,
            path: Some(PathEnd { solved, lowest }),
        }
    }

    /// Fills `jac` with the exact, unshifted Newton matrix of step `h` at v' = `self.vn`
    /// (x' = x̂ + h v', into `self.xn`).
    fn exact_matrix(&mut self, st: &Stage<'_>, h: f64, jac: &mut Jacobian) {
        let sys = st.sys;
        for p in 0..st.x0.len() {
            self.xn[p] = st.x0[p] + self.vn[p] * h;
        }
        jac.shift = 0.0;
        sys.newton_matrix(&self.xn, &self.vn, h, 0.0, jac);
    }
}

/// The step of piece `k` of a stage of step `h`.
fn piece_step(h: f64, k: usize) -> f64 {
    h * k as f64 / PIECES as f64
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
