//! Serde types of the `[[obstacle]]` and `[collision]` tables. One flat table per
//! obstacle: `shape` says which keys apply, and validation rejects keys of other shapes.

use serde::{Deserialize, Serialize};

/// `[[obstacle]]`: one static obstacle.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ObstacleSpec {
    /// `plane`, `sphere`, `box`, `capsule` or `mesh`.
    pub shape: String,
    /// plane: a point on the plane.
    pub point: Option<[f64; 3]>,
    /// plane: outward normal (any non-zero length).
    pub normal: Option<[f64; 3]>,
    /// sphere, box: centre.
    pub center: Option<[f64; 3]>,
    /// sphere, capsule: radius (m, > 0).
    pub radius: Option<f64>,
    /// box: half side lengths (m, each > 0).
    pub half_extents: Option<[f64; 3]>,
    /// box: orientation as an axis-angle vector (rad; default none).
    pub rotation: Option<[f64; 3]>,
    /// capsule: first end of the axis.
    pub a: Option<[f64; 3]>,
    /// capsule: second end of the axis.
    pub b: Option<[f64; 3]>,
    /// mesh: OBJ file, relative to the scene file (exclusive with vertices + triangles).
    pub file: Option<String>,
    /// mesh: inline vertex positions.
    pub vertices: Option<Vec<[f64; 3]>>,
    /// mesh: inline triangles (0-based vertex indices, counter-clockwise seen from outside).
    pub triangles: Option<Vec<[i64; 3]>>,
    /// Coefficient of restitution in [0, 1] (default 0).
    pub restitution: Option<f64>,
    /// Coulomb friction coefficient ≥ 0 (default 0).
    pub friction: Option<f64>,
}

/// `[collision]`: how contacts with obstacles are resolved.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CollisionSpec {
    /// `impulse` (default), `penalty` or `projection`.
    pub response: Option<String>,
    /// penalty: contact spring stiffness (N/m, required for penalty).
    pub stiffness: Option<f64>,
    /// penalty: dashpot coefficient (N·s/m); exclusive with `restitution`.
    pub damping: Option<f64>,
    /// penalty: restitution the dashpot is tuned for (damping ratio derived per particle
    /// mass); without `damping` or `restitution`, each obstacle's restitution is used.
    pub restitution: Option<f64>,
}
