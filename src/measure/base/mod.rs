//! The building blocks every measurement uses: time grids, cost probes and budgets, the ODE
//! solver, kept solves, observables, bounce apexes and linearised modes. They import nothing
//! else of `measure`.

pub mod apexes;
pub(crate) mod dop853;
pub mod grid;
pub(crate) mod kept;
pub(crate) mod modes;
pub mod observables;
pub mod probe;
