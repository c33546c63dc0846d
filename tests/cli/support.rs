//! Helpers every command-line test shares: the binary under test, and a run that must succeed.

use std::process::Command;

/// The `springlab` binary under test.
pub fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_springlab"))
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
