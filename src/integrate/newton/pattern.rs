//! The block sparsity pattern of the Newton matrix that the factorisations share (IC(0) and
//! the sparse Cholesky): which particles a spring couples, and the topology a pattern was
//! built for, so that each factorisation rebuilds its symbolic structure only when the
//! springs or the fixed particles change.

use crate::model::Jacobian;

/// The topology a pattern was built for: free mask and spring pairs.
#[derive(Debug, Default, PartialEq)]
pub(super) struct Topology {
    free: Vec<bool>,
    pairs: Vec<[u32; 2]>,
}

impl Topology {
    /// Whether `jac`'s pairs and `free` are the ones recorded.
    pub(super) fn is(&self, jac: &Jacobian, free: &[bool]) -> bool {
        self.free == free && self.pairs == jac.pairs
    }

    /// The topology of `jac` and `free`.
    pub(super) fn of(jac: &Jacobian, free: &[bool]) -> Self {
        Topology {
            free: free.to_vec(),
            pairs: jac.pairs.clone(),
        }
    }
}

/// Whether a spring between `a` and `b` couples two unknowns: distinct particles, both free
/// (a fixed particle keeps an identity block and no coupling, as in CG).
pub(super) fn couples(free: &[bool], a: u32, b: u32) -> bool {
    a != b && free[a as usize] && free[b as usize]
}

/// For each particle, the particles coupled to it on one side of it in the natural order,
/// sorted and unique: those of higher index (`higher`: the columns of the upper triangle's
/// row, i.e. the rows of the lower triangle's column) or of lower index (the lower triangle's
/// row).
pub(super) fn neighbours(jac: &Jacobian, free: &[bool], higher: bool) -> Vec<Vec<u32>> {
    let mut out: Vec<Vec<u32>> = vec![Vec::new(); free.len()];
    for &[a, b] in &jac.pairs {
        if couples(free, a, b) {
            let (lo, hi) = (a.min(b), a.max(b));
            if higher {
                out[lo as usize].push(hi);
            } else {
                out[hi as usize].push(lo);
            }
        }
    }
    for l in &mut out {
        l.sort_unstable();
        l.dedup();
    }
    out
}
