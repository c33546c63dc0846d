//! Sparse Cholesky factorisation of the Newton matrix A = M − h ∂f/∂v − h² ∂f/∂x, with faer's
//! supernodal/simplicial LLᵀ under an approximate-minimum-degree (AMD) fill-reducing ordering
//! (Amestoy, Davis & Duff, SIAM J. Matrix Anal. Appl. 17, 1996).
//!
//! The 3×3 blocks of [`Jacobian`] are expanded into the lower triangle of a compressed-column
//! matrix over the free particles' coordinates (a fixed particle keeps an identity block and
//! no coupling, so its update is zero, as in CG). The pattern, the AMD ordering and the
//! symbolic factorisation depend on the spring topology only: they are built once per
//! topology, and each refactorisation is numeric only, into storage sized once, so a step
//! does not allocate. faer runs sequentially here (`Par::Seq`): the factor and every solve
//! give the same bits whatever the thread count.

use super::pattern::{couples, neighbours, Topology};
use crate::model::{Jacobian, Vec3};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky,
    SymmetricOrdering,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side, Spec};
use nalgebra::Matrix3;

/// A sparse LLᵀ factor of the Newton matrix with its pattern, ordering and workspace.
#[derive(Default)]
pub(super) struct Factor {
    topo: Topology,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
    /// Per pair: (first column of its lower end, position of the upper end's block among the
    /// lower end's neighbours), or `u32::MAX` when an end is fixed (no coupling).
    pair_slot: Vec<(u32, u32)>,
    symbolic: Option<SymbolicCholesky<usize>>,
    l_values: Vec<f64>,
    mem: Option<MemBuffer>,
    rhs: Vec<f64>,
    diag: Vec<Matrix3<f64>>,
    /// Whether `l_values` holds the factor of the last assembled matrix.
    factored: bool,
}

impl std::fmt::Debug for Factor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Factor")
            .field("dofs", &(self.col_ptr.len().saturating_sub(1)))
            .field("nnz_a", &self.row_idx.len())
            .field("nnz_l", &self.l_values.len())
            .field("factored", &self.factored)
            .finish()
    }
}

/// The matrix was not numerically positive definite (LLᵀ met a non-positive pivot).
#[derive(Debug, Clone, Copy)]
pub(super) struct NotPositiveDefinite;

impl Factor {
    /// Whether a factor of the last assembled matrix is ready for [`Factor::solve`].
    pub(super) fn is_factored(&self) -> bool {
        self.factored
    }

    /// Marks the factor stale (a new step, a new matrix).
    pub(super) fn invalidate(&mut self) {
        self.factored = false;
    }

    /// Builds the pattern and the symbolic factorisation when the topology differs from the
    /// last one (only then does it allocate).
    fn ensure_pattern(&mut self, jac: &Jacobian, free: &[bool]) {
        if self.symbolic.is_some() && self.topo.is(jac, free) {
            return;
        }
        let n = free.len();
        self.topo = Topology::of(jac, free);
        // Neighbours q > p of each free particle p: the rows of column p's lower blocks.
        let nbr = neighbours(jac, free, true);
        self.col_ptr.clear();
        self.row_idx.clear();
        self.col_ptr.push(0);
        for p in 0..n {
            for c in 0..3 {
                for r in c..3 {
                    self.row_idx.push(3 * p + r);
                }
                for &q in &nbr[p] {
                    for r in 0..3 {
                        self.row_idx.push(3 * q as usize + r);
                    }
                }
                self.col_ptr.push(self.row_idx.len());
            }
        }
        self.pair_slot = jac
            .pairs
            .iter()
            .map(|&[a, b]| {
                if !couples(free, a, b) {
                    return (u32::MAX, u32::MAX);
                }
                let (lo, hi) = (a.min(b), a.max(b));
                let k = nbr[lo as usize].binary_search(&hi).expect("listed") as u32;
                (lo, k)
            })
            .collect();
        self.values = vec![0.0; self.row_idx.len()];
        let dim = 3 * n;
        let sym =
            SymbolicSparseColMatRef::new_checked(dim, dim, &self.col_ptr, None, &self.row_idx);
        let symbolic = factorize_symbolic_cholesky(
            sym,
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .expect("symbolic Cholesky of a valid pattern");
        self.l_values = vec![0.0; symbolic.len_val()];
        let req = StackReq::any_of(&[
            symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Spec::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        self.mem = Some(MemBuffer::new(req));
        self.symbolic = Some(symbolic);
        self.rhs = vec![0.0; dim];
        self.diag = vec![Matrix3::zeros(); n];
        self.factored = false;
    }

    /// Assembles the Newton matrix prepared in `jac` (see [`Jacobian::prepare_newton`]) and
    /// factors it. `Err` when it is not positive definite.
    pub(super) fn factor(
        &mut self,
        jac: &Jacobian,
        free: &[bool],
    ) -> Result<(), NotPositiveDefinite> {
        self.ensure_pattern(jac, free);
        self.factored = false;
        jac.newton_diagonal(free, &mut self.diag);
        let (pair_blocks, _) = jac.newton_blocks();
        let (cp, v) = (&self.col_ptr, &mut self.values);
        v.iter_mut().for_each(|x| *x = 0.0);
        for (p, d) in self.diag.iter().enumerate() {
            let d = if free[p] { *d } else { Matrix3::identity() };
            for c in 0..3 {
                for r in c..3 {
                    v[cp[3 * p + c] + r - c] += d[(r, c)];
                }
            }
        }
        for (s, &(lo, k)) in self.pair_slot.iter().enumerate() {
            if lo == u32::MAX {
                continue;
            }
            let (lo, k) = (lo as usize, k as usize);
            let b = pair_blocks[s].full();
            for c in 0..3 {
                let at = cp[3 * lo + c] + (3 - c) + 3 * k;
                for r in 0..3 {
                    v[at + r] -= b[(r, c)];
                }
            }
        }
        let symbolic = self.symbolic.as_ref().expect("pattern built");
        let dim = self.rhs.len();
        let a = SparseColMatRef::new(
            SymbolicSparseColMatRef::new_checked(dim, dim, &self.col_ptr, None, &self.row_idx),
            &self.values,
        );
        let stack = MemStack::new(self.mem.as_mut().expect("workspace sized"));
        symbolic
            .factorize_numeric_llt(
                &mut self.l_values,
                a,
                Side::Lower,
                LltRegularization::default(),
                Par::Seq,
                stack,
                Spec::default(),
            )
            .map_err(|_| NotPositiveDefinite)?;
        self.factored = true;
        Ok(())
    }

    /// x = A⁻¹ b with the last factor (fixed particles' rows of `b` are ignored: zero in x).
    pub(super) fn solve(&mut self, free: &[bool], b: &[Vec3], x: &mut [Vec3]) {
        debug_assert!(self.factored);
        for (p, bp) in b.iter().enumerate() {
            for c in 0..3 {
                self.rhs[3 * p + c] = if free[p] { bp[c] } else { 0.0 };
            }
        }
        let symbolic = self.symbolic.as_ref().expect("pattern built");
        let dim = self.rhs.len();
        let stack = MemStack::new(self.mem.as_mut().expect("workspace sized"));
        LltRef::new(symbolic, &self.l_values).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut self.rhs, dim, 1),
            Par::Seq,
            stack,
        );
        for (p, xp) in x.iter_mut().enumerate() {
            *xp = if free[p] {
                Vec3::new(self.rhs[3 * p], self.rhs[3 * p + 1], self.rhs[3 * p + 2])
            } else {
                Vec3::zeros()
            };
        }
    }
}

#[cfg(test)]
mod tests {
    //! Oracle: nalgebra's dense Cholesky of the same Newton matrix, built column by column
    //! from the matrix-free product [`Jacobian::newton_matvec`] that CG uses.
    use super::*;

