//! The best exact loop for the benchmark cloth: one symplectic Euler step of a grid cloth's
//! structural and shear springs written as a stencil. The state is split by coordinate
//! (structure of arrays), each spring family (horizontal, vertical, two diagonals) is read with
//! unit stride row by row, its forces are computed into row buffers (a loop without scatter,
//! which the compiler vectorises) and then added to both ends. The force of each spring is the
//! same expression as [`super::hand_step`]'s; only the order in which a particle's forces are
//! summed differs, so the two agree to rounding. It is what springlab's general spring pass is
//! measured against in `bench-ratios` (`step_vs_best_loop`).

use crate::model::{System, Vec3};
use std::collections::HashMap;

/// One spring family of a grid: the index offset from a spring's first particle to its second,
/// the columns its first particles span in each row, and the rows it spans.
#[derive(Debug, Clone, Copy)]
struct Family {
    offset: usize,
    columns: (usize, usize),
    rows: usize,
}

/// A grid cloth in structure-of-arrays form with its springs' constants per family.
#[derive(Debug, Clone)]
pub struct GridCloth {
    nx: usize,
    x: [Vec<f64>; 3],
    v: [Vec<f64>; 3],
    f: [Vec<f64>; 3],
    /// Gravity times mass for free particles, 0 for fixed ones.
    weight: [Vec<f64>; 3],
    inv_mass: Vec<f64>,
    families: Vec<(Family, Vec<[f64; 3]>)>,
    buf: [Vec<f64>; 3],
}

impl GridCloth {
    /// The stencil form of `sys` when it is exactly an `nx`×`ny` grid cloth (particle
    /// `iy·nx + ix`) with structural and shear springs and nothing else; `None` otherwise.
    pub fn of(sys: &System, nx: usize, ny: usize) -> Option<Self> {
        let n = sys.len();
        // Springs and gravity only: no drag, rods, kicks, contact stage or other force term.
        let only_gravity = sys
            .terms
            .iter()
            .all(|t| t.kind() == crate::model::TermKind::Gravity);
        if nx < 2
            || ny < 2
            || nx.checked_mul(ny) != Some(n)
            || sys.drag.is_some()
            || !sys.constraints.is_empty()
            || !sys.impulses.is_empty()
            || sys.post_step.is_some()
            || !only_gravity
        {
            return None;
        }
        let sp = &sys.springs;
        let index: HashMap<(usize, usize), usize> = (0..sp.len())
            .map(|s| ((sp.i[s] as usize, sp.j[s] as usize), s))
            .collect();
        let families = [
            Family {
                offset: 1,
                columns: (0, nx - 1),
                rows: ny,
            },
            Family {
                offset: nx,
                columns: (0, nx),
                rows: ny - 1,
            },
            Family {
                offset: nx + 1,
                columns: (0, nx - 1),
                rows: ny - 1,
            },
            Family {
                offset: nx - 1,
                columns: (1, nx),
                rows: ny - 1,
            },
        ];
        let mut found = 0;
        let mut per_family = Vec::new();
        for fam in families {
            let mut consts = Vec::new();
            for iy in 0..fam.rows {
                for ix in fam.columns.0..fam.columns.1 {
                    let p = iy * nx + ix;
                    let s = *index.get(&(p, p + fam.offset))?;
                    consts.push([sp.k[s], sp.l0[s], sp.c[s]]);
                    found += 1;
                }
            }
            per_family.push((fam, consts));
        }
        if found != sp.len() {
            return None;
        }
        let g = sys.gravity.unwrap_or_else(Vec3::zeros);
        let split = |a: &[Vec3]| -> [Vec<f64>; 3] {
            std::array::from_fn(|k| a.iter().map(|p| p[k]).collect())
        };
        let weight = std::array::from_fn(|k| {
            (0..n)
                .map(|p| if sys.free[p] { g[k] * sys.mass[p] } else { 0.0 })
                .collect()
        });
        Some(GridCloth {
            nx,
            x: split(&vec![Vec3::zeros(); n]),
            v: split(&vec![Vec3::zeros(); n]),
            f: split(&vec![Vec3::zeros(); n]),
            weight,
            inv_mass: sys.inv_mass.clone(),
            families: per_family,
            buf: std::array::from_fn(|_| vec![0.0; nx]),
        })
    }

    /// Sets the state from positions `x` and velocities `v`.
    pub fn set_state(&mut self, x: &[Vec3], v: &[Vec3]) {
        for k in 0..3 {
            for p in 0..x.len() {
                self.x[k][p] = x[p][k];
                self.v[k][p] = v[p][k];
            }
        }
    }

    /// Position of particle `p`.
    pub fn position(&self, p: usize) -> Vec3 {
        Vec3::new(self.x[0][p], self.x[1][p], self.x[2][p])
    }

    /// Velocity of particle `p`.
    pub fn velocity(&self, p: usize) -> Vec3 {
        Vec3::new(self.v[0][p], self.v[1][p], self.v[2][p])
    }

