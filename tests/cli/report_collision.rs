//! The collision-validation section of an obstacle scene's page, from a
//! quick report of the shipped bounce scene into a temporary directory: the per-impact chart
//! and table carry the measured e beside the expected one for every method, and Rapier's
//! documented differences are each named where a Rapier method ran.
//!
//! Oracle: the ball is dropped from rest at 1 m above the plane's surface with e = 0.5 (the
//! scene file), so its first impact arrives at √(2·9.81·1) = 4.429 m/s, and every impulse-type
//! method must rebound at 0.5 of it (within 2 %); the page's first-impacts
//! table must show both numbers.

use std::path::Path;

fn report(scenes: &[&str], out: &Path) {
    let dir = out.join("scenarios");
    std::fs::create_dir_all(&dir).unwrap();
    for s in scenes {
        std::fs::copy(
            format!("{}/scenarios/{s}.toml", env!("CARGO_MANIFEST_DIR")),
            dir.join(format!("{s}.toml")),
        )
        .unwrap();
    }
    let st = crate::support::bin()
        .args(["report", "--quick", "--scenarios"])
        .arg(&dir)
        .arg("--out")
        .arg(out.join("reports"))
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
}

#[test]
fn the_bounce_page_shows_each_impact_against_theory_and_rapiers_differences() {
    let tmp = tempfile::tempdir().unwrap();
    report(&["bounce"], tmp.path());
    let dir = tmp.path().join("reports/bounce");
    let page = std::fs::read_to_string(dir.join("index.html")).unwrap();
    assert!(
        page.contains("impacts.svg"),
        "no per-impact chart on the page"
    );
    let csv = std::fs::read_to_string(dir.join("impacts.csv")).unwrap();
    let mut rdr = csv::Reader::from_reader(csv.as_bytes());
    let mut first: std::collections::BTreeMap<String, (f64, f64)> = Default::default();
    for r in rdr.records() {
        let r = r.unwrap();
        let (group, series, x, y) = (&r[0], &r[1], &r[2], &r[3]);
        let (x, y): (f64, f64) = (x.parse().unwrap(), y.parse().unwrap());
        assert!(x.is_finite() && y.is_finite());
        if group == "measured" {
            let e = first.entry(series.to_string()).or_insert((0.0, 0.0));
            if x > e.0 {
                *e = (x, y);
            }
        }
    }
    // The fastest impact of each method is the first: 4.429 m/s in, e = 0.5 out.
    let v1 = (2.0f64 * 9.81 * 1.0).sqrt();
    assert!(first.len() >= 4, "{first:?}");
    for (method, (v, e)) in &first {
        assert!(
            (v / v1 - 1.0).abs() < 0.01,
            "{method}: first impact at {v} m/s"
        );
        assert!((e / 0.5 - 1.0).abs() < 0.02, "{method}: first e = {e}");
    }
    assert!(page.contains("First impacts"));
    assert!(
        page.contains("4.4294"),
        "the first approach speed in the table"
    );
    assert!(page.contains("documented differences"));
    // The bounce scene's contacts are impulse ones: the colliders' differences, not the
    // penalty one.
    for d in &springlab::rapier::DIFFERENCES {
        assert_eq!(
            page.contains(d.title),
            d.applies_to(springlab::collide::ResponseKind::Impulse),
            "{}",
            d.title
        );
    }
}
