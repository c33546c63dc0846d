//! Cost of one force evaluation and one step of every method on cloths of 32², 100² and 316²
//! particles, in ns per spring (criterion `Throughput::Elements(springs)`), against a plain
//! hand-written loop, plus the 1→2 thread speedup on the 316² cloth.
//!
//! Run: `cargo bench --bench step` (release); `SPRINGLAB_BENCH_METHODS=a,b` limits the step
//! group to those methods. External methods (Rapier) are picked up from `springlab::method`.
//! The hand loop is [`springlab::perf::hand_step`]. Ratios with targets are also measured
//! interleaved in one process by `springlab bench-ratios`, which is steadier on a noisy machine.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use springlab::integrate::Stepper;
use springlab::method::MethodOptions;
use springlab::model::{State, System, Vec3};
use springlab::perf::{bench_dt, cloth, hand_step, methods_for};
use std::hint::black_box;
use std::time::{Duration, Instant};

const SIZES: [usize; 3] = [32, 100, 316];

/// Steps timed from one initial state before restarting from it (outside the timing), so
/// conditionally stable methods never time a blown-up state.
const RESTART_EVERY: u64 = 200;

/// The same for methods timed at a frame (1/60 s): implicit Euler and Rapier stay within the
/// first 10 frames of the fall, where every cloth size is solvable.
const RESTART_EVERY_FRAME: u64 = 10;

fn config<'a>(
    c: &'a mut Criterion,
    name: &str,
) -> criterion::BenchmarkGroup<'a, criterion::measurement::WallTime> {
    let mut g = c.benchmark_group(name);
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2));
    g
}

/// Steps `stepper` `iters` times, restarting from `s0` every [`RESTART_EVERY`] steps.
fn timed_steps(
    sys: &System,
    s0: &State,
    stepper: &mut dyn Stepper,
    dt: f64,
    iters: u64,
) -> Duration {
    let mut total = Duration::ZERO;
    let mut s = s0.clone();
    let mut done = 0;
    let restart = if dt > 1e-3 {
        RESTART_EVERY_FRAME
    } else {
        RESTART_EVERY
    };
    while done < iters {
        s.clone_from(s0);
        stepper.reset();
        let batch = restart.min(iters - done);
        let t0 = Instant::now();
        for _ in 0..batch {
            stepper.step(sys, &mut s, dt).expect("step");
        }
        total += t0.elapsed();
        black_box(&s);
        done += batch;
    }
    total
}

fn force_and_hand(c: &mut Criterion) {
    let mut g = config(c, "force");
    for n in SIZES {
        let scene = cloth(n);
        let sys = scene.build();
        let s0 = scene.initial_state();
        g.throughput(Throughput::Elements(sys.springs.len() as u64));
        let mut a = vec![Vec3::zeros(); sys.len()];
        g.bench_function(BenchmarkId::new("accelerations", n), |b| {
            b.iter(|| black_box(sys.accelerations(&s0.x, &s0.v, &mut a)))
        });
        g.bench_function(BenchmarkId::new("hand_loop_step", n), |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                let mut f = vec![Vec3::zeros(); sys.len()];
                let mut done = 0;
                while done < iters {
                    let (mut x, mut v) = (s0.x.clone(), s0.v.clone());
                    let batch = RESTART_EVERY.min(iters - done);
                    let t0 = Instant::now();
                    for _ in 0..batch {
                        hand_step(&sys, &mut x, &mut v, &mut f, 1e-3);
                    }
                    total += t0.elapsed();
                    black_box(&x);
                    done += batch;
                }
                total
            })
        });
    }
    g.finish();
}

fn steps(c: &mut Criterion) {
    let mut g = config(c, "step");
    for n in SIZES {
        let scene = cloth(n);
        let sys = scene.build();
        let s0 = scene.initial_state();
        g.throughput(Throughput::Elements(sys.springs.len() as u64));
        // Rapier (`rapier_impulse`) appears here once registered in `springlab::method`.
        for name in methods_for(&scene).into_iter().filter(|n| selected(n)) {
            let dt = bench_dt(name);
            let mut stepper = springlab::method::create(name, &MethodOptions::default()).unwrap();
            g.bench_function(BenchmarkId::new(name, n), |b| {
                b.iter_custom(|iters| timed_steps(&sys, &s0, stepper.as_mut(), dt, iters))
            });
        }
    }
    g.finish();
}

/// Methods to time: all, or the comma-separated list in `SPRINGLAB_BENCH_METHODS`.
fn selected(name: &str) -> bool {
    std::env::var("SPRINGLAB_BENCH_METHODS").map_or(true, |l| l.split(',').any(|n| n == name))
}

/// Implicit Euler solver statistics at dt = 1/60 over 10 steps from rest (printed, not timed
/// by criterion).
fn implicit_stats(_c: &mut Criterion) {
    if !selected("implicit_euler") {
        return;
    }
    for n in SIZES {
        let scene = cloth(n);
        let springs = scene.build().springs.len();
        let opts = springlab::method::MethodOptions::default();
        match springlab::perf::ratios::implicit_cost(&scene, "implicit_euler", &opts, 1.0 / 60.0, 10)
        {
            Ok(c) => eprintln!(
                "implicit_euler {n}x{n} dt=1/60: {:.2} Newton iterations/step, {:.1} CG iterations/Newton iteration, {:.3} ms/step ({:.1} ns/spring)",
                c.newton_per_step,
                c.linear_per_step / c.newton_per_step.max(f64::MIN_POSITIVE),
                c.seconds_per_step * 1e3,
                c.seconds_per_step * 1e9 / springs as f64
            ),
            Err(why) => eprintln!("implicit_euler {n}x{n} dt=1/60: {why}"),
        }
    }
}

fn threads(c: &mut Criterion) {
    let mut g = config(c, "threads");
    let n = 316;
    let scene = cloth(n);
    let sys = scene.build();
    let s0 = scene.initial_state();
    g.throughput(Throughput::Elements(sys.springs.len() as u64));
    for t in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .unwrap();
        let mut a = vec![Vec3::zeros(); sys.len()];
        g.bench_function(BenchmarkId::new("accelerations", t), |b| {
            b.iter(|| pool.install(|| black_box(sys.accelerations(&s0.x, &s0.v, &mut a))))
        });
        let mut stepper =
            springlab::method::create("symplectic_euler", &MethodOptions::default()).unwrap();
        g.bench_function(BenchmarkId::new("symplectic_euler", t), |b| {
            b.iter_custom(|iters| {
                pool.install(|| timed_steps(&sys, &s0, stepper.as_mut(), 1e-3, iters))
            })
        });
    }
    g.finish();
}

criterion_group!(benches, force_and_hand, steps, implicit_stats, threads);
criterion_main!(benches);
