//! Nonlinear elimination of the patch that holds a stalled stage's residual (Lanzkron, Rose
//! & Wilkes, SIAM J. Sci. Comput. 17, 1996; Cai & Keyes, SIAM J. Sci. Comput. 24, 2002).
//!
//! Where a folding cloth's stage runs out of Newton iterations, its residual sits on a few
//! neighbouring particles (a 3×3 knot holding 97 % of it on the 100×100 cloth), whose springs
//! turn through large angles within the step: the global iteration, whose matrix the rest of
//! the cloth makes well conditioned, crawls there. The patch, those particles and their spring
//! neighbours with every other velocity held, is a small problem of its own: the stage's
//! incremental potential Φ restricted to it is minimised by a trust-region Newton method on
//! its exact dense Hessian (Moré & Sorensen, SIAM J. Sci. Stat. Comput. 4, 1983: the step
//! minimises the quadratic model within a radius whatever the Hessian's inertia, so it
//! leaves saddles and converges quadratically at a minimum). Φ's change is summed over the
//! patch's own terms, so that its round-off is the patch's and not the whole cloth's. The
//! global iteration then resumes from there. The elimination runs only for a stage whose
//! direct iteration failed, never in a step that converges, and it allocates.

use super::stage::Stage;
use super::{Failure, Newton};
use crate::model::TermKind;
use crate::model::{Jacobian, System, Vec3};
use nalgebra::{DMatrix, DVector, Matrix3};

/// Most particles in the residual's core, the particles holding the most of it.
const CORE: usize = 40;
/// Most particles in a patch: the core and its spring neighbours.
const MAX_PATCH: usize = 120;
/// Trials of one trust-region iteration, each on a smaller radius.
const MAX_TRIALS: usize = 60;
/// Share of the residual's merit the core gathers before it stops growing.
const CORE_SHARE: f64 = 0.999;
/// Most patch eliminations in one stage.
const MAX_ELIMINATIONS: usize = 128;
/// Eliminations end once this many in a row past the first [`FULL_RESUMES`] have not lowered
/// the lowest residual merit their cut-short iterations reached.
const STALE_ELIMINATIONS: usize = 20;
/// The iterations resumed after the first this many eliminations run in full.
const FULL_RESUMES: usize = 8;
/// Later, the iteration resumed after an elimination hands back to the next one once this
/// many of its iterations in a row have not lowered its lowest merit.
const RESUME_PATIENCE: usize = 5;
/// The patch is solved to this fraction of the stage's root tolerance (RMS over the whole
/// system), so that the rest of the stage meets it.
const PATCH_TOL: f64 = 0.01;

/// The particles of a patch, the springs touching them, and their indices.
struct Patch {
    particles: Vec<usize>,
    springs: Vec<usize>,
    /// Position of each particle in `particles`, `usize::MAX` outside the patch.
    index: Vec<usize>,
    /// M^(−1/2) per unknown.
    scale: Vec<f64>,
    /// Scratch: x' = x̂ + h v' at the particles the patch's springs join.
    x: Vec<Vec3>,
}

/// Whether a patch's potential can be summed over its own terms: springs and gravity only,
/// and the stage not momentum-balanced (a patch move would shift every velocity).
pub(super) fn eliminable(sys: &System, balanced: bool) -> bool {
    !balanced
        && sys.constraints.is_empty()
        && sys.terms.iter().all(|t| t.kind() == TermKind::Gravity)
}

