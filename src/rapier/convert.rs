//! Conversions between the model's nalgebra vectors and Rapier's glam types (Rapier 0.36's
//! public API is glam-based; keeping the conversion in one place keeps the rest type-safe).

use crate::model::Vec3;
use rapier3d_f64::math::Vector;

/// nalgebra → glam.
pub fn to_glam(v: &Vec3) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

/// glam → nalgebra.
pub fn to_na(v: Vector) -> Vec3 {
    Vec3::new(v.x, v.y, v.z)
}
