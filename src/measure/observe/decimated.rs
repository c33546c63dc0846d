//! A bounded record of a run's per-step samples: every sample while they fit, then every
//! second, fourth, … one, so a run of any length keeps at most a fixed number.
//!
//! Why: the per-step records a measured run keeps (its energy error for the drift fit, a
//! particle's height over an obstacle) grew with the step count, and a run of billions of steps
//! exhausted memory. Runs that fit keep every sample, so their numbers are unchanged.

/// Most samples a [`Decimated`] record keeps by default (16 MiB of `[f64; 2]`): more than any
/// run of the shipped scenes' studies records, so their numbers are kept bit for bit.
pub const MAX_KEPT: usize = 1 << 20;

/// Samples pushed one at a time, kept at a stride that doubles whenever the record is full:
/// the samples kept are those whose push index is a multiple of [`Decimated::stride`].
#[derive(Debug, Clone)]
pub struct Decimated<T> {
    kept: Vec<T>,
    cap: usize,
    stride: u64,
    pushed: u64,
}

impl<T: Copy> Decimated<T> {
    /// An empty record keeping at most `cap` samples (at least 2).
    pub fn new(cap: usize) -> Self {
        Decimated {
            kept: Vec::new(),
            cap: cap.max(2),
            stride: 1,
            pushed: 0,
        }
    }

    /// Records `x`, the next sample: kept when its index is a multiple of the stride; when the
    /// record is full, every second kept sample is dropped first and the stride doubles.
    pub fn push(&mut self, x: T) {
        let i = self.pushed;
        self.pushed += 1;
        if i % self.stride != 0 {
            return;
        }
        if self.kept.len() >= self.cap {
            let mut k = 0;
            self.kept.retain(|_| {
                k += 1;
                (k - 1) % 2 == 0
            });
            self.stride *= 2;
            if i % self.stride != 0 {
                return;
            }
        }
        self.kept.push(x);
    }

    /// The samples kept, in the order pushed.
    pub fn kept(&self) -> &[T] {
        &self.kept
    }

    /// Push indices between two kept samples (1: every sample is kept).
    pub fn stride(&self) -> u64 {
        self.stride
    }

    /// Samples pushed in all.
    pub fn pushed(&self) -> u64 {
        self.pushed
    }
}

impl<T: Copy> Default for Decimated<T> {
    fn default() -> Self {
        Decimated::new(MAX_KEPT)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Oracle: which indices a stride-doubling record keeps, by hand: with room for 4, pushing
    // 0..10 keeps 0, 4, 8 (stride 4), and pushing fewer than the room keeps all.
    #[test]
    fn keeps_every_sample_until_full_then_every_stride_th() {
        let mut d = Decimated::new(4);
        for i in 0..3u64 {
            d.push(i);
        }
        assert_eq!((d.kept(), d.stride()), (&[0, 1, 2][..], 1));
        for i in 3..10u64 {
            d.push(i);
        }
        assert_eq!((d.kept(), d.stride(), d.pushed()), (&[0, 4, 8][..], 4, 10));
        // A long run never keeps more than the room.
        let mut big = Decimated::new(1000);
        for i in 0..1_000_000u64 {
            big.push(i);
        }
        assert!(big.kept().len() <= 1000);
        assert!(big.kept().iter().all(|i| i % big.stride() == 0));
    }
}
