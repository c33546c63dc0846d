//! Digests that tell inputs apart: of a byte string, and of the running program itself, so
//! that what one build computed is never taken for another build's.

use std::hash::{DefaultHasher, Hash, Hasher};
use std::sync::OnceLock;

/// A 128-bit digest of `parts` in hex (two independently seeded 64-bit hashes).
pub fn digest(parts: &[&[u8]]) -> String {
    let half = |seed: u64| {
        let mut h = DefaultHasher::new();
        seed.hash(&mut h);
        for p in parts {
            p.hash(&mut h);
        }
        h.finish()
    };
    format!("{:016x}{:016x}", half(1), half(2))
}

/// The running program's digest: a changed build never reuses an older build's results.
pub fn program_digest() -> &'static str {
    static DIGEST: OnceLock<String> = OnceLock::new();
    DIGEST.get_or_init(|| {
        let bytes = std::env::current_exe()
            .and_then(std::fs::read)
            .unwrap_or_default();
        // Without its own bytes the program cannot tell builds apart: a digest nothing
        // stored holds, so nothing is reused.
        if bytes.is_empty() {
            return format!("unreadable-{}", std::process::id());
        }
        digest(&[&bytes])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    // Oracle: a digest is a function of its parts: equal parts give equal digests, and a
    // change of one byte anywhere, or of where the parts split, gives another.
    #[test]
    fn digest_tells_inputs_apart() {
        let a = digest(&[b"scene", b"opts"]);
        assert_eq!(a, digest(&[b"scene", b"opts"]));
        assert_ne!(a, digest(&[b"scene", b"optt"]));
        assert_ne!(a, digest(&[b"scen", b"eopts"]));
        assert_eq!(a.len(), 32);
    }
}
