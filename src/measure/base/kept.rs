//! Values made once per key in a process and handed out again: a scene's modes, its
//! ensembles. Each is made outside the lock (two threads asking at once both make it, to the
//! same bits, and the first to finish is kept); at most a fixed number are held, the oldest
//! dropped first and made again, to the same bits, when asked for.

use std::sync::Mutex;

/// A process-wide store of at most `most` values, keyed by a full description of what made
/// them (a system's and state's `Debug` text, say).
pub(crate) struct Kept<T> {
    held: Mutex<Vec<(String, T)>>,
    most: usize,
}

impl<T: Clone> Kept<T> {
    /// An empty store holding at most `most` values.
    pub(crate) const fn new(most: usize) -> Self {
        Kept {
            held: Mutex::new(Vec::new()),
            most,
        }
    }

    /// The value kept under `key`, or `make`'s, kept when it succeeds.
    pub(crate) fn get_or_make<E>(
        &self,
        key: String,
        make: impl FnOnce() -> Result<T, E>,
    ) -> Result<T, E> {
        let lock = || self.held.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, v)) = lock().iter().find(|(k, _)| *k == key) {
            return Ok(v.clone());
        }
        let made = make()?;
        let mut held = lock();
        if let Some((_, v)) = held.iter().find(|(k, _)| *k == key) {
            return Ok(v.clone());
        }
        if held.len() >= self.most {
            held.remove(0);
        }
        held.push((key, made.clone()));
        Ok(made)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // A value is made once per key while it is held, again after the oldest-first drop; a
    // failed make keeps nothing.
    #[test]
    fn made_once_per_key_and_again_after_it_is_dropped() {
        let kept: Kept<u32> = Kept::new(2);
        let mut made = 0;
        let mut get = |k: &str| {
            kept.get_or_make::<()>(k.into(), || {
                made += 1;
                Ok(made)
            })
            .unwrap()
        };
        assert_eq!((get("a"), get("a"), get("b"), get("a")), (1, 1, 2, 1));
        assert_eq!(get("c"), 3);
        assert_eq!(get("a"), 4, "a, the oldest, was dropped for c");
        assert!(kept.get_or_make("d".into(), || Err("no")).is_err());
        assert_eq!(kept.get_or_make::<()>("d".into(), || Ok(9)).unwrap(), 9);
    }
}