impl Patch {
    /// The core of the residual `r` (its largest particles until they hold [`CORE_SHARE`]
    /// of the merit, at most [`CORE`]) and the core's spring neighbours, at most
    /// [`MAX_PATCH`] particles in all, in index order.
    fn around(sys: &System, r: &[Vec3]) -> Self {
        let n = sys.len();
        let mut weight: Vec<(f64, usize)> = (0..n)
            .filter(|&p| sys.free[p])
            .map(|p| (r[p].norm_squared() * sys.inv_mass[p], p))
            .collect();
        weight.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        let total: f64 = weight.iter().map(|w| w.0).sum();
        let mut in_core = vec![false; n];
        let mut index = vec![usize::MAX; n];
        let mut particles = Vec::new();
        let mut held = 0.0;
        for &(w, p) in weight.iter().take(CORE) {
            if held >= CORE_SHARE * total {
                break;
            }
            held += w;
            in_core[p] = true;
            index[p] = 0;
            particles.push(p);
        }
        let sp = &sys.springs;
        for s in 0..sp.len() {
            let (a, b) = (sp.i[s] as usize, sp.j[s] as usize);
            for (u, w) in [(a, b), (b, a)] {
                if in_core[u]
                    && index[w] == usize::MAX
                    && sys.free[w]
                    && particles.len() < MAX_PATCH
                {
                    index[w] = 0;
                    particles.push(w);
                }
            }
        }
        particles.sort_unstable();
        for (q, &p) in particles.iter().enumerate() {
            index[p] = q;
        }
        let springs = (0..sp.len())
            .filter(|&s| {
                index[sp.i[s] as usize] != usize::MAX || index[sp.j[s] as usize] != usize::MAX
            })
            .collect();
        let scale = particles
            .iter()
            .flat_map(|&p| [sys.inv_mass[p].sqrt(); 3])
            .collect();
        Patch {
            particles,
            springs,
            index,
            scale,
            x: vec![Vec3::zeros(); n],
        }
    }

    /// Σ |Gₚ|²/mₚ over the patch.
    fn merit(&self, sys: &System, r: &[Vec3]) -> f64 {
        self.particles
            .iter()
            .map(|&p| r[p].norm_squared() * sys.inv_mass[p])
            .sum()
    }

    /// The terms of the stage's incremental potential that the patch's velocities change,
    /// at v' = `v` (x' = x̂ + h v'), the dampers' directions frozen at `frozen`, and their
    /// round-off: the patch's kinetic and gravity terms, and its springs' elastic energy and
    /// half their dissipation times h (as `potential.rs` sums them for the whole system).
    fn potential(&mut self, st: &Stage<'_>, v: &[Vec3], frozen: &[Vec3]) -> (f64, f64) {
        let (sys, h) = (st.sys, st.h);
        let sp = &sys.springs;
        let joined = self
            .springs
            .iter()
            .flat_map(|&s| [sp.i[s] as usize, sp.j[s] as usize]);
        for p in self.particles.iter().copied().chain(joined) {
            self.x[p] = st.x0[p] + v[p] * h;
        }
        let g = sys.gravity.unwrap_or_else(Vec3::zeros);
        let (mut value, mut size) = (0.0, 0.0);
        for &p in &self.particles {
            let kin = 0.5 * sys.mass[p] * (v[p] - st.v0[p]).norm_squared();
            let lift = -sys.mass[p] * g.dot(&self.x[p]);
            value += kin + lift;
            size += kin + lift.abs();
        }
        for &s in &self.springs {
            let elastic = sp.energy_of(s, &self.x);
            // The damper's power c (n·(v_b − v_a))² along its frozen direction.
            let damp = 0.5 * h * sp.force::<true>(s, frozen, v).1;
            value += elastic + damp;
            size += elastic + damp;
        }
        let terms = (self.particles.len() + self.springs.len()) as f64;
        (value, 8.0 * f64::EPSILON * terms.sqrt() * size)
    }

    /// The patch's rows and columns of the Newton matrix prepared in `jac`, scaled by
    /// M^(−1/2) on both sides.
    fn hessian(&self, jac: &Jacobian) -> DMatrix<f64> {
        let k = self.particles.len();
        let (pairs, own) = jac.newton_blocks();
        let mut a = DMatrix::zeros(3 * k, 3 * k);
        let mut add = |qi: usize, qj: usize, b: &Matrix3<f64>, sign: f64| {
            for r in 0..3 {
                for c in 0..3 {
                    a[(3 * qi + r, 3 * qj + c)] += sign * b[(r, c)];
                }
            }
        };
        for (q, &p) in self.particles.iter().enumerate() {
            add(q, q, &own[p], 1.0);
        }
        for &s in &self.springs {
            let [u, w] = jac.pairs[s];
            let (qu, qw) = (self.index[u as usize], self.index[w as usize]);
            let b = pairs[s].full();
            if qu != usize::MAX {
                add(qu, qu, &b, 1.0);
            }
            if qw != usize::MAX {
                add(qw, qw, &b, 1.0);
            }
            if qu != usize::MAX && qw != usize::MAX && u != w {
                add(qu, qw, &b, -1.0);
                add(qw, qu, &b, -1.0);
            }
        }
        for i in 0..3 * k {
            for j in 0..3 * k {
                a[(i, j)] *= self.scale[i] * self.scale[j];
            }
        }
        a
    }
}

