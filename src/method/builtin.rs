//! springlab's built-in methods and their facts: the registry's one entry per method (a new
//! method adds its stepper file in `src/integrate/` and one entry here). Orders and limits are the textbook ones (Hairer, Nørsett & Wanner, *Solving
//! ODEs I*; Hairer, Lubich & Wanner, *Geometric Numerical Integration*).

use super::info::{CostUnit, MethodInfo, Order, StabilityTheory};
use super::options::{
    MethodOptions, ITERATIONS, LINEAR_SOLVER, MAX_NEWTON, XPBD_ITERATIONS, XPBD_SUBSTEPS,
};
use super::registry::{Method, Registry};
use crate::integrate::{
    Analytic, BackwardEuler, Bdf2Rule, ExplicitEuler, Implicit, LinearSolver, LinearizedEuler,
    Midpoint, PositionVerlet, Rattle, Rule, RungeKutta, Stepper, SymplecticEuler, Tableau,
    VelocityVerlet, VerletConstraints, Xpbd,
};
use crate::rapier::{
    Mode, RapierStepper, SoftSolver, SoftStepper, IMPULSE, MULTIBODY, SOFT, SOFT_FEM,
};

/// A native method that solves a system each step ([`MethodInfo::implicit`]) by Newton's
/// method on the shared implicit core, whose linear solver and iteration cap it reads
/// ([`LINEAR_SOLVER`], [`MAX_NEWTON`]).
const fn implicit(name: &'static str, order: u32, summary: &'static str) -> MethodInfo {
    MethodInfo {
        implicit: true,
        options: &[LINEAR_SOLVER, MAX_NEWTON],
        ..MethodInfo::native(name, order, summary)
    }
}

/// A fresh implicit method of rule `R` with the linear solver and Newton cap `opts` give.
fn on_core<R: Rule + Default + Send + 'static>(opts: &MethodOptions) -> Box<dyn Stepper> {
    let mut s = Implicit::<R>::default();
    let set = &mut s.newton_mut().settings;
    set.solver = LinearSolver::from_name(&opts.choice(&LINEAR_SOLVER)).unwrap_or_default();
    set.max_newton = opts.count(&MAX_NEWTON);
    Box::new(s)
}

const fn engine(name: &'static str, summary: &'static str) -> MethodInfo {
    MethodInfo {
        stability: StabilityTheory::Empirical,
        cost: CostUnit::ModelledOnly,
        engine: true,
        contacts: true,
        splits_frames: true,
        // A frame of h is N substeps of symplectic Euler with backward-Euler joint springs
        // (see `rapier::scheme`): first order.
        ..MethodInfo::native(name, 1, summary)
    }
}

/// Each built-in method's chart colour: eighteen colours no two alike, the closed form black,
/// so every method keeps its own line in every chart.
const COLOURS: [(&str, [u8; 3]); 18] = [
    ("explicit_euler", [214, 39, 40]),
    ("symplectic_euler", [31, 119, 180]),
    ("implicit_euler", [44, 160, 44]),
    ("linear_implicit_euler", [127, 201, 127]),
    ("implicit_midpoint", [23, 190, 207]),
    ("bdf2", [0, 128, 128]),
    ("rk2", [255, 127, 14]),
    ("rk4", [148, 103, 189]),
    ("velocity_verlet", [140, 86, 75]),
    ("position_verlet", [204, 153, 0]),
    ("verlet_constraints", [227, 119, 194]),
    ("xpbd", [188, 189, 34]),
    ("rattle", [170, 0, 170]),
    ("analytic", [0, 0, 0]),
    ("rapier_impulse", [128, 0, 0]),
    ("rapier_multibody", [0, 0, 128]),
    ("rapier_soft", [250, 128, 114]),
    ("rapier_soft_fem", [100, 110, 160]),
];

/// The built-in methods, in the order reports list them, each with its colour ([`COLOURS`]).
pub fn methods() -> Vec<Method> {
    let mut all = table();
    for m in &mut all {
        m.info.colour = COLOURS
            .iter()
            .find(|(n, _)| *n == m.info.name)
            .map(|(_, c)| *c);
    }
    all
}

/// The built-in methods in report order: one entry per method, each its facts and
/// constructor.
fn table() -> Vec<Method> {
    [
        euler_and_implicit(),
        runge_kutta_and_verlet(),
        constrained_and_exact(),
        engines(),
    ]
    .into_iter()
    .flatten()
    .collect()
}

/// Euler's explicit and symplectic forms, and the implicit methods.
fn euler_and_implicit() -> Vec<Method> {
    vec![
        Method::new(
            MethodInfo::native(
                "explicit_euler",
                1,
                "forward Euler; unstable on undamped oscillators at every step",
            ),
            |_| Box::new(ExplicitEuler::default()),
        ),
        Method::new(
            MethodInfo {
                aliases: &["semi_implicit_euler"],
                ..MethodInfo::native(
                    "symplectic_euler",
                    1,
                    "semi-implicit Euler (kick then drift), symplectic; stable for hω < 2",
                )
            },
            |_| Box::new(SymplecticEuler::default()),
        ),
        Method::new(
            implicit(
                "implicit_euler",
                1,
                "backward Euler, Newton + block-Jacobi CG; stable at any step, damps",
            ),
            on_core::<BackwardEuler>,
        ),
        Method::new(
            implicit(
                "linear_implicit_euler",
                1,
                "Baraff-Witkin linearly implicit Euler: one CG solve per step; stable at any step, damps",
            ),
            on_core::<LinearizedEuler>,
        ),
        Method::new(
            implicit(
                "implicit_midpoint",
                2,
                "implicit midpoint, Newton + block-Jacobi CG; symplectic, stable at any step, keeps linear-spring energy",
            ),
            on_core::<Midpoint>,
        ),
        Method::new(
            MethodInfo {
                recurrence_steps: 2,
                ..implicit(
                    "bdf2",
                    2,
                    "two-step BDF (backward-Euler start), Newton + block-Jacobi CG; stable at any step, damps",
                )
            },
            on_core::<Bdf2Rule>,
        ),
    ]
}

