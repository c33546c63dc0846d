//! No allocation inside a step: a counting global allocator (this test binary only) counts
//! every allocation made by the stepping thread and its rayon helpers while every native method steps, after a warm-up
//! step that sizes its scratch buffers. Covers the serial spring loop (small scenes), the
//! parallel path (a cloth above `PARALLEL_MIN_SPRINGS`), gravity, drag and dampers.

mod common;

use springlab::model::PARALLEL_MIN_SPRINGS;
use springlab::scenario::Scenario;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

struct Counting;

static COUNTING: AtomicBool = AtomicBool::new(false);
static ALLOCS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    /// Set on the measuring pool's threads (the stepping thread and its helpers): the test
    /// harness's own threads may allocate at any time and are not counted.
    static COUNTED: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

fn counted() -> bool {
    COUNTING.load(Ordering::SeqCst) && COUNTED.with(|c| c.get())
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        if counted() {
            ALLOCS.fetch_add(1, Ordering::SeqCst);
        }
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        if counted() {
            ALLOCS.fetch_add(1, Ordering::SeqCst);
        }
        unsafe { System.realloc(p, l, n) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made by `steps` steps of `name` on `scene` after one warm-up step, stepping on a
/// rayon worker thread. (Called from outside a pool, each parallel loop is pushed onto
/// rayon's global injector queue, which allocates one block per 63 pushes: the scheduler's
/// cost, amortized, not the step's. Inside the pool the loops go to the worker's own deque.)
/// One pool for the whole test: a pool dropped between measurements would wind its threads
/// down (and free and allocate) during the next one.
fn allocations(scene: &Scenario, name: &str, h: f64, steps: usize) -> Option<usize> {
    static POOL: std::sync::OnceLock<rayon::ThreadPool> = std::sync::OnceLock::new();
    let pool = POOL.get_or_init(|| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .start_handler(|_| COUNTED.with(|c| c.set(true)))
            .build()
            .unwrap()
    });
    pool.install(|| allocations_here(scene, name, h, steps))
}

fn allocations_here(scene: &Scenario, name: &str, h: f64, steps: usize) -> Option<usize> {
    let sys = scene.build();
    let mut stepper = common::stepper(name);
    if stepper.check(&sys).is_err() {
        return None;
    }
    let mut s = scene.initial_state();
    stepper.step(&sys, &mut s, h).expect("warm-up step");
    stepper.step(&sys, &mut s, h).expect("warm-up step");
    // Three windows, the fewest allocations kept: a pool thread's first work steal registers
    // it once with crossbeam's epoch collector (rayon's one-time cost, at a moment the
    // scheduler picks); a step that allocated would do so in every window.
    let mut fewest = usize::MAX;
    for _ in 0..3 {
        ALLOCS.store(0, Ordering::SeqCst);
        COUNTING.store(true, Ordering::SeqCst);
        for _ in 0..steps {
            stepper.step(&sys, &mut s, h).expect("step");
        }
        COUNTING.store(false, Ordering::SeqCst);
        fewest = fewest.min(ALLOCS.load(Ordering::SeqCst));
    }
    assert!(s.first_non_finite().is_none(), "{name}");
    Some(fewest)
}

// One test function: the counter is global, and tests in one binary run concurrently.
#[test]
fn no_method_allocates_inside_a_step() {
    let damped_cloth = |n: usize| {
        Scenario::from_toml_str(
            &format!(
                "[world]\ngravity=[0.0,-9.81,0.0]\ndrag=0.01\n[[cloth]]\norigin=[0.0,0.0,0.0]\n\
                 size=[1.0,1.0]\ncount=[{n},{n}]\nmass=0.001\nstiffness=200.0\ndamping=0.002\n\
                 bend_stiffness=20.0\nfix=[\"top_left\",\"top_right\"]\n"
            ),
            "cloth.toml",
        )
        .unwrap()
    };
    let small = damped_cloth(8);
    let large = springlab::perf::cloth(130);
    assert!(large.build().springs.len() >= PARALLEL_MIN_SPRINGS);
    let osc = common::oscillator(4.0, 0.3, 0.1, 0.0);
    let mut checked = 0;
    let native = springlab::method::Registry::builtin().native_names();
    for name in &native {
        for (label, scene, steps) in [
            ("oscillator", &osc, 50),
            ("cloth 8x8", &small, 20),
            ("cloth 130x130", &large, 3),
        ] {
            if let Some(n) = allocations(scene, name, 1e-3, steps) {
                assert_eq!(n, 0, "{name} on {label}: {n} allocations in {steps} steps");
                checked += 1;
            }
        }
    }
    // analytic runs the oscillator only; every other method runs all three scenes.
    assert_eq!(checked, 3 * (native.len() - 1) + 1);
}
