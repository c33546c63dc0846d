//! Rapier 0.36's soft bodies as methods: the scene's particles as soft-body particles, its
//! springs as distance edges, each edge's softness set from the spring's stiffness, damper and
//! the two masses, so a game programmer's Rapier cloth or rope runs beside the other methods.
//!
//! Mapping ([`mapping`]): one soft body per connected set of springs; fixed particles pinned;
//! gravity as Rapier's; drag −c·v as the body's linear damping c/m (one rate per body, so the
//! particles of a body with drag must share one mass); obstacles as fixed colliders, touched
//! through the body's edges as a wire of the particles' radius. An edge of stiffness k and
//! damper c between masses m_a and m_b gets natural frequency √(k/m_eff)/2π and damping ratio
//! c/(2√(k·m_eff)), m_eff = m_a·m_b/(m_a + m_b) (the free mass when one end is pinned): Rapier
//! normalises an edge's softness by that effective mass, so the edge is the spring k, c.
//!
//! Two solvers ([`SoftSolver`]): `rapier_soft` sweeps the edges as soft constraints by
//! coloured Gauss-Seidel once per substep; `rapier_soft_fem` solves them as elastic elements
//! by implicit Euler over the whole body each substep (Rapier's FEM solver, which treats a
//! distance edge as the energy ½k(|d| − L)² with k = ω²·m_eff and Rayleigh damping 2ζ/ω·k,
//! the same spring and damper).

mod mapping;
mod stepper;

pub use mapping::{soft_plan, SoftPlan};
pub use stepper::{SoftSolver, SoftStepper, SOFT, SOFT_FEM};