/// The explicit Runge–Kutta and Störmer–Verlet methods.
fn runge_kutta_and_verlet() -> Vec<Method> {
    vec![
        Method::new(
            MethodInfo::native(
                "rk2",
                2,
                "explicit midpoint Runge-Kutta; unstable on undamped oscillators",
            ),
            |_| Box::new(RungeKutta::new(Tableau::rk2())),
        ),
        Method::new(
            MethodInfo::native(
                "rk4",
                4,
                "classic Runge-Kutta; stable for hω < 2√2 on oscillators",
            ),
            |_| Box::new(RungeKutta::new(Tableau::rk4())),
        ),
        Method::new(
            MethodInfo::native(
                "velocity_verlet",
                2,
                "kick-drift-kick Störmer-Verlet, symplectic; stable for hω < 2",
            ),
            |_| Box::new(VelocityVerlet::default()),
        ),
        Method::new(
            MethodInfo::native(
                "position_verlet",
                2,
                "two-step Störmer form, symplectic; stable for hω < 2",
            ),
            |_| Box::new(PositionVerlet::default()),
        ),
    ]
}

/// The constraint methods and the closed form.
fn constrained_and_exact() -> Vec<Method> {
    vec![
        Method::new(
            MethodInfo {
                options: &[ITERATIONS],
                ..MethodInfo::native(
                    "verlet_constraints",
                    1,
                    "Verlet + Jakobsen/XPBD projection of rigid constraints (games' ropes and cloth)",
                )
            },
            |o| Box::new(VerletConstraints::new(o.count(&ITERATIONS))),
        ),
        Method::new(
            MethodInfo {
                // XPBD is a projection, not a one-step map of an ODE right-hand side: the
                // linear spectral-radius theory does not describe it, so its stability is
                // found by the empirical search on the scene. It never evaluates the spring
                // force model (springs become constraints): costed in wall time.
                stability: StabilityTheory::Empirical,
                cost: CostUnit::ModelledOnly,
                options: &[XPBD_SUBSTEPS, XPBD_ITERATIONS],
                ..MethodInfo::native(
                    "xpbd",
                    1,
                    "XPBD (Macklin et al. 2016): springs as compliant constraints with XPBD damping, --xpbd-substeps x --xpbd-iterations Gauss-Seidel",
                )
            },
            |o| Box::new(Xpbd::new(o.count(&XPBD_SUBSTEPS), o.count(&XPBD_ITERATIONS))),
        ),
        Method::new(
            MethodInfo::native(
                "rattle",
                2,
                "velocity Verlet with SHAKE/RATTLE rigid constraints, symplectic; stable for hω < 2",
            ),
            |_| Box::new(Rattle::default()),
        ),
        Method::new(
            MethodInfo {
                order: Order::Exact,
                stability: StabilityTheory::Unconditional,
                cost: CostUnit::ModelledOnly,
                ..MethodInfo::native(
                    "analytic",
                    1,
                    "exact closed form for independent damped springs on fixed anchors",
                )
            },
            |_| Box::new(Analytic::default()),
        ),
    ]
}

/// The Rapier engines.
fn engines() -> Vec<Method> {
    vec![
        Method::new(
            engine(
                IMPULSE,
                "Rapier 0.36 (f64): a body per particle, springs as force-based joint motors",
            ),
            |o| Box::new(RapierStepper::new(Mode::Impulse, o.substeps)),
        ),
        Method::new(
            engine(
                MULTIBODY,
                "Rapier 0.36 (f64): multibody trees, loop-closing edges as impulse joints",
            ),
            |o| Box::new(RapierStepper::new(Mode::Multibody, o.substeps)),
        ),
        Method::new(
            engine(
                SOFT,
                "Rapier 0.36 (f64) soft bodies: springs as soft-body edges, coloured Gauss-Seidel once per substep",
            ),
            |o| Box::new(SoftStepper::new(SoftSolver::Constraints, o.substeps)),
        ),
        Method::new(
            engine(
                SOFT_FEM,
                "Rapier 0.36 (f64) soft bodies, FEM solver: springs as elastic edges, implicit Euler over the body each substep",
            ),
            |o| Box::new(SoftStepper::new(SoftSolver::Fem, o.substeps)),
        ),
    ]
}

impl Registry {
    /// springlab's native schemes and the Rapier engines.
    pub fn builtin() -> Self {
        static BUILTIN: std::sync::OnceLock<Registry> = std::sync::OnceLock::new();
        BUILTIN
            .get_or_init(|| {
                methods()
                    .into_iter()
                    .try_fold(Registry::empty(), Registry::with)
                    .expect("built-in methods have consistent facts")
            })
            .clone()
    }
}

#[cfg(test)]
mod colour_tests {
    use super::*;

    // Oracle: the definition of a legend: every built-in method has a colour, no two share
    // one, and the colour table names only built-in methods.
    #[test]
    fn every_built_in_method_has_its_own_colour() {
        let all = methods();
        let mut seen: Vec<[u8; 3]> = Vec::new();
        for m in &all {
            let c = m
                .info
                .colour
                .unwrap_or_else(|| panic!("{} has no colour", m.info.name));
            assert!(!seen.contains(&c), "{} shares {c:?}", m.info.name);
            seen.push(c);
        }
        for (n, _) in COLOURS {
            assert!(all.iter().any(|m| m.info.name == n), "{n} is not a method");
        }
    }
}