    #[test]
    fn sparse_factor_solves_the_newton_matrix_like_a_dense_cholesky() {
        // The crumpled 5×5 cloth of CG's tests (compressed springs), clamped: the SPD
        // (projected) matrix the factor is built for, and its dense form.
        let h = 1.0 / 60.0;
        let (sys, mut jac, dense, dofs) = super::super::cg::tests::crumpled(h, 1.0);
        let n = sys.len();
        let chol = dense
            .clone()
            .cholesky()
            .expect("clamped Newton matrix is SPD");
        let b: Vec<Vec3> = (0..n)
            .map(|p| {
                Vec3::new(
                    (p as f64).sin(),
                    (p as f64 * 0.7).cos(),
                    0.3 - p as f64 * 0.01,
                )
            })
            .collect();
        let bd = super::super::cg::tests::flat(&b, &dofs);
        let want = chol.solve(&bd);
        let mut f = Factor::default();
        f.factor(&jac, &sys.free).expect("SPD");
        let mut x = vec![Vec3::zeros(); n];
        f.solve(&sys.free, &b, &mut x);
        let scale = want.amax();
        for (i, &d) in dofs.iter().enumerate() {
            assert!(
                (x[d / 3][d % 3] - want[i]).abs() <= 1e-12 * scale,
                "dof {d}: {} vs {}",
                x[d / 3][d % 3],
                want[i]
            );
        }
        for p in (0..n).filter(|&p| !sys.free[p]) {
            assert_eq!(x[p], Vec3::zeros(), "a fixed particle does not move");
        }
        // Refactoring the same pattern with new values reuses the symbolic analysis.
        jac.prepare_newton(&sys.mass, &sys.free, 2.0 * h);
        f.factor(&jac, &sys.free).expect("SPD");
        f.solve(&sys.free, &b, &mut x);
        let mut ax = vec![Vec3::zeros(); n];
        jac.newton_matvec(&sys.free, &x, &mut ax);
        for p in (0..n).filter(|&p| sys.free[p]) {
            assert!(
                (ax[p] - b[p]).amax() <= 1e-10 * b[p].amax().max(1.0),
                "A x = b at {p}"
            );
        }
    }

    #[test]
    fn an_indefinite_matrix_is_reported_not_factored() {
        // One free particle between two fixed ones on a compressed spring pair, exact
        // Jacobian, with a huge step: the negative transverse stiffness outweighs the mass.
        let scene = crate::scenario::Scenario::from_toml_str(
            "[[particle]]\nposition=[0.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
             [[particle]]\nposition=[0.5,0.0,0.0]\nmass=0.001\n\
             [[particle]]\nposition=[1.0,0.0,0.0]\nmass=1.0\nfixed=true\n\
             [[spring]]\nbetween=[0,1]\nstiffness=1000.0\nrest_length=1.0\n\
             [[spring]]\nbetween=[1,2]\nstiffness=1000.0\nrest_length=1.0\n",
            "p.toml",
        )
        .unwrap();
        let sys = scene.build();
        let s = scene.initial_state();
        let mut jac = sys.new_jacobian();
        sys.jacobian(&s.x, &s.v, &mut jac);
        jac.prepare_newton(&sys.mass, &sys.free, 1.0);
        let mut f = Factor::default();
        assert!(f.factor(&jac, &sys.free).is_err());
        assert!(!f.is_factored());
    }
}
