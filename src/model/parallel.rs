//! Deterministic parallel evaluation of large spring sets.
//!
//! Owner computes: particles are split into fixed chunks of [`PARTICLE_CHUNK`], and each chunk
//! walks, in increasing spring index, the springs with an end among its particles, adding the
//! force to the ends it owns (a spring crossing two chunks is evaluated by both). Every particle
//! therefore receives exactly the additions the serial scatter loop `f[i] += fs; f[j] -= fs`
//! makes, in the same order, so the forces are bit-identical to the serial loop whatever the
//! thread count, and no per-spring buffer is written or gathered.
//! Dissipated power is summed per particle chunk (each spring counted by the chunk owning its
//! first end) and the chunk partials are added sequentially; elastic energy is summed per
//! fixed chunk of [`SPRING_CHUNK`] springs. Both sums depend on the scene only, never on the
//! thread count.
//!
//! Scratch storage: the chunk lists are built once per [`Springs`](super::Springs) (lazily, on
//! the first large evaluation) and the partial sums live in a [`ScratchPool`], a mutex-guarded
//! free list: each evaluation takes a buffer and returns it, so after the first evaluation
//! nothing is allocated, and systems shared by concurrent runs stay thread-safe.

use super::state::Vec3;
use std::sync::Mutex;

/// Spring count from which evaluation goes parallel. Depends only on the scene, never on the
/// thread count, so a scene always takes the same path and the same summation order.
pub const PARALLEL_MIN_SPRINGS: usize = 65_536;

/// Springs per chunk for the partial sums of elastic energy.
pub const SPRING_CHUNK: usize = 4096;

/// Particles per chunk in the owner-computes force loop.
pub const PARTICLE_CHUNK: usize = 2048;

/// Particle count from which per-particle loops (force fill, gravity, kick-drift) run in
/// parallel over fixed [`PARTICLE_CHUNK`]s; they have no reductions, so results do not depend
/// on the thread count.
pub const PARALLEL_MIN_PARTICLES: usize = 32_768;

/// Runs `op(p, &mut a[p])` for every particle `p`, in parallel over fixed chunks for large
/// systems (at least [`PARALLEL_MIN_PARTICLES`]).
#[inline(always)]
pub fn each_particle<T: Send>(a: &mut [T], op: impl Fn(usize, &mut T) + Sync) {
    use rayon::prelude::*;
    if a.len() < PARALLEL_MIN_PARTICLES {
        a.iter_mut().enumerate().for_each(|(p, t)| op(p, t));
    } else {
        a.par_chunks_mut(PARTICLE_CHUNK)
            .enumerate()
            .for_each(|(c, ch)| {
                let base = c * PARTICLE_CHUNK;
                ch.iter_mut().enumerate().for_each(|(k, t)| op(base + k, t));
            });
    }
}

/// Like [`each_particle`] over two arrays of equal length: `op(p, &mut a[p], &mut b[p])`.
#[inline(always)]
pub fn each_particle2<T: Send, U: Send>(
    a: &mut [T],
    b: &mut [U],
    op: impl Fn(usize, &mut T, &mut U) + Sync,
) {
    use rayon::prelude::*;
    assert_eq!(
        a.len(),
        b.len(),
        "each_particle2: arrays of different length"
    );
    if a.len() < PARALLEL_MIN_PARTICLES {
        for (p, (t, u)) in a.iter_mut().zip(b.iter_mut()).enumerate() {
            op(p, t, u);
        }
    } else {
        a.par_chunks_mut(PARTICLE_CHUNK)
            .zip(b.par_chunks_mut(PARTICLE_CHUNK))
            .enumerate()
            .for_each(|(c, (ca, cb))| {
                let base = c * PARTICLE_CHUNK;
                for (k, (t, u)) in ca.iter_mut().zip(cb.iter_mut()).enumerate() {
                    op(base + k, t, u);
                }
            });
    }
}

