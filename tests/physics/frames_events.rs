//! `[run] events = "frame"` applies each impulse at the first frame boundary
//! at or after its time. Oracle: the damped oscillator's closed form
//! u(t) = e^{-γt}[u₀ cos ω_d t + (v₀ + γu₀)/ω_d sin ω_d t] (γ = c/2m, ω_d² = k/m − γ²),
//! written out here and walked through the kicks moved by hand to the next 1/60 s boundary;
//! the runner (with the `analytic` stepper between kicks) must match it to 1e-9 m at every
//! frame. The row at a kick's frame shows the state before the kick.

use springlab::method::MethodOptions;
use springlab::method::Registry;
use springlab::model::State;
use springlab::run::{run, EnergyRecord, Observer, RunPlan};
use springlab::scenario::Scenario;

#[derive(Default)]
struct Keep(Vec<State>);
impl Observer for Keep {
    fn observe(&mut self, _: u64, s: &State, _: &EnergyRecord) -> springlab::Result<()> {
        self.0.push(s.clone());
        Ok(())
    }
}

/// The recoil spring: 0.35 kg, k = 1500 N/m, c = 6 N·s/m, kicks at 0.037, 0.137,
/// 0.237 and 0.3 s (the last exactly on a 60 Hz boundary).
fn scene(events: &str) -> Scenario {
    let toml = format!(
        r#"
[[particle]]
position = [0.0, 0.0, 0.0]
mass = 1.0
fixed = true
[[particle]]
position = [0.2, 0.0, 0.0]
mass = 0.35
[[spring]]
between = [0, 1]
stiffness = 1500.0
rest_length = 0.2
damping = 6.0
[[impulse]]
time = 0.037
particle = 1
delta_v = [-0.8, 0.0, 0.0]
[[impulse]]
time = 0.137
particle = 1
delta_v = [-0.8, 0.0, 0.0]
[[impulse]]
time = 0.237
particle = 1
delta_v = [-0.8, 0.0, 0.0]
[[impulse]]
time = 0.3
particle = 1
delta_v = [-0.8, 0.0, 0.0]
[run]
dt = 0.01
duration = 0.5
events = "{events}"
"#
    );
    Scenario::from_toml_str(&toml, "recoil.toml").unwrap()
}

/// Displacement from rest at `t`, kicks (time, Δv) applied strictly before `t`.
fn closed_form(t: f64, kicks: &[(f64, f64)]) -> f64 {
    let (m, k, c) = (0.35f64, 1500.0f64, 6.0f64);
    let g = c / (2.0 * m);
    let wd = (k / m - g * g).sqrt();
    let flow = |u: f64, v: f64, s: f64| {
        let e = (-g * s).exp();
        let (cs, sn) = ((wd * s).cos(), (wd * s).sin());
        let u1 = e * (u * cs + (v + g * u) / wd * sn);
        let v1 = e * (v * cs - (g * v + (k / m) * u) / wd * sn);
        (u1, v1)
    };
    let (mut u, mut v, mut t0) = (0.0, 0.0, 0.0);
    for &(tk, dv) in kicks.iter().filter(|(tk, _)| *tk < t - 1e-12) {
        (u, v) = flow(u, v, tk - t0);
        v += dv;
        t0 = tk;
    }
    flow(u, v, t - t0).0
}

fn frames_of(events: &str, hz: f64, substeps: u64, method: &str) -> Vec<State> {
    let sc = scene(events);
    let sys = sc.build();
    let mut stepper = Registry::builtin()
        .create(method, &MethodOptions::default())
        .unwrap();
    let frames = (0.5 * hz).round() as u64;
    let plan = RunPlan::new(1.0 / hz, frames).with_substeps(substeps);
    let mut keep = Keep::default();
    let out = run(&sys, &mut stepper, sc.initial_state(), &plan, &mut keep).unwrap();
    assert!(out.status.is_ok());
    keep.0
}

#[test]
fn frame_events_follow_the_closed_form_with_kicks_moved_to_the_next_frame() {
    let hz = 60.0;
    let h = 1.0 / hz;
    // Moved by hand: 0.037 → 3 h, 0.137 → 9 h, 0.237 → 15 h, 0.3 = 18 h stays.
    let moved: Vec<(f64, f64)> = [3.0, 9.0, 15.0, 18.0]
        .iter()
        .map(|k| (k * h, -0.8))
        .collect();
    let exact: Vec<(f64, f64)> = [0.037, 0.137, 0.237, 0.3]
        .iter()
        .map(|&t| (t, -0.8))
        .collect();
    for substeps in [1, 4] {
        let rows = frames_of("frame", hz, substeps, "analytic");
        let mut lag: f64 = 0.0;
        for (n, s) in rows.iter().enumerate() {
            let t = n as f64 * h;
            let u = s.x[1].x - 0.2;
            assert!(
                (u - closed_form(t, &moved)).abs() < 1e-9,
                "frame {n} ({substeps} substeps): {u} vs {}",
                closed_form(t, &moved)
            );
            lag = lag.max((u - closed_form(t, &exact)).abs());
        }
        // The game loop's lag is visible: millimetres to centimetres, far above 1e-9.
        assert!(lag > 1e-3, "lag {lag}");
    }
    // The row at the frame the first kick moved to (frame 3) still shows the state before
    // it: the slide is still at rest there, and moving one frame later.
    let rows = frames_of("frame", hz, 1, "analytic");
    assert_eq!(
        rows[3].v[1].x, 0.0,
        "kick not yet applied in the row at its frame"
    );
    assert_eq!(rows[3].x[1].x, 0.2);
    assert!(rows[4].v[1].x < -0.1, "applied by the next row");
}

#[test]
fn exact_events_still_split_the_step() {
    let h = 1.0 / 60.0;
    let exact: Vec<(f64, f64)> = [0.037, 0.137, 0.237, 0.3]
        .iter()
        .map(|&t| (t, -0.8))
        .collect();
    for (n, s) in frames_of("exact", 60.0, 1, "analytic").iter().enumerate() {
        let t = n as f64 * h;
        assert!(
            (s.x[1].x - 0.2 - closed_form(t, &exact)).abs() < 1e-9,
            "frame {n}"
        );
    }
}
