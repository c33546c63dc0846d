//! Helpers every command-line test shares: the binary under test, and a run that must succeed.

use std::process::Command;

/// The `springlab` binary under test, without the reference store: each test solves its own
/// references, so no test's timing or progress depends on what another test stored (the
/// store's own tests point `SPRINGLAB_CACHE_DIR` at a folder of their own and clear this).
pub fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_springlab"));
    c.env("SPRINGLAB_NO_CACHE", "1");
    c
}

/// Runs `springlab ARGS`, asserts that it succeeded (showing its stderr when not) and returns
/// its stdout.
pub fn ok(args: &[&str]) -> String {
    let out = bin().args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}
