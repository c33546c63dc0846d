//! `springlab check` on obstacle scenes: obstacles with shape, pose,
//! restitution and friction, particle radii, the contact response, and every method that
//! applies, Rapier included (penalty scenes too), with the reason each other one does not;
//! and a scene's impulses, listed under their header.
//!
//! Oracle: the shipped scene files themselves (`scenarios/bounce.toml`,
//! `scenarios/bounce_penalty.toml`, `scenarios/rain_on_mesh.toml`).

fn check(scene: &str) -> String {
    let out = crate::support::bin()
        .args([
            "check",
            &format!("{}/scenarios/{scene}", env!("CARGO_MANIFEST_DIR")),
        ])
        .output()
        .unwrap();
    assert!(out.status.success());
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn check_lists_obstacles_radii_response_and_rapier() {
    let text = check("bounce.toml");
    for needle in [
        "radius = 0.1 m",
        "[0] plane: point = (0, 0, 0), normal = (0, 1, 0); restitution = 0.5, friction = 0",
        "contact response: impulse",
        "rapier_impulse, rapier_multibody",
    ] {
        assert!(text.contains(needle), "missing '{needle}' in:\n{text}");
    }
}

/// Rapier takes penalty contacts as user forces (`src/rapier/user_forces.rs`).
#[test]
fn check_lists_rapier_for_penalty_contacts() {
    let text = check("bounce_penalty.toml");
    assert!(
        text.contains("contact response: penalty, stiffness = 100000 N/m"),
        "{text}"
    );
    assert!(text.contains("rapier_impulse, rapier_multibody"), "{text}");
    assert!(!text.contains("not rapier_impulse: "), "{text}");
}

#[test]
fn check_says_whether_a_mesh_is_closed_or_a_two_sided_sheet() {
    let text = check("rain_on_mesh.toml");
    assert!(
        text.contains("open (two-sided sheet); restitution = 0.3, friction = 0.2"),
        "{text}"
    );
}

/// `check` lists each impulse right under the `impulses:` header, before the run's lines.
/// Oracle: the shipped recoil spring's file, five shots at 0.05, 0.15, … 0.45 s.
#[test]
fn check_lists_the_impulses_under_their_header() {
    let out = crate::support::bin()
        .args(["check", "scenarios/recoil_spring.toml"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = text.lines().collect();
    let h = lines
        .iter()
        .position(|l| l.starts_with("impulses: 5 "))
        .expect("the header");
    for (k, t) in ["0.05", "0.15", "0.25", "0.35", "0.45"].iter().enumerate() {
        assert!(
            lines[h + 1 + k].starts_with(&format!("  [{k}] t = {t} s: particle 1")),
            "{text}"
        );
    }
    assert!(lines[h + 6].starts_with("run: "), "{text}");
}
