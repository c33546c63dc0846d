//! Generators that expand `[[chain]]` and `[[cloth]]` blocks into particles and springs.

use super::file::{ChainSpec, ClothSpec};
use super::words::{ChainEnd, Corner, Plane};
use super::{Particle, SpringDef};
use crate::model::Vec3;

/// A generated block's particle index range and grid shape, kept for plots and snapshots.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Block {
    /// "chain" or "cloth".
    pub kind: &'static str,
    /// First particle index.
    pub first: usize,
    /// Grid shape: `[count, 1]` for chains, `[nx, ny]` for cloths (row-major, x fastest).
    pub shape: [usize; 2],
}

/// Appends a chain's particles and springs. `count`/`fix` are already validated.
pub fn chain(c: &ChainSpec, particles: &mut Vec<Particle>, springs: &mut Vec<SpringDef>) -> Block {
    let n = c.count as usize;
    let first = particles.len();
    let (a, b) = (Vec3::from(c.start), Vec3::from(c.end));
    for k in 0..n {
        let s = k as f64 / (n - 1) as f64;
        let fixed = (k == 0 && c.fixes(ChainEnd::First)) || (k == n - 1 && c.fixes(ChainEnd::Last));
        particles.push(Particle {
            position: a + (b - a) * s,
            velocity: Vec3::zeros(),
            mass: c.mass,
            fixed,
            radius: 0.0,
        });
    }
    for k in 0..n - 1 {
        springs.push(SpringDef::hooke(
            first + k,
            first + k + 1,
            c.stiffness,
            c.damping,
        ));
    }
    Block {
        kind: "chain",
        first,
        shape: [n, 1],
    }
}

/// Appends a cloth's particles and structural, shear and (optionally) bend springs.
pub fn cloth(c: &ClothSpec, particles: &mut Vec<Particle>, springs: &mut Vec<SpringDef>) -> Block {
    let (nx, ny) = (c.count[0] as usize, c.count[1] as usize);
    let first = particles.len();
    let o = Vec3::from(c.origin);
    let axis2 = match c.plane() {
        Plane::Xz => Vec3::z(),
        Plane::Xy => Vec3::y(),
    };
    let idx = |ix: usize, iy: usize| first + iy * nx + ix;
    for iy in 0..ny {
        for ix in 0..nx {
            let p = o
                + Vec3::x() * (c.size[0] * ix as f64 / (nx - 1) as f64)
                + axis2 * (c.size[1] * iy as f64 / (ny - 1) as f64);
            let corner = match (ix, iy) {
                (0, y) if y == ny - 1 => Some(Corner::TopLeft),
                (x, y) if x == nx - 1 && y == ny - 1 => Some(Corner::TopRight),
                (0, 0) => Some(Corner::BottomLeft),
                (x, 0) if x == nx - 1 => Some(Corner::BottomRight),
                _ => None,
            };
            let fixed = corner.is_some_and(|corner| c.fixes(corner));
            particles.push(Particle {
                position: p,
                velocity: Vec3::zeros(),
                mass: c.mass,
                fixed,
                radius: 0.0,
            });
        }
    }
    let mut add = |a: usize, b: usize, k: f64| springs.push(SpringDef::hooke(a, b, k, c.damping));
    for iy in 0..ny {
        for ix in 0..nx {
            if ix + 1 < nx {
                add(idx(ix, iy), idx(ix + 1, iy), c.stiffness);
            }
            if iy + 1 < ny {
                add(idx(ix, iy), idx(ix, iy + 1), c.stiffness);
            }
            if ix + 1 < nx && iy + 1 < ny {
                add(idx(ix, iy), idx(ix + 1, iy + 1), c.stiffness);
                add(idx(ix + 1, iy), idx(ix, iy + 1), c.stiffness);
            }
            if c.bend_stiffness > 0.0 {
                if ix + 2 < nx {
                    add(idx(ix, iy), idx(ix + 2, iy), c.bend_stiffness);
                }
                if iy + 2 < ny {
                    add(idx(ix, iy), idx(ix, iy + 2), c.bend_stiffness);
                }
            }
        }
    }
    Block {
        kind: "cloth",
        first,
        shape: [nx, ny],
    }
}