impl Newton {
    /// Eliminates the patches of a stage whose direct iteration `solved` ran out of
    /// iterations (any other outcome is returned as is, with no elimination), each
    /// elimination followed by the iteration resumed, until the stage is
    /// solved, an elimination gains nothing, [`STALE_ELIMINATIONS`] in a row leave the lowest
    /// merit where it was, or [`MAX_ELIMINATIONS`] were made. A folding cloth's stage holds
    /// many knots, each solved in turn: past the first [`FULL_RESUMES`] eliminations the
    /// resumed iteration is cut short once it stalls ([`RESUME_PATIENCE`]), since there the
    /// next elimination gains more than it, and it runs in full once more when the
    /// eliminations end. A stage solved within the first eliminations is solved as it would
    /// be with no more. Returns the outcome and the eliminations made.
    pub(super) fn eliminate_patches(
        &mut self,
        st: &Stage<'_>,
        jac: &mut Jacobian,
        evals: &mut u64,
        mut solved: Result<f64, Failure>,
    ) -> (Result<f64, Failure>, usize) {
        let (mut lowest, mut stale, mut eliminated) = (f64::INFINITY, 0, 0);
        while eliminated < MAX_ELIMINATIONS
            && stale < STALE_ELIMINATIONS
            && matches!(solved, Err(Failure::NoConvergence { .. }))
            && self.eliminate_patch(st, jac, evals)
        {
            eliminated += 1;
            let patience = if eliminated <= FULL_RESUMES {
                usize::MAX
            } else {
                RESUME_PATIENCE
            };
            let merit;
            (solved, merit) = self.iterate_from_here(st, jac, evals, patience);
            // Progress is judged among the cut-short iterations alone: a full one ends lower.
            if eliminated > FULL_RESUMES {
                if merit < lowest {
                    (lowest, stale) = (merit, 0);
                } else {
                    stale += 1;
                }
            }
        }
        if eliminated > FULL_RESUMES && matches!(solved, Err(Failure::NoConvergence { .. })) {
            // The last resumed iteration may have been cut short: it runs once more in full.
            solved = self.iterate_from_here(st, jac, evals, usize::MAX).0;
        }
        (solved, eliminated)
    }