/// Runs `op(p, &mut a[p])` for every particle as [`each_particle`] does and returns the sum
/// of what it returns, added as [`dot`] adds its terms (in particle order, or per fixed chunk
/// with the chunk sums then added in order): an update and a dot product in one pass.
#[inline(always)]
pub fn each_particle_sum<T: Send>(
    a: &mut [T],
    parts: &mut Vec<f64>,
    op: impl Fn(usize, &mut T) -> f64 + Sync,
) -> f64 {
    // A second array of units: zero-sized, so it allocates nothing.
    let mut none = vec![(); a.len()];
    each_particle2_sum(a, &mut none, parts, |p, t, _| op(p, t))
}

/// Like [`each_particle_sum`] over two arrays of equal length.
#[inline(always)]
pub fn each_particle2_sum<T: Send, U: Send>(
    a: &mut [T],
    b: &mut [U],
    parts: &mut Vec<f64>,
    op: impl Fn(usize, &mut T, &mut U) -> f64 + Sync,
) -> f64 {
    // A third array of units (zero-sized: nothing allocated) and a second sum of −0.0 terms,
    // which leaves it −0.0 and the first sum exactly [`each_particle3_sum2`]'s.
    let mut none = vec![(); a.len()];
    each_particle3_sum2(a, b, &mut none, parts, |p, t, u, _| (op(p, t, u), -0.0)).0
}

/// Runs `op(p, &mut a[p], &mut b[p], &mut c[p])` for every particle of three arrays of equal
/// length and returns the sums of the two numbers it returns, each added as [`dot`] adds its
/// terms: an update and two dot products in one pass. `parts` holds twice the chunk sums.
#[inline(always)]
pub fn each_particle3_sum2<T: Send, U: Send, V: Send>(
    a: &mut [T],
    b: &mut [U],
    c: &mut [V],
    parts: &mut Vec<f64>,
    op: impl Fn(usize, &mut T, &mut U, &mut V) -> (f64, f64) + Sync,
) -> (f64, f64) {
    use rayon::prelude::*;
    assert!(
        a.len() == b.len() && a.len() == c.len(),
        "each_particle3_sum2: arrays of different length"
    );
    // The serial fold starts where `Iterator::sum` does, so that each sum is `dot`'s.
    let add = |(s, t): (f64, f64), (x, y): (f64, f64)| (s + x, t + y);
    let chunk = |base: usize, ca: &mut [T], cb: &mut [U], cc: &mut [V]| {
        ca.iter_mut()
            .zip(cb.iter_mut())
            .zip(cc.iter_mut())
            .enumerate()
            .map(|(k, ((t, u), v))| op(base + k, t, u, v))
            .fold((-0.0, -0.0), add)
    };
    if a.len() < PARALLEL_MIN_PARTICLES {
        chunk(0, a, b, c)
    } else {
        let chunks = a.len().div_ceil(PARTICLE_CHUNK);
        parts.resize(2 * chunks, 0.0);
        let (first, second) = parts.split_at_mut(chunks);
        first
            .par_iter_mut()
            .zip(second.par_iter_mut())
            .zip(
                a.par_chunks_mut(PARTICLE_CHUNK).zip(
                    b.par_chunks_mut(PARTICLE_CHUNK)
                        .zip(c.par_chunks_mut(PARTICLE_CHUNK)),
                ),
            )
            .enumerate()
            .for_each(|(k, ((p1, p2), (ca, (cb, cc))))| {
                (*p1, *p2) = chunk(k * PARTICLE_CHUNK, ca, cb, cc);
            });
        (sum_partials(first), sum_partials(second))
    }
}

