//! The parallel Gauss–Seidel order for large scenes: a greedy colouring of the constraint
//! graph (links in index order, each given the smallest colour no earlier link at either of
//! its particles has). Links of one colour share no particle, so they are solved together:
//! first every link's correction from the same positions (in parallel, each link on its own),
//! then every particle applies the one correction of that colour that touches it (in parallel,
//! each particle on its own). Neither phase has a reduction or a write another task reads, so
//! the result depends on the scene only, never on the thread count; the sweep visits the
//! colours in order, a Gauss–Seidel sweep in colour order.
//!
//! Built once per scene (at the first step) and checked against the scene's topology at every
//! step by a fingerprint, so a stepper moved to another scene rebuilds it.

use super::link::{link, solve};
use crate::model::{System, Vec3};
use rayon::prelude::*;

/// No link of this colour touches the particle.
const NONE: u32 = u32::MAX;
/// Flag in a slot: the particle is the link's second end (it adds +w n Δλ).
const SECOND: u32 = 1 << 31;
/// Links per parallel task in the correction phase (any value gives the same bits).
const LINK_CHUNK: usize = 1024;

/// Links grouped by colour, and for each colour the link touching each particle.
#[derive(Debug, Default)]
pub(crate) struct Colouring {
    /// Link indices sorted by (colour, index).
    pub order: Vec<u32>,
    /// `order[start[c]..start[c + 1]]` are the links of colour `c`.
    pub start: Vec<usize>,
    /// `slot[c · n + p]`: position in `order` of the colour-`c` link at particle `p`
    /// ([`SECOND`] set when `p` is its second end), or [`NONE`].
    slot: Vec<u32>,
    /// Particles the colouring was built for.
    particles: usize,
    /// Fingerprint of the topology it was built for.
    fingerprint: u64,
}

/// A cheap fingerprint of a scene's link topology (counts and end indices).
fn fingerprint(sys: &System) -> u64 {
    let mut f = (sys.len() as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    for l in 0..super::link::count(sys) {
        let k = link(sys, l);
        f = (f ^ ((k.i as u64) << 32 | k.j as u64)).wrapping_mul(0x1000_0000_01B3);
    }
    f
}

impl Colouring {
    /// Rebuilds the colouring when `sys` is not the scene it was built for.
    pub fn fit(&mut self, sys: &System) {
        let f = fingerprint(sys);
        if self.particles == sys.len() && self.fingerprint == f && !self.start.is_empty() {
            return;
        }
        let n = sys.len();
        let m = super::link::count(sys);
        let mut used: Vec<Vec<u32>> = vec![Vec::new(); n];
        let mut colour = vec![0u32; m];
        let mut colours = 0;
        for (l, col) in colour.iter_mut().enumerate() {
            let k = link(sys, l);
            let mut c = 0;
            while used[k.i].contains(&c) || used[k.j].contains(&c) {
                c += 1;
            }
            used[k.i].push(c);
            used[k.j].push(c);
            *col = c;
            colours = colours.max(c as usize + 1);
        }
        let mut start = vec![0usize; colours + 1];
        for &c in &colour {
            start[c as usize + 1] += 1;
        }
        for c in 0..colours {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut order = vec![0u32; m];
        let mut slot = vec![NONE; colours * n];
        for (l, &c) in colour.iter().enumerate() {
            let pos = fill[c as usize];
            fill[c as usize] += 1;
            order[pos] = l as u32;
            let k = link(sys, l);
            slot[c as usize * n + k.i] = pos as u32;
            slot[c as usize * n + k.j] = pos as u32 | SECOND;
        }
        *self = Colouring {
            order,
            start,
            slot,
            particles: n,
            fingerprint: f,
        };
    }

    /// Number of colours.
    pub fn colours(&self) -> usize {
        self.start.len().saturating_sub(1)
    }

    /// One Gauss–Seidel sweep in colour order. `lambda` and `corr` are indexed like `order`.
    pub fn sweep(
        &self,
        sys: &System,
        x: &mut [Vec3],
        x0: &[Vec3],
        h: f64,
        lambda: &mut [f64],
        corr: &mut [Vec3],
    ) {
        let n = self.particles;
        for c in 0..self.colours() {
            let (lo, hi) = (self.start[c], self.start[c + 1]);
            {
                let xr: &[Vec3] = x;
                self.order[lo..hi]
                    .par_chunks(LINK_CHUNK)
                    .zip(lambda[lo..hi].par_chunks_mut(LINK_CHUNK))
                    .zip(corr[lo..hi].par_chunks_mut(LINK_CHUNK))
                    .for_each(|((ls, lam), cs)| {
                        for ((&l, lm), cr) in ls.iter().zip(lam.iter_mut()).zip(cs.iter_mut()) {
                            let k = link(sys, l as usize);
                            *cr =
                                solve(&k, &sys.inv_mass, xr, x0, h, lm).unwrap_or_else(Vec3::zeros);
                        }
                    });
            }
            let slots = &self.slot[c * n..(c + 1) * n];
            let corr: &[Vec3] = corr;
            crate::model::parallel::each_particle(x, |p, xp| {
                let s = slots[p];
                if s != NONE {
                    let g = corr[(s & !SECOND) as usize] * sys.inv_mass[p];
                    if s & SECOND != 0 {
                        *xp += g;
                    } else {
                        *xp -= g;
                    }
                }
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Oracle: the definition of a colouring — no two links of one colour share a particle,
    /// and every link appears exactly once.
    #[test]
    fn links_of_one_colour_share_no_particle() {
        let scene = crate::perf::cloth(12);
        let sys = scene.build();
        let mut col = Colouring::default();
        col.fit(&sys);
        let m = super::super::link::count(&sys);
        let mut seen = vec![false; m];
        for c in 0..col.colours() {
            let mut touched = vec![false; sys.len()];
            for &l in &col.order[col.start[c]..col.start[c + 1]] {
                let k = link(&sys, l as usize);
                assert!(!touched[k.i] && !touched[k.j], "colour {c}");
                touched[k.i] = true;
                touched[k.j] = true;
                assert!(!seen[l as usize]);
                seen[l as usize] = true;
            }
        }
        assert!(seen.iter().all(|&s| s));
        assert!(
            col.colours() >= 4 && col.colours() <= 16,
            "{}",
            col.colours()
        );
    }
}
