//! One function per chart, each taking plain data from [`super::data`] and returning an SVG
//! document as a string (plotters' SVG backend: text as `<text>` elements, no font files).

pub mod collision;
pub mod common;
pub mod convergence;
pub mod energy;
pub mod energy_error;
pub mod impacts;
pub mod paths;
pub mod position_error;
pub mod snapshots;
pub mod work_precision;

pub use collision::collision;
pub use convergence::convergence;
pub use energy::energy;
pub use energy_error::energy_error;
pub use impacts::impacts;
pub use paths::paths;
pub use position_error::position_error;
pub use snapshots::snapshots;
pub use work_precision::work_precision;
