//! `springlab report --quick` into a temporary directory: every referenced file exists, every
//! SVG is well-formed XML with axis labels and a legend, every CSV has its header, no NaN or
//! infinity anywhere, and an unstable run's line stops at its blow-up marker. The physics
//! checks use textbook oracles: global orders (1 for Euler, 2 for Verlet, 4 for RK4) and the
//! undamped-oscillator stability limits h·ω < 2 (Verlet) and 2√2 (RK4) (Hairer, Lubich &
//! Wanner, Geometric Numerical Integration, §I.5).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The shipped scenes this test reports: an exact oscillator, a blow-up, a bounce, a chain
/// (snapshots) and two free bodies (every chart kind; the full set is the CI report's job).
const SCENES: [&str; 5] = [
    "anchored_spring",
    "stiff_spring",
    "bounce",
    "hanging_chain",
    "two_body",
];

fn report_dir() -> &'static Path {
    static DIR: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    &DIR.get_or_init(|| {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("reports");
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let scenes = tmp.path().join("scenes");
        std::fs::create_dir(&scenes).unwrap();
        for s in SCENES {
            std::fs::copy(
                root.join(format!("scenarios/{s}.toml")),
                scenes.join(format!("{s}.toml")),
            )
            .unwrap();
        }
        let st = crate::support::bin()
            .args(["report", "--quick", "--energy-terms", "--scenarios"])
            .arg(&scenes)
            .arg("--out")
            .arg(&out)
            .status()
            .unwrap();
        assert!(st.success(), "springlab report --quick failed");
        (tmp, out)
    })
    .1
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Values of `attr="…"` attributes in an HTML page.
fn links(html: &str, attr: &str) -> Vec<String> {
    let pat = format!("{attr}=\"");
    html.match_indices(&pat)
        .map(|(i, _)| {
            let rest = &html[i + pat.len()..];
            rest[..rest.find('"').unwrap()].to_string()
        })
        .collect()
}

fn pages() -> Vec<PathBuf> {
    let dir = report_dir();
    let mut v = vec![dir.join("index.html")];
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            v.push(p.join("index.html"));
        }
    }
    v.sort();
    v
}

fn files_with_ext(ext: &str) -> Vec<PathBuf> {
    let mut v = Vec::new();
    for e in std::fs::read_dir(report_dir()).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            for f in std::fs::read_dir(&p).unwrap() {
                let f = f.unwrap().path();
                if f.extension().is_some_and(|e| e == ext) {
                    v.push(f);
                }
            }
        }
    }
    v.sort();
    v
}

#[test]
fn every_referenced_file_exists_and_pages_are_offline() {
    let dir = report_dir();
    for f in ["index.html", "README.md", "summary.json"] {
        assert!(dir.join(f).is_file(), "missing {f}");
    }
    let scenes = SCENES.len();
    assert_eq!(
        pages().len(),
        scenes + 1,
        "one page per scene plus the overview"
    );
    for page in pages() {
        let html = read(&page);
        let base = page.parent().unwrap();
        let mut refs: Vec<String> = links(&html, "href");
        refs.extend(links(&html, "src"));
        assert!(!refs.is_empty());
        for r in refs {
            assert!(
                !r.contains("://"),
                "{}: external reference {r}",
                page.display()
            );
            let target = base.join(&r);
            assert!(target.exists(), "{}: {r} does not exist", page.display());
        }
        // Scripts only for the playback: its local data file and the inline player.
        let scripts = html.matches("<script").count();
        assert!(
            scripts == 0 || (scripts == 2 && html.contains("<script src=\"playback.js\">")),
            "{}: scripts other than the playback's",
            page.display()
        );
        for bad in ["NaN", "inf ", ">inf<"] {
            assert!(!html.contains(bad), "{}: contains {bad}", page.display());
        }
    }
    // The Markdown overview links every scene page.
    let md = read(&dir.join("README.md"));
    for page in pages().iter().filter(|p| p.parent().unwrap() != dir) {
        let scene = page
            .parent()
            .unwrap()
            .file_name()
            .unwrap()
            .to_str()
            .unwrap();
        assert!(
            md.contains(&format!("({scene}/index.html)")),
            "README.md lacks {scene}"
        );
    }
}

