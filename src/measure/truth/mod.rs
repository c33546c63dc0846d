//! The truth runs are judged against: the reference solutions and the ensemble statistics of
//! chaotic scenes. They import only `base`.

pub mod reference;
pub mod statistics;
