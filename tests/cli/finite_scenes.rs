//! A scene is finite or refused: `check` (and so every command, which load scenes the same
//! way) refuses initial positions, energies and forces that f64 cannot hold, a spring whose
//! ends coincide while its rest length is not zero, and a name that cannot be a folder, with
//! the file and the field at fault. Each refusal has an accepted twin near the same edge.
//!
//! Oracles: f64's largest value, about 1.8e308 (so (1e300)² overflows and (1e150)² = 1e300
//! does not); the closed forms m·g·z and ½k(l - l0)² for the energies; the length of a file
//! name on Linux and macOS, at most 255 bytes, without '/' or NUL.

use crate::support::bin;
use std::path::{Path, PathBuf};
use std::process::Output;

fn write(dir: &Path, text: &str) -> PathBuf {
    let p = dir.join("scene.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn check(text: &str) -> Output {
    let dir = tempfile::tempdir().unwrap();
    bin()
        .arg("check")
        .arg(write(dir.path(), text))
        .output()
        .unwrap()
}

/// `check` refuses with the file and every needle in the message.
fn rejects(text: &str, needles: &[&str]) {
    let out = check(text);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "accepted:\n{text}");
    assert!(!err.contains("panicked"), "panic: {err}");
    assert!(err.contains("scene.toml"), "no file name in: {err}");
    for n in needles {
        assert!(err.contains(n), "missing '{n}' in: {err}");
    }
}

fn accepts(text: &str) {
    let out = check(text);
    assert!(
        out.status.success(),
        "refused:\n{text}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A chain of 4 along x at height `z`, hanging from its first particle.
fn chain_at(z: &str) -> String {
    format!(
        "[world]\ngravity = [0.0, 0.0, -9.81]\n\
         [[chain]]\nstart = [0.0, 0.0, {z}]\nend = [1.0, 0.0, {z}]\ncount = 4\nmass = 0.1\n\
         stiffness = 100.0\nfix = [\"first\"]\n[run]\ndt = 0.01\nduration = 1.0\n"
    )
}

/// A fixed anchor at the origin, a 1 kg particle at z = 10 m and a spring of rest length
/// 0.5 m between them (stretched by 9.5 m), under gravity `g` along -z.
fn anchored(stiffness: &str, g: &str) -> String {
    format!(
        "[[particle]]\nposition = [0.0, 0.0, 0.0]\nmass = 1.0\nfixed = true\n\
         [[particle]]\nposition = [0.0, 0.0, 10.0]\nmass = 1.0\n\
         [[spring]]\nbetween = [0, 1]\nstiffness = {stiffness}\nrest_length = 0.5\n\
         [world]\ngravity = [0.0, 0.0, -{g}]\n[run]\ndt = 0.01\nsteps = 10\n"
    )
}

#[test]
fn a_chain_too_far_from_the_origin_is_refused() {
    // (1e300)² overflows f64: every distance and energy would be inf or NaN.
    rejects(&chain_at("1e300"), &["chain[0]", "position"]);
}

#[test]
fn twin_a_chain_far_but_within_f64_is_accepted() {
    // (1e150)² = 1e300 < 1.8e308; m g z = 0.1 × 9.81 × 1e150 is finite.
    accepts(&chain_at("1e150"));
}

#[test]
fn run_refuses_the_far_chain_instead_of_writing_nan() {
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), &chain_at("1e300"));
    let out = bin()
        .args(["run", "-i", "rk4", "--out"])
        .arg(dir.path().join("o"))
        .arg(&f)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("chain[0]"));
    assert!(!dir.path().join("o").join("energy.csv").exists());
}

#[test]
fn an_explicit_particle_too_far_away_is_named_with_its_field() {
    let text = anchored("2.0", "9.81").replace("[0.0, 0.0, 10.0]", "[1e200, 0.0, 10.0]");
    rejects(&text, &["particle[1].position"]);
}

#[test]
fn gravity_whose_energy_overflows_is_refused() {
    // m g z = 1 kg × 1e308 m/s² × 10 m = 1e309 J > 1.8e308.
    rejects(&anchored("2.0", "1e308"), &["world.gravity", "not finite"]);
}

#[test]
fn twin_strong_but_finite_gravity_passes_the_energy_rule() {
    // 1 × 1e306 × 10 = 1e307 J: finite, so the energy rule passes it; its time scale
    // √(10 m / 1e306 m/s²) = 3e-153 s is what refuses it (see `check`'s time-scale rule).
    let out = check(&anchored("2.0", "1e306"));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("time scale") && !err.contains("not finite"),
        "{err}"
    );
    // Strong but resolvable: √(10 / 1e20) = 3e-10 s, above the run's 1e3 f64 spacings.
    accepts(&anchored("2.0", "1e20"));
}

#[test]
fn stiffness_whose_energy_overflows_is_refused() {
    // ½ k (10 - 0.5)² = 45.125 k: 4.5e308 J for k = 1e307.
    rejects(
        &anchored("1e307", "9.81"),
        &["spring[0].stiffness", "not finite"],
    );
}

#[test]
fn twin_stiff_but_finite_spring_is_accepted() {
    // 45.125 × 1e306 = 4.5e307 J.
    accepts(&anchored("1e306", "9.81"));
}

#[test]
fn a_spring_with_coincident_ends_and_a_rest_length_is_refused() {
    let text = anchored("2.0", "9.81").replace("[0.0, 0.0, 10.0]", "[0.0, 0.0, 0.0]");
    rejects(&text, &["spring[0]", "coincide"]);
}

#[test]
fn twin_a_spring_with_ends_barely_apart_is_accepted() {
    let text = anchored("2.0", "9.81").replace("[0.0, 0.0, 10.0]", "[0.0, 0.0, 1e-9]");
    accepts(&text);
}

fn named(name: &str) -> String {
    format!("name = \"{name}\"\n{}", anchored("2.0", "9.81"))
}

#[test]
fn a_name_with_a_nul_byte_is_refused() {
    rejects(&named("a\\u0000b"), &["name", "NUL"]);
}

#[test]
fn a_name_with_a_slash_is_refused() {
    rejects(&named("a/b"), &["name"]);
}

#[test]
fn a_name_over_255_bytes_is_refused() {
    rejects(&named(&"a".repeat(256)), &["name", "256 bytes"]);
    // Bytes, not characters: 128 two-byte letters are 256 bytes.
    rejects(&named(&"é".repeat(128)), &["name", "256 bytes"]);
}

#[test]
fn twin_a_name_of_255_bytes_is_accepted() {
    accepts(&named(&"a".repeat(255)));
    accepts(&named(&format!("{}a", "é".repeat(127))));
}

#[test]
fn a_tiny_negative_mass_is_quoted_in_short_form() {
    // Printed in full, -1e-300 is over 300 characters long.
    let text =
        anchored("2.0", "9.81").replacen("mass = 1.0\n[[spring]]", "mass = -1e-300\n[[spring]]", 1);
    let out = check(&text);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("particle[1].mass: must be > 0, got -1e-300"),
        "{err}"
    );
    assert!(err.len() < 200, "{err}");
}

#[test]
fn twin_a_tiny_positive_mass_is_accepted() {
    accepts(&anchored("2.0", "9.81").replacen(
        "mass = 1.0\n[[spring]]",
        "mass = 1e-300\n[[spring]]",
        1,
    ));
}