/// Axis labels each chart must carry (with units).
fn axis_labels(stem: &str) -> &'static [&'static str] {
    match stem {
        "energy" => &["time t (s)", "total energy (J)"],
        "energy_error" => &["time t (s)", "|E(t) − E(0)|"],
        "position_error" => &["time t (s)", "max position error (m)"],
        "convergence" => &["time step dt (s)", "max position error over the run (m)"],
        "work_precision" => &["modelled time (s)", "force evaluations (count)"],
        "paths" | "snapshots" => &["(m)"],
        "collision" => &["time t (s)", "height (m)", "bounce n"],
        "impacts" => &["approach speed |v_in| (m/s)", "impact time t (s)"],
        "game_rate" => &["modelled time per frame (s)", "error ("],
        "framerate" => &[
            "frame rate (Hz)",
            "max position error (m)",
            "modelled time per frame (s)",
        ],
        other => panic!("unexpected chart {other}"),
    }
}

#[test]
fn every_svg_is_well_formed_with_axes_and_legend() {
    let svgs = files_with_ext("svg");
    assert!(svgs.len() >= 5 * 5, "too few charts: {}", svgs.len());
    for f in svgs {
        let text = read(&f);
        let doc = roxmltree::Document::parse(&text)
            .unwrap_or_else(|e| panic!("{}: not well-formed XML: {e}", f.display()));
        assert_eq!(doc.root_element().tag_name().name(), "svg");
        let texts: Vec<&str> = doc
            .descendants()
            .filter(|n| n.has_tag_name("text"))
            .filter_map(|n| n.text())
            .collect();
        let stem = f.file_stem().unwrap().to_str().unwrap();
        for label in axis_labels(stem) {
            assert!(
                texts.iter().any(|t| t.contains(label)),
                "{}: no axis label containing {label:?}",
                f.display()
            );
        }
        // Legend: every series named in the CSV appears as a text element.
        let csv = read(&f.with_extension("csv"));
        let mut rdr = csv::Reader::from_reader(csv.as_bytes());
        let headers = rdr.headers().unwrap().clone();
        let col = ["series", "method"]
            .iter()
            .find_map(|c| headers.iter().position(|h| h == *c))
            .unwrap();
        let names: BTreeSet<String> = rdr
            .records()
            .map(|r| r.unwrap()[col].to_string())
            .filter(|n| !n.starts_with("reference slope"))
            .collect();
        assert!(!names.is_empty(), "{}: empty data", f.display());
        for n in names {
            assert!(
                texts.iter().any(|t| t.contains(n.as_str())),
                "{}: legend lacks {n}",
                f.display()
            );
        }
        assert!(
            !text.contains("NaN") && !text.contains("inf\""),
            "{}",
            f.display()
        );
    }
}

fn expected_header(stem: &str) -> &'static str {
    match stem {
        "energy" | "energy_error" | "position_error" | "paths" | "collision" | "impacts"
        | "framerate" => "group,series,x,y,kind",
        "convergence" => "group,series,dt,error,kind,order,fitted_slope",
        "work_precision" => "method,dt,error,modelled_seconds,force_evals",
        "snapshots" => "method,t,line,index,u,v",
        "game_rate" => "method,engine,substeps,modelled_seconds_per_frame,error,meets,answer",
        other => panic!("unexpected csv {other}"),
    }
}

#[test]
fn every_csv_has_its_header_and_finite_numbers() {
    let csvs = files_with_ext("csv");
    assert!(!csvs.is_empty());
    for f in csvs {
        let text = read(&f);
        let stem = f.file_stem().unwrap().to_str().unwrap();
        assert_eq!(
            text.lines().next(),
            Some(expected_header(stem)),
            "{}",
            f.display()
        );
        assert!(text.lines().count() > 1, "{}: no rows", f.display());
        assert!(
            !text.contains("NaN") && !text.contains("inf"),
            "{}",
            f.display()
        );
        // Every SVG has its CSV and vice versa (same stem).
        assert!(f.with_extension("svg").is_file(), "{}: no SVG", f.display());
    }
}