    /// One symplectic Euler step of `h`: forces, then kick and drift.
    pub fn step(&mut self, h: f64) {
        for k in 0..3 {
            self.f[k].copy_from_slice(&self.weight[k]);
        }
        for (fam, consts) in &self.families {
            let width = fam.columns.1 - fam.columns.0;
            for iy in 0..fam.rows {
                let start = iy * self.nx + fam.columns.0;
                let row = &consts[iy * width..(iy + 1) * width];
                spring_row(&self.x, &self.v, start, fam.offset, row, &mut self.buf);
                for k in 0..3 {
                    let (fk, bk) = (&mut self.f[k], &self.buf[k][..width]);
                    for (j, b) in bk.iter().enumerate() {
                        fk[start + j] += b;
                    }
                    for (j, b) in bk.iter().enumerate() {
                        fk[start + fam.offset + j] -= b;
                    }
                }
            }
        }
        for k in 0..3 {
            let (x, v, f) = (&mut self.x[k], &mut self.v[k], &self.f[k]);
            for p in 0..x.len() {
                v[p] += f[p] * (self.inv_mass[p] * h);
                x[p] += v[p] * h;
            }
        }
    }
}

/// The forces of one row of springs from particles `start + j` to `start + offset + j`, into
/// `out` (one entry per spring and coordinate): no scatter, so the loop vectorises.
fn spring_row(
    x: &[Vec<f64>; 3],
    v: &[Vec<f64>; 3],
    start: usize,
    offset: usize,
    consts: &[[f64; 3]],
    out: &mut [Vec<f64>; 3],
) {
    let w = consts.len();
    let (a, b) = (start..start + w, start + offset..start + offset + w);
    let (xa, ya, za) = (&x[0][a.clone()], &x[1][a.clone()], &x[2][a.clone()]);
    let (xb, yb, zb) = (&x[0][b.clone()], &x[1][b.clone()], &x[2][b.clone()]);
    let (ua, va, wa) = (&v[0][a.clone()], &v[1][a.clone()], &v[2][a]);
    let (ub, vb, wb) = (&v[0][b.clone()], &v[1][b.clone()], &v[2][b]);
    let [ox, oy, oz] = out;
    for j in 0..w {
        let (dx, dy, dz) = (xb[j] - xa[j], yb[j] - ya[j], zb[j] - za[j]);
        let len = (dx * dx + dy * dy + dz * dz).sqrt();
        let (nx, ny, nz) = (dx / len, dy / len, dz / len);
        let vrel = (ub[j] - ua[j]) * nx + (vb[j] - va[j]) * ny + (wb[j] - wa[j]) * nz;
        let [k, l0, c] = consts[j];
        let m = k * (len - l0) + c * vrel;
        ox[j] = nx * m;
        oy[j] = ny * m;
        oz[j] = nz * m;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::{Stepper, SymplecticEuler};

    /// Oracle: springlab's symplectic Euler on the same cloth; the stencil does the same
    /// physics, to rounding (each spring's force is the same expression, summed in another
    /// order).
    #[test]
    fn stencil_steps_like_symplectic_euler() {
        let scene = crate::perf::cloth(12);
        let sys = scene.build();
        let mut s = scene.initial_state();
        let mut g = GridCloth::of(&sys, 12, 12).expect("a grid cloth");
        g.set_state(&s.x, &s.v);
        let mut se = SymplecticEuler::default();
        for _ in 0..50 {
            se.step(&sys, &mut s, 1e-3).unwrap();
            g.step(1e-3);
        }
        for p in 0..sys.len() {
            assert!((s.x[p] - g.position(p)).amax() < 1e-12, "particle {p}");
            assert!((s.v[p] - g.velocity(p)).amax() < 1e-9, "particle {p}");
        }
    }

    /// The twin: a scene that is not exactly the grid (another shape, one spring more, a kick,
    /// a rod) has no stencil form.
    #[test]
    fn a_scene_off_the_grid_has_no_stencil_form() {
        let scene = crate::perf::cloth(6);
        assert!(GridCloth::of(&scene.build(), 6, 6).is_some());
        assert!(GridCloth::of(&scene.build(), 4, 9).is_none());
        let mut more = scene.build();
        more.springs.push(0, 35, 1.0, 1.0, 0.0);
        assert!(GridCloth::of(&more, 6, 6).is_none());
        let mut kicked = scene.build();
        kicked.impulses.push(crate::model::Impulse {
            time: 0.1,
            particle: 3,
            delta_v: Vec3::x(),
        });
        assert!(GridCloth::of(&kicked, 6, 6).is_none());
        let mut rod = scene.build();
        rod.constraints.push(crate::model::DistanceConstraint {
            i: 0,
            j: 7,
            length: 0.3,
            compliance: 0.0,
        });
        assert!(GridCloth::of(&rod, 6, 6).is_none());
    }
}
