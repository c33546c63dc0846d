//! What every measuring command shares: a case (one method run against the reference), the
//! tolerance decided once up front, the shared settings and the recorded command. They
//! import `base`, `truth` and `observe`; the commands, in `measure` itself, import them.

pub mod case;
pub mod command;
pub mod common;
pub mod tolerance;