/// Σ a[p]·b[p]: summed in particle order for small systems, and for large ones (at least
/// [`PARALLEL_MIN_PARTICLES`]) per fixed [`PARTICLE_CHUNK`] in parallel, the chunk sums then
/// added in order, so the result never depends on the thread count. `parts` is scratch for
/// the chunk sums (grown once, then reused).
pub fn dot(a: &[Vec3], b: &[Vec3], parts: &mut Vec<f64>) -> f64 {
    use rayon::prelude::*;
    if a.len() < PARALLEL_MIN_PARTICLES {
        a.iter().zip(b).map(|(x, y)| x.dot(y)).sum()
    } else {
        parts.resize(a.len().div_ceil(PARTICLE_CHUNK), 0.0);
        parts
            .par_iter_mut()
            .zip(
                a.par_chunks(PARTICLE_CHUNK)
                    .zip(b.par_chunks(PARTICLE_CHUNK)),
            )
            .for_each(|(part, (x, y))| *part = x.iter().zip(y).map(|(p, q)| p.dot(q)).sum());
        sum_partials(parts)
    }
}

/// Flag of a chunk-list entry: the chunk owns the spring's first end (it adds `+f`, and counts
/// the spring's dissipated power).
pub const OWNS_FIRST: u32 = 2;
/// Flag of a chunk-list entry: the chunk owns the spring's second end (it adds `-f`).
pub const OWNS_SECOND: u32 = 1;
/// Both flags: the spring lies inside the chunk.
pub const OWNS_BOTH: u32 = OWNS_FIRST | OWNS_SECOND;

/// The springs touching each particle chunk, in compressed sparse row form.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Incidence {
    /// Particle count the lists were built for.
    pub particles: usize,
    /// Spring count the lists were built for.
    pub springs: usize,
    /// `start[c]..start[c + 1]` indexes `entries` for particle chunk `c`.
    pub start: Vec<u32>,
    /// `spring << 2 | flags` ([`OWNS_FIRST`], [`OWNS_SECOND`]), in increasing spring order.
    pub entries: Vec<u32>,
}

impl Incidence {
    /// Builds the chunk lists for springs `i[s]`–`j[s]` over `n` particles. `None` when the
    /// sizes do not fit the 32-bit encoding or an index is out of range.
    pub fn build(i: &[u32], j: &[u32], n: usize) -> Option<Self> {
        Self::build_in_chunks(i, j, n, PARTICLE_CHUNK)
    }

    /// The same lists over chunks of `size` particles (`size` 1: the springs at each particle).
    pub fn build_in_chunks(i: &[u32], j: &[u32], n: usize, size: usize) -> Option<Self> {
        let m = i.len();
        if m >= (1 << 29) || n >= u32::MAX as usize {
            return None;
        }
        if i.iter().chain(j).any(|&p| p as usize >= n) {
            return None;
        }
        let chunks = n.div_ceil(size);
        let chunk = |p: u32| p as usize / size;
        let mut start = vec![0u32; chunks + 1];
        for s in 0..m {
            start[chunk(i[s]) + 1] += 1;
            if chunk(j[s]) != chunk(i[s]) {
                start[chunk(j[s]) + 1] += 1;
            }
        }
        for c in 0..chunks {
            start[c + 1] += start[c];
        }
        let mut fill: Vec<u32> = start[..chunks].to_vec();
        let mut entries = vec![0u32; start[chunks] as usize];
        for s in 0..m {
            let (a, b) = (chunk(i[s]), chunk(j[s]));
            let key = (s as u32) << 2;
            if a == b {
                entries[fill[a] as usize] = key | OWNS_BOTH;
                fill[a] += 1;
            } else {
                entries[fill[a] as usize] = key | OWNS_FIRST;
                fill[a] += 1;
                entries[fill[b] as usize] = key | OWNS_SECOND;
                fill[b] += 1;
            }
        }
        Some(Incidence {
            particles: n,
            springs: m,
            start,
            entries,
        })
    }

    /// Number of particle chunks.
    pub fn chunks(&self) -> usize {
        self.start.len() - 1
    }

    /// The entries of particle chunk `c`.
    pub fn chunk(&self, c: usize) -> &[u32] {
        &self.entries[self.start[c] as usize..self.start[c + 1] as usize]
    }
}

/// Reusable buffers for one parallel evaluation.
#[derive(Debug, Default)]
pub struct Scratch {
    /// One partial sum per chunk.
    pub partials: Vec<f64>,
}

