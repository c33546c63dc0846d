//! Chart functions on hand-made data: non-finite values never reach the SVG, a blown-up
//! series is marked, log axes drop non-positive values, and every chart is well-formed XML.
//! The collision data are the closed-form bouncing ball: apexes h₀·e^(2n) (DESIGN.md oracle).

use springlab::report::data::*;
use springlab::report::plots;

fn texts(svg: &str) -> Vec<String> {
    let doc = roxmltree::Document::parse(svg).expect("well-formed SVG");
    doc.descendants()
        .filter(|n| n.has_tag_name("text"))
        .filter_map(|n| n.text().map(str::to_string))
        .collect()
}

fn nasty() -> Vec<[f64; 2]> {
    vec![
        [0.0, 1.0],
        [0.5, f64::NAN],
        [1.0, 2.0],
        [f64::INFINITY, 3.0],
        [1.5, 0.0],
        [2.0, 4.0],
    ]
}

#[test]
fn non_finite_values_never_reach_the_svg_and_blowups_are_marked() {
    let mut blown = Series::new("explicit_euler", vec![[0.0, 1e-6], [1.0, 1e-2]]);
    blown.blowup = Some(BlowUp { x: 1.05, y: 1e-2 });
    let data = EnergyErrorData {
        series: vec![Series::new("rk4", nasty()), blown],
        scale_note: "E_scale = 1 J".into(),
    };
    let svg = plots::energy_error(&data).unwrap();
    assert!(
        !svg.contains("NaN") && !svg.contains("inf"),
        "non-finite value in SVG"
    );
    let t = texts(&svg);
    for want in ["rk4", "explicit_euler", "blow-up", "time t (s)"] {
        assert!(t.iter().any(|x| x.contains(want)), "missing text {want}");
    }
    let energy = plots::energy(&EnergyData {
        totals: vec![Series::new("rk4", nasty())],
        terms: vec![Series::new("kinetic (rk4)", nasty())],
    })
    .unwrap();
    assert!(!energy.contains("NaN"));
    assert!(texts(&energy).iter().any(|x| x.contains("kinetic (rk4)")));
}

#[test]
fn every_chart_renders_from_plain_data() {
    // Closed-form bouncing ball: h0 = 1 m, e = 0.5, g = 9.81: apex n at h0 e^(2n).
    let (h0, e, g) = (1.0f64, 0.5f64, 9.81f64);
    let mut t = (2.0 * h0 / g).sqrt();
    let mut apexes = vec![[0.0, h0]];
    let mut bounces = Vec::new();
    for n in 1..=4u32 {
        let v = (2.0 * g * h0).sqrt() * e.powi(n as i32);
        apexes.push([t + v / g, h0 * e.powi(2 * n as i32)]);
        bounces.push(Bounce {
            n,
            measured: e,
            specified: e,
            penetration: 1e-4 / n as f64,
        });
        t += 2.0 * v / g;
    }
    let col = CollisionData {
        heights: vec![Series::new("velocity_verlet", apexes.clone())],
        envelope: Series::new("particle 0", apexes),
        bounces: vec![("velocity_verlet".into(), bounces)],
    };
    let svgs = [
        plots::collision(&col).unwrap(),
        plots::convergence(&ConvergenceData {
            lines: vec![ConvergenceLine {
                series: Series::new("rk4", vec![[0.1, 1e-4], [0.05, 6.25e-6]]),
                fitted_slope: Some(4.0),
                order: 4,
                note: None,
            }],
            guides: vec![Guide {
                label: "reference slope 4".into(),
                points: vec![[0.05, 3e-6], [0.1, 5e-5]],
            }],
            reference: "analytic".into(),
        })
        .unwrap(),
        plots::paths(&PathData {
            axes: ["x".into(), "y".into()],
            series: vec![Series::new("rk4", nasty())],
        })
        .unwrap(),
    ];
    for svg in &svgs {
        assert!(!svg.contains("NaN"));
        assert!(
            texts(svg).len() > 5,
            "too little text: axes and legend expected"
        );
    }
    assert!(texts(&svgs[0]).iter().any(|x| x.contains("envelope")));
    assert!(texts(&svgs[1])
        .iter()
        .any(|x| x.contains("observed order 4.00")));
    // The collision CSV carries every bounce.
    let csv = String::from_utf8(col.to_csv().unwrap()).unwrap();
    assert_eq!(csv.lines().filter(|l| l.starts_with("bounce,")).count(), 4);
}
