//! `springlab bench-scaling`: wall time per step against particle count for every method on
//! n×n cloths, as `scaling.csv` and a log-log `scaling.svg` (both written atomically).

use anyhow::{bail, Result};
use plotters::prelude::*;
use springlab::method::MethodOptions;
use springlab::output::write_atomic;
use springlab::perf::{bench_dt, cloth, methods_for, time_per_step};
use std::path::PathBuf;

/// Flags of `springlab bench-scaling`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Cloth sizes n (an n×n cloth each), comma-separated.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "8,16,32,64,128",
        allow_negative_numbers = true
    )]
    pub sizes: Vec<usize>,
    /// Output directory.
    #[arg(long, default_value = "out/bench-scaling")]
    pub out: PathBuf,
    /// Repetitions per point (the minimum is reported).
    #[arg(long, default_value_t = 5, allow_negative_numbers = true)]
    pub reps: usize,
}

/// One measured point.
struct Row {
    method: &'static str,
    n: usize,
    particles: usize,
    springs: usize,
    dt: f64,
    /// Wall time per step, or why the method could not step this cloth.
    seconds: std::result::Result<f64, String>,
}

/// Runs the command.
pub fn run(a: Args) -> Result<()> {
    super::common::check_out(&a.out)?;
    if a.sizes.is_empty() || a.sizes.iter().any(|&n| !(2..=1000).contains(&n)) {
        bail!(
            "--sizes: each size must be between 2 and 1000, got {:?}",
            a.sizes
        );
    }
    let _lock = springlab::output::lock_dir(&a.out)?;
    if a.reps == 0 {
        bail!("--reps: must be at least 1");
    }
    let mut rows = Vec::new();
    for &n in &a.sizes {
        let scene = cloth(n);
        let springs = scene.springs.len();
        for name in methods_for(&scene) {
            let mut stepper = springlab::method::create(name, &MethodOptions::default())?;
            let dt = bench_dt(name);
            // About 10⁶ spring updates per repetition, at least 2 steps.
            let steps = (1_000_000 / springs.max(1)).clamp(2, 500);
            let seconds = time_per_step(&scene, stepper.as_mut(), dt, steps, a.reps)
                .map_err(|e| e.to_string());
            match &seconds {
                Ok(t) => println!(
                    "{name:>18} {n:>4}×{n:<4} {:>8} particles: {:>12.3} µs/step, {:>8.2} ns/spring",
                    n * n,
                    t * 1e6,
                    t * 1e9 / springs as f64
                ),
                Err(why) => println!("{name:>18} {n:>4}×{n:<4} failed: {why}"),
            }
            rows.push(Row {
                method: name,
                n,
                particles: n * n,
                springs,
                dt,
                seconds,
            });
        }
    }
    let csv_path = a.out.join("scaling.csv");
    write_atomic(&csv_path, &to_csv(&rows)?)?;
    let svg_path = a.out.join("scaling.svg");
    write_atomic(&svg_path, plot(&rows)?.as_bytes())?;
    println!("wrote {} and {}", csv_path.display(), svg_path.display());
    Ok(())
}

fn to_csv(rows: &[Row]) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "method",
        "n",
        "particles",
        "springs",
        "dt",
        "seconds_per_step",
        "ns_per_spring",
        "status",
    ])?;
    for r in rows {
        w.write_record([
            r.method.to_string(),
            r.n.to_string(),
            r.particles.to_string(),
            r.springs.to_string(),
            r.dt.to_string(),
            r.seconds.as_ref().map_or(String::new(), |t| t.to_string()),
            r.seconds
                .as_ref()
                .map_or(String::new(), |t| (t * 1e9 / r.springs as f64).to_string()),
            match &r.seconds {
                Ok(_) => "ok".to_string(),
                Err(why) => format!("failed: {why}"),
            },
        ])?;
    }
    Ok(w.into_inner()?)
}

/// Log-log plot of seconds per step against particles, one line per method (failed points
/// are left out).
fn plot(rows: &[Row]) -> Result<String> {
    let pts_of = |name: &str| -> Vec<(f64, f64)> {
        rows.iter()
            .filter(|r| r.method == name)
            .filter_map(|r| r.seconds.as_ref().ok().map(|&t| (r.particles as f64, t)))
            .collect()
    };
    let ok: Vec<(f64, f64)> = rows
        .iter()
        .filter_map(|r| r.seconds.as_ref().ok().map(|&t| (r.particles as f64, t)))
        .collect();
    if ok.is_empty() {
        bail!("no method could step any of the cloths: nothing to plot");
    }
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (800, 560)).into_drawing_area();
        root.fill(&WHITE)?;
        let (x0, x1) = ok
            .iter()
            .fold((f64::MAX, 0f64), |(lo, hi), p| (lo.min(p.0), hi.max(p.0)));
        let (y0, y1) = ok
            .iter()
            .fold((f64::MAX, 0f64), |(lo, hi), p| (lo.min(p.1), hi.max(p.1)));
        let mut chart = ChartBuilder::on(&root)
            .caption(
                "Cost per step against particle count (n×n cloth)",
                ("sans-serif", 20),
            )
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d(
                (x0 * 0.8..x1 * 1.25).log_scale(),
                (y0 * 0.5..y1 * 2.0).log_scale(),
            )?;
        chart
            .configure_mesh()
            .x_desc("particles")
            .y_desc("wall time per step (s)")
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()?;
        let mut names: Vec<&str> = rows.iter().map(|r| r.method).collect();
        names.dedup();
        names.sort_unstable();
        names.dedup();
        for (k, name) in names.iter().enumerate() {
            let color = Palette99::pick(k).to_rgba();
            let pts = pts_of(name);
            chart
                .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))?
                .label(*name)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2))
                });
            chart.draw_series(pts.into_iter().map(|p| Circle::new(p, 3, color.filled())))?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()?;
        root.present()?;
    }
    Ok(svg)
}