#[test]
fn an_unstable_run_stops_at_its_marker() {
    // explicit Euler on the 1000 rad/s spring at 1/60 s (h·ω ≈ 17) must blow up.
    let dir = report_dir().join("stiff_spring");
    let mut checked = 0;
    for stem in ["energy", "energy_error"] {
        let csv = read(&dir.join(format!("{stem}.csv")));
        let mut rdr = csv::Reader::from_reader(csv.as_bytes());
        let rows: Vec<csv::StringRecord> = rdr.records().map(|r| r.unwrap()).collect();
        let marker = rows
            .iter()
            .find(|r| &r[1] == "explicit_euler" && &r[4] == "blowup")
            .expect("explicit_euler has a blow-up marker");
        let mx: f64 = marker[2].parse().unwrap();
        let xs: Vec<f64> = rows
            .iter()
            .filter(|r| &r[1] == "explicit_euler" && &r[4] == "point")
            .map(|r| r[2].parse().unwrap())
            .collect();
        let last = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        assert!(
            last <= mx,
            "{stem}: line goes past its marker ({last} > {mx})"
        );
        assert!(
            mx - last <= (1.0 / 60.0) * (1.0 + 1e-8), // CSV keeps 10 significant digits
            "{stem}: line stops more than a step before the marker"
        );
        let svg = read(&dir.join(format!("{stem}.svg")));
        assert!(svg.contains("blow-up"), "{stem}.svg has no marker");
        checked += 1;
    }
    assert_eq!(checked, 2);
    let sum: serde_json::Value =
        serde_json::from_str(&read(&report_dir().join("summary.json"))).unwrap();
    let scene = sum["scenes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["scene"] == "stiff_spring")
        .unwrap();
    let ee = scene["methods"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| b["method"] == "explicit_euler")
        .unwrap();
    assert_eq!(ee["status"], "unstable");
    assert!(ee["blowup_time"].as_f64().unwrap() > 0.0);
}

fn method<'a>(sum: &'a serde_json::Value, scene: &str, b: &str) -> &'a serde_json::Value {
    let s = sum["scenes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["scene"] == scene)
        .unwrap();
    s["methods"]
        .as_array()
        .unwrap()
        .iter()
        .find(|x| x["method"] == b)
        .unwrap()
}

#[test]
fn fitted_orders_and_stability_limits_match_the_textbook() {
    let sum: serde_json::Value =
        serde_json::from_str(&read(&report_dir().join("summary.json"))).unwrap();
    // Global orders on the undamped oscillator (exact reference: analytic).
    for (b, order) in [
        ("explicit_euler", 1.0),
        ("symplectic_euler", 1.0),
        ("velocity_verlet", 2.0),
        ("rk2", 2.0),
        ("rk4", 4.0),
    ] {
        let k = method(&sum, "anchored_spring", b)["observed_order"]
            .as_f64()
            .unwrap_or_else(|| panic!("{b}: no observed order"));
        assert!(
            (k - order).abs() < 0.25,
            "{b}: fitted order {k}, textbook {order}"
        );
    }
    // Stability limits: the stability report's h·ω_max limit (spectral radius, bisected) is
    // the textbook one.
    for (b, limit) in [
        ("symplectic_euler", 2.0),
        ("velocity_verlet", 2.0),
        ("rk4", 2.0 * 2f64.sqrt()),
    ] {
        let h = method(&sum, "anchored_spring", b)["stable_h_omega"]
            .as_f64()
            .unwrap();
        assert!(
            (h - limit).abs() < 1e-6 * limit,
            "{b}: stable up to {h}, textbook {limit}"
        );
    }
    // Explicit Euler grows at every step size on an undamped oscillator.
    let ee = method(&sum, "anchored_spring", "explicit_euler");
    assert_eq!(ee["stability"], "unstable_for_all_dt");
    // The closed form's order is "exact", never a number.
    assert_eq!(
        method(&sum, "anchored_spring", "analytic")["order"],
        "exact"
    );
    // Every scene has a verdict that names the step it compares at.
    for s in sum["scenes"].as_array().unwrap() {
        let v = s["verdict"].as_str().unwrap();
        assert!(v.contains("At dt = "), "{v}");
    }
}
