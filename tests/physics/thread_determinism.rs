//! Whole steps give the same bits with 1 and 2 threads (symplectic Euler, RK4, implicit Euler
//! with its parallel CG, xpbd with its coloured sweep). Oracle: the one-thread run — the tool promises the same bits
//! whatever the thread count.

use springlab::{method, scenario::Scenario};

fn cloth(n: usize) -> Scenario {
    let toml = format!(
        "[world]\ngravity=[0.0,-9.81,0.0]\n[[cloth]]\norigin=[0.0,0.0,0.0]\nsize=[1.0,1.0]\n\
         count=[{n},{n}]\nmass=0.001\nstiffness=200.0\ndamping=0.002\nplane=\"xz\"\n\
         fix=[\"top_left\",\"top_right\"]\n"
    );
    Scenario::from_toml_str(&toml, "cloth.toml").unwrap()
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

#[test]
fn stepping_is_bit_identical_across_thread_counts() {
    // 130²: parallel springs, serial particle loops; 190²: both parallel.
    for n in [130, 190] {
        let scene = cloth(n);
        let sys = scene.build();
        assert!(sys.springs.is_parallel(sys.len()));
        for name in ["symplectic_euler", "rk4", "implicit_euler", "xpbd"] {
            let run = |threads| {
                in_pool(threads, || {
                    let mut stepper = method::create(name, &Default::default()).unwrap();
                    let mut s = scene.initial_state();
                    for _ in 0..3 {
                        stepper.step(&sys, &mut s, 1e-3).unwrap();
                    }
                    s
                })
            };
            let (a, b) = (run(1), run(2));
            for q in 0..a.len() {
                for c in 0..3 {
                    assert_eq!(a.x[q][c].to_bits(), b.x[q][c].to_bits(), "{name} x[{q}]");
                    assert_eq!(a.v[q][c].to_bits(), b.v[q][c].to_bits(), "{name} v[{q}]");
                }
            }
        }
    }
}

/// Implicit Euler with the block IC(0) preconditioner (sequential triangular solves next to
/// the parallel products) gives the same bits with 1 and 2 threads.
#[test]
fn implicit_euler_with_ic0_is_bit_identical_across_thread_counts() {
    use springlab::integrate::{ImplicitEuler, LinearSolver, Stepper};
    let scene = cloth(130);
    let sys = scene.build();
    assert!(sys.springs.is_parallel(sys.len()));
    let run = |threads| {
        in_pool(threads, || {
            let mut ie = ImplicitEuler::default();
            ie.newton.settings.solver = LinearSolver::BlockIc0Cg;
            let mut s = scene.initial_state();
            for _ in 0..3 {
                ie.step(&sys, &mut s, 1.0 / 60.0).unwrap();
            }
            s
        })
    };
    let (a, b) = (run(1), run(2));
    for q in 0..a.len() {
        for c in 0..3 {
            assert_eq!(a.x[q][c].to_bits(), b.x[q][c].to_bits(), "x[{q}]");
            assert_eq!(a.v[q][c].to_bits(), b.v[q][c].to_bits(), "v[{q}]");
        }
    }
}