impl Scratch {
    /// Sizes the partial sums for the larger of the force and energy chunk counts (so
    /// alternating force and energy evaluations never reallocate); returns them.
    pub fn fit(&mut self, chunks: usize, other: usize) -> &mut [f64] {
        self.partials.resize(chunks.max(other), 0.0);
        &mut self.partials
    }
}

/// A thread-safe free list of [`Scratch`] buffers: `take` one, use it, `give` it back.
/// Cloning gives an empty pool (scratch is never shared between copies).
#[derive(Debug, Default)]
pub struct ScratchPool(Mutex<Vec<Scratch>>);

impl Clone for ScratchPool {
    fn clone(&self) -> Self {
        ScratchPool::default()
    }
}

impl ScratchPool {
    /// A buffer from the pool, or a new empty one when all are in use.
    pub fn take(&self) -> Scratch {
        self.0
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .pop()
            .unwrap_or_default()
    }
    /// Returns a buffer to the pool.
    pub fn give(&self, s: Scratch) {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).push(s);
    }
}

/// Sequential sum of chunk partials, starting from +0.0 (the order the serial path uses).
pub fn sum_partials(p: &[f64]) -> f64 {
    let mut s = 0.0;
    for &x in p {
        s += x;
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Vec3;

    /// Oracle: [`dot`] itself. An update fused with its sum adds the same terms in the same
    /// order, below and above the parallel size: the same bits as the update followed by
    /// `dot`.
    #[test]
    fn a_fused_update_sums_as_dot_does() {
        for n in [1000, PARALLEL_MIN_PARTICLES + 3 * PARTICLE_CHUNK / 2] {
            let f = |p: usize| Vec3::new((p as f64 * 0.3).sin(), (p as f64).cos(), 1e-3 * p as f64);
            let (mut a, mut b): (Vec<Vec3>, Vec<Vec3>) =
                ((0..n).map(f).collect(), (0..n).map(|p| f(p + 7)).collect());
            let (a0, b0) = (a.clone(), b.clone());
            let mut parts = Vec::new();
            let fused = each_particle_sum(&mut a, &mut parts, |p, x| {
                *x *= 2.0;
                x.dot(&b0[p])
            });
            let twice: Vec<Vec3> = a0.iter().map(|x| x * 2.0).collect();
            assert_eq!(a, twice);
            assert_eq!(fused.to_bits(), dot(&twice, &b0, &mut parts).to_bits());
            let fused2 = each_particle2_sum(&mut a, &mut b, &mut parts, |_, x, y| {
                *y -= *x;
                x.dot(y)
            });
            let diff: Vec<Vec3> = b0.iter().zip(&twice).map(|(y, x)| y - x).collect();
            assert_eq!(b, diff);
            assert_eq!(fused2.to_bits(), dot(&twice, &diff, &mut parts).to_bits());
            let mut c = vec![Vec3::zeros(); n];
            let (s1, s2) = each_particle3_sum2(&mut a, &mut b, &mut c, &mut parts, |p, x, y, z| {
                *x += b0[p];
                *z = *y * 3.0;
                (x.dot(y), y.dot(z))
            });
            let sum: Vec<Vec3> = twice.iter().zip(&b0).map(|(x, y)| x + y).collect();
            let thrice: Vec<Vec3> = diff.iter().map(|y| y * 3.0).collect();
            assert_eq!((&a, &c), (&sum, &thrice));
            assert_eq!(s1.to_bits(), dot(&sum, &diff, &mut parts).to_bits());
            assert_eq!(s2.to_bits(), dot(&diff, &thrice, &mut parts).to_bits());
        }
    }

    #[test]
    fn chunk_lists_hold_each_spring_once_per_chunk_in_order() {
        let c = PARTICLE_CHUNK as u32;
        // Springs 0:(0,1) inside chunk 0; 1:(1,c) crossing; 2:(c+1,c) inside chunk 1.
        let inc = Incidence::build(&[0, 1, c + 1], &[1, c, c], 2 * PARTICLE_CHUNK).unwrap();
        assert_eq!(inc.start, vec![0, 2, 4]);
        assert_eq!(inc.chunk(0), &[OWNS_BOTH, 1 << 2 | OWNS_FIRST]);
        assert_eq!(inc.chunk(1), &[1 << 2 | OWNS_SECOND, 2 << 2 | OWNS_BOTH]);
        assert!(Incidence::build(&[0], &[3], 3).is_none());
    }

    /// An n×n grid of structural springs (k = 200·(n−1) N/m, rest 1/(n−1) m, damped) with a
    /// perturbed, moving state: every spring stretched or compressed and moving.
    fn grid(n: usize) -> (crate::model::Springs, Vec<Vec3>, Vec<Vec3>) {
        let mut springs = crate::model::Springs::default();
        let h = 1.0 / (n - 1) as f64;
        for r in 0..n {
            for c in 0..n {
                let p = r * n + c;
                if c + 1 < n {
                    springs.push(p, p + 1, 200.0 / h, h, 0.002);
                }
                if r + 1 < n {
                    springs.push(p, p + n, 200.0 / h, h, 0.002);
                }
            }
        }
        let (mut x, mut v) = (Vec::new(), Vec::new());
        for p in 0..n * n {
            let q = p as f64;
            let (r, c) = ((p / n) as f64, (p % n) as f64);
            x.push(
                Vec3::new(c * h, 0.0, r * h)
                    + Vec3::new((q * 0.37).sin(), (q * 0.11).cos(), (q * 0.23).sin()) * 1e-3,
            );
            v.push(Vec3::new(
                (q * 0.05).cos(),
                (q * 0.7).sin(),
                (q * 0.3).cos(),
            ));
        }
        (springs, x, v)
    }

    fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(f)
    }

    /// Oracle: the serial scatter loop (the definition of the force); the parallel path must
    /// reproduce it bit for bit, with 1, 2 and 3 threads, forces, power and energy alike.
    #[test]
    fn parallel_forces_are_bit_identical_to_serial_for_any_thread_count() {
        use crate::model::ForceTerm;
        let (springs, x, v) = grid(200);
        let n = x.len();
        assert!(springs.len() >= PARALLEL_MIN_SPRINGS);
        assert!(springs.is_parallel(n));
        // Serial reference: a copy below the threshold cannot exist, so call the serial kernel.
        let mut f_ref = vec![Vec3::new(0.5, -0.25, 1.0); n];
        let p_ref = springs.add_forces_serial::<true>(&x, &v, &mut f_ref);
        let e_ref: f64 = {
            let m = springs.len();
            let mut e = 0.0;
            let mut lo = 0;
            while lo < m {
                let hi = (lo + SPRING_CHUNK).min(m);
                e += springs.energy_range(&x, lo, hi);
                lo = hi;
            }
            e
        };
        assert!(p_ref > 0.0);
        for threads in [1, 2, 3] {
            let (f, p, e) = in_pool(threads, || {
                let mut f = vec![Vec3::new(0.5, -0.25, 1.0); n];
                let p = springs.add_forces(&x, &v, &mut f);
                (f, p, springs.potential_energy(&x))
            });
            // Power is summed per particle chunk, not per spring chunk: same terms, other
            // grouping, so equal to the serial sum to rounding and bit-equal across threads.
            assert!(
                (p - p_ref).abs() <= 1e-12 * p_ref,
                "power, {threads} threads"
            );
            let p1 = in_pool(1, || {
                let mut f = vec![Vec3::zeros(); n];
                springs.add_forces(&x, &v, &mut f)
            });
            assert_eq!(p.to_bits(), p1.to_bits(), "power, {threads} vs 1 thread");
            assert_eq!(e.to_bits(), e_ref.to_bits(), "energy, {threads} threads");
            for q in 0..n {
                for c in 0..3 {
                    assert_eq!(f[q][c].to_bits(), f_ref[q][c].to_bits(), "particle {q}");
                }
            }
        }
    }
}
