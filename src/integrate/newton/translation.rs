//! Whether a system is invariant under a uniform velocity shift: the condition under which
//! the stage's momentum balance can be zeroed exactly (see `momentum`) and CG deflated of the
//! rigid translations.

use crate::model::System;

/// True when a uniform velocity shift leaves every force of `sys` unchanged: all particles
/// free, no drag, and no force term but springs and gravity (the scene builder adds a term
/// for gravity, drag and penalty contacts only; a hand-built system with other terms is
/// treated as not invariant unless it has exactly one term, gravity's).
pub(super) fn translation_invariant(sys: &System) -> bool {
    sys.free.iter().all(|&f| f)
        && sys.drag.is_none()
        && match sys.terms.as_slice() {
            [] => true,
            [only] => sys.gravity.is_some() && only.kind() == crate::model::TermKind::Gravity,
            _ => false,
        }
}