    /// Minimises the stage's incremental potential over the patch around its residual in
    /// `self.r` (module docs), from the iterate in `self.vn`, in at most the stage's
    /// iteration cap of trust-region iterations; returns whether the patch's residual fell.
    /// Counts its force evaluations and trust-region iterations.
    pub(super) fn eliminate_patch(
        &mut self,
        st: &Stage<'_>,
        jac: &mut Jacobian,
        evals: &mut u64,
    ) -> bool {
        let sys = st.sys;
        if jac.pairs.len() != sys.springs.len() {
            return false;
        }
        let mut patch = Patch::around(sys, &self.r);
        let start = patch.merit(sys, &self.r);
        let res = self.residual(st);
        *evals += 1;
        let target = (PATCH_TOL * self.settings.root_tol * res.scale).powi(2) * st.free_mass;
        let mut radius = f64::NAN;
        let mut frozen = vec![Vec3::zeros(); sys.len()];
        // The stage's iteration cap bounds each patch solve too.
        for _ in 0..self.settings.max_newton {
            if patch.merit(sys, &self.r) <= target {
                break;
            }
            self.patch_iterations += 1;
            jac.shift = 0.0;
            sys.newton_matrix(&self.xn, &self.vn, st.h, 0.0, jac);
            let a = patch.hessian(jac);
            let g = DVector::from_iterator(
                a.nrows(),
                patch
                    .particles
                    .iter()
                    .flat_map(|&p| [self.r[p][0], self.r[p][1], self.r[p][2]])
                    .zip(&patch.scale)
                    .map(|(g, s)| g * s),
            );
            let mut model = Model::new(a, g);
            if radius.is_nan() {
                radius = model.g.norm();
            }
            self.vbase.copy_from_slice(&self.vn);
            for &s in &patch.springs {
                for p in [sys.springs.i[s] as usize, sys.springs.j[s] as usize] {
                    frozen[p] = st.x0[p] + self.vbase[p] * st.h;
                }
            }
            let (phi0, noise) = patch.potential(st, &self.vbase, &frozen);
            let mut accepted = false;
            for _ in 0..MAX_TRIALS {
                let (y, pred) = model.step(radius);
                let len = y.norm();
                for (q, &p) in patch.particles.iter().enumerate() {
                    for d in 0..3 {
                        self.vn[p][d] = self.vbase[p][d] + y[3 * q + d] * patch.scale[3 * q + d];
                    }
                }
                let (phi, _) = patch.potential(st, &self.vn, &frozen);
                let drop = phi0 - phi;
                let rho = drop / pred;
                // A ratio that is not a number (a non-finite trial) shrinks the radius too.
                if rho.is_nan() || rho < 0.25 {
                    radius = 0.25 * len;
                } else if rho > 0.75 && len > 0.99 * radius {
                    radius *= 2.0;
                }
                if drop > noise && rho > 0.01 {
                    accepted = true;
                    break;
                }
                if pred.is_nan() || pred <= noise {
                    break;
                }
            }
            if !accepted {
                self.vn.copy_from_slice(&self.vbase);
            }
            let _ = self.residual(st);
            *evals += 1;
            if !accepted {
                break;
            }
        }
        patch.merit(sys, &self.r) < start
    }
}

/// The quadratic model gᵀy + ½ yᵀAy of a patch in its Hessian's eigenbasis.
struct Model {
    a: DMatrix<f64>,
    g: DVector<f64>,
    /// Newton's step where A is positive definite.
    newton: Option<DVector<f64>>,
    eigen: Option<(DVector<f64>, DMatrix<f64>, DVector<f64>)>,
}

impl Model {
    fn new(a: DMatrix<f64>, g: DVector<f64>) -> Self {
        let newton = a.clone().cholesky().map(|c| -c.solve(&g));
        Model {
            a,
            g,
            newton,
            eigen: None,
        }
    }

    /// The step of length at most `radius` that minimises the model (Moré & Sorensen), and
    /// the decrease it predicts.
    fn step(&mut self, radius: f64) -> (DVector<f64>, f64) {
        let y = match &self.newton {
            Some(y) if y.norm() <= radius => y.clone(),
            _ => self.boundary_step(radius),
        };
        let pred = -(self.g.dot(&y) + 0.5 * y.dot(&(&self.a * &y)));
        (y, pred)
    }

    /// The model's minimiser on the sphere of `radius`: y(σ) = −(A + σI)⁻¹g with σ ≥
    /// max(0, −λ_min) found by bisection, plus the lowest eigenvector where g has no part
    /// along it (the hard case).
    fn boundary_step(&mut self, radius: f64) -> DVector<f64> {
        if self.eigen.is_none() {
            let e = self.a.clone().symmetric_eigen();
            let c = e.eigenvectors.transpose() * &self.g;
            self.eigen = Some((e.eigenvalues, e.eigenvectors, c));
        }
        let (l, q, c) = self.eigen.as_ref().expect("set above");
        let at = |sigma: f64| {
            DVector::from_iterator(l.len(), (0..l.len()).map(|i| -c[i] / (l[i] + sigma)))
        };
        let lowest = (0..l.len())
            .min_by(|&a, &b| l[a].total_cmp(&l[b]))
            .unwrap_or(0);
        let floor = (-l[lowest]).max(0.0);
        let mut lo = floor + 1e-12 * (1.0 + floor);
        let y = at(lo);
        if y.norm() < radius {
            let mut y = y;
            y[lowest] += (radius * radius - y.norm_squared()).max(0.0).sqrt();
            return q * y;
        }
        let mut hi = floor + c.norm() / radius + 1.0;
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if at(mid).norm() > radius {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        q * at(hi)
    }
}

#[cfg(test)]
mod tests {
    //! Oracle: Moré & Sorensen's characterisation of the trust-region step (SIAM J. Sci.
    //! Stat. Comput. 4, 1983, Lemma 2.1; Nocedal & Wright, Numerical Optimization, Thm 4.1):
    //! y minimises gᵀy + ½yᵀAy over |y| ≤ Δ if and only if (A + σI)y = −g for some σ ≥ 0
    //! with A + σI positive semi-definite and σ(Δ − |y|) = 0.
    use super::*;

