//! The dynamic state of a particle system: flat arrays of positions and velocities.

use nalgebra::Vector3;

/// A 3-vector of f64, the one vector type of the model.
pub type Vec3 = Vector3<f64>;

/// Time, positions and velocities of every particle (fixed ones included, never moved).
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    /// Simulated time in s.
    pub t: f64,
    /// Positions in m, one per particle.
    pub x: Vec<Vec3>,
    /// Velocities in m/s, one per particle.
    pub v: Vec<Vec3>,
}

impl State {
    /// Number of particles.
    pub fn len(&self) -> usize {
        self.x.len()
    }
    /// True when there are no particles.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }
    /// Index of the first particle with a non-finite position or velocity, if any.
    pub fn first_non_finite(&self) -> Option<usize> {
        (0..self.x.len()).find(|&i| {
            !(self.x[i].iter().all(|c| c.is_finite()) && self.v[i].iter().all(|c| c.is_finite()))
        })
    }
}