    fn check(a: DMatrix<f64>, g: DVector<f64>, radius: f64) -> (DVector<f64>, f64) {
        let mut model = Model::new(a.clone(), g.clone());
        let (y, pred) = model.step(radius);
        let n = y.len();
        assert!(y.norm() <= radius * (1.0 + 1e-9), "inside the radius");
        // σ from the step itself: (A + σI)y = −g along y.
        let sigma = -(g.dot(&y) + y.dot(&(&a * &y))) / y.norm_squared();
        assert!(sigma >= -1e-9, "σ = {sigma} ≥ 0");
        let shifted = &a + DMatrix::identity(n, n) * sigma;
        let lowest = shifted.clone().symmetric_eigen().eigenvalues.min();
        assert!(lowest >= -1e-8, "A + σI positive semi-definite ({lowest})");
        let stationarity = (&shifted * &y + &g).norm();
        assert!(
            stationarity <= 1e-8 * (1.0 + g.norm()),
            "(A + σI)y = −g: {stationarity}"
        );
        assert!(
            sigma.abs() * (radius - y.norm()).abs() <= 1e-8,
            "complementarity"
        );
        assert!((pred + g.dot(&y) + 0.5 * y.dot(&(&a * &y))).abs() <= 1e-12);
        (y, sigma)
    }

    #[test]
    fn a_positive_definite_model_takes_newtons_step_inside_the_radius() {
        let a = DMatrix::from_row_slice(3, 3, &[4.0, 1.0, 0.0, 1.0, 3.0, 0.5, 0.0, 0.5, 2.0]);
        let g = DVector::from_row_slice(&[0.1, -0.2, 0.3]);
        let (y, sigma) = check(a.clone(), g.clone(), 10.0);
        assert!(sigma.abs() <= 1e-12);
        assert!((&a * &y + &g).norm() <= 1e-14);
        // Its twin with a radius below Newton's step: on the boundary, σ > 0.
        let newton = y.norm();
        let (y, sigma) = check(a, g, 0.5 * newton);
        assert!((y.norm() - 0.5 * newton).abs() <= 1e-9 * newton && sigma > 0.0);
    }

    #[test]
    fn an_indefinite_model_steps_to_the_boundary_past_its_negative_curvature() {
        let a = DMatrix::from_row_slice(3, 3, &[1.0, 2.0, 0.0, 2.0, -1.0, 0.3, 0.0, 0.3, 5.0]);
        let g = DVector::from_row_slice(&[0.4, 0.1, -0.2]);
        let lowest = a.clone().symmetric_eigen().eigenvalues.min();
        let (y, sigma) = check(a, g, 0.7);
        assert!((y.norm() - 0.7).abs() <= 1e-9 && sigma >= -lowest);
    }

    #[test]
    fn the_hard_case_leaves_along_the_lowest_eigenvector() {
        // g has no part along e₁, the negative-curvature direction.
        let a = DMatrix::from_diagonal(&DVector::from_row_slice(&[-2.0, 1.0, 3.0]));
        let g = DVector::from_row_slice(&[0.0, 0.5, 0.3]);
        let (y, sigma) = check(a, g, 2.0);
        assert!((y.norm() - 2.0).abs() <= 1e-9 && (sigma - 2.0).abs() <= 1e-6);
        assert!(y[0].abs() > 1.0, "the step turns along e₁: {y}");
    }
}
