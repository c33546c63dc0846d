//! Validated obstacle and collision settings: what the scene file asked for, in model units,
//! before any parry shape is built (the Rapier engines read the same definitions).

use crate::model::Vec3;

/// The geometry of one obstacle, in world coordinates.
#[derive(Debug, Clone, PartialEq)]
pub enum ShapeDef {
    /// The half-space behind a plane through `point` with unit outward `normal`.
    Plane {
        /// A point on the plane (m).
        point: Vec3,
        /// Unit outward normal.
        normal: Vec3,
    },
    /// A solid sphere.
    Sphere {
        /// Centre (m).
        center: Vec3,
        /// Radius (m, > 0).
        radius: f64,
    },
    /// A solid box.
    Box {
        /// Centre (m).
        center: Vec3,
        /// Half side lengths along the box's own axes (m, each > 0).
        half_extents: Vec3,
        /// Orientation as an axis-angle vector (axis × angle in rad; zero: axis-aligned).
        rotation: Vec3,
    },
    /// A solid capsule: all points within `radius` of the segment `a`–`b`.
    Capsule {
        /// First end of the axis (m).
        a: Vec3,
        /// Second end of the axis (m).
        b: Vec3,
        /// Radius (m, > 0).
        radius: f64,
    },
    /// A triangle mesh in world coordinates. Closed (every edge shared by two triangles): a
    /// solid with an inside, whatever its winding (an inside-out one is turned outward). Open:
    /// a two-sided thin sheet, solid on neither side (see [`crate::collide::mesh`]).
    Mesh {
        /// Vertex positions (m).
        vertices: Vec<Vec3>,
        /// Triangles as vertex indices (counter-clockwise seen from outside by convention).
        triangles: Vec<[u32; 3]>,
    },
}

/// Which kind of shape an obstacle is, as a value (documents spell it as scene files do).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ShapeKind {
    /// A half-space.
    Plane,
    /// A ball.
    Sphere,
    /// An oriented box.
    Box,
    /// A capsule.
    Capsule,
    /// A triangle mesh.
    Mesh,
}

impl ShapeKind {
    /// The name as written in scene files.
    pub fn name(self) -> &'static str {
        match self {
            ShapeKind::Plane => "plane",
            ShapeKind::Sphere => "sphere",
            ShapeKind::Box => "box",
            ShapeKind::Capsule => "capsule",
            ShapeKind::Mesh => "mesh",
        }
    }
}

impl std::fmt::Display for ShapeKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.name())
    }
}

impl ShapeDef {
    /// The shape's kind.
    pub fn kind(&self) -> ShapeKind {
        match self {
            ShapeDef::Plane { .. } => ShapeKind::Plane,
            ShapeDef::Sphere { .. } => ShapeKind::Sphere,
            ShapeDef::Box { .. } => ShapeKind::Box,
            ShapeDef::Capsule { .. } => ShapeKind::Capsule,
            ShapeDef::Mesh { .. } => ShapeKind::Mesh,
        }
    }
}

/// One static obstacle with its contact coefficients.
#[derive(Debug, Clone, PartialEq)]
pub struct ObstacleDef {
    /// Geometry.
    pub shape: ShapeDef,
    /// Coefficient of restitution in [0, 1] (default 0).
    pub restitution: f64,
    /// Coulomb friction coefficient ≥ 0 (default 0).
    pub friction: f64,
}

/// Where the penalty dashpot's damping comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PenaltyDamping {
    /// A fixed dashpot coefficient c (N·s/m) for every contact.
    Coefficient(f64),
    /// One restitution for every contact: ζ = −ln e / √(π² + ln² e), c = 2ζ√(k m).
    Restitution(f64),
    /// Each obstacle's own `restitution`, converted as in [`PenaltyDamping::Restitution`].
    PerObstacle,
}

/// How contacts are resolved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Response {
    /// After each step: put the particle back on the surface along the normal, reflect the
    /// normal velocity with restitution and apply a Coulomb friction impulse (at most μ × the
    /// normal velocity change) to the tangential part; when friction acted, the step's end
    /// moves by h/2 × friction's velocity change (exact under constant friction for every
    /// method, whose own travel under the other forces is kept), and a particle friction
    /// stops travels h·v_t,start/2 (a stuck particle does not creep).
    Impulse,
    /// A spring-dashpot force on the penetration depth (a force term every method sees).
    Penalty {
        /// Contact spring stiffness k (N/m).
        stiffness: f64,
        /// Dashpot setting.
        damping: PenaltyDamping,
    },
    /// After each step: project positions out along the normal and cut the step's tangential
    /// displacement by at most μ·Δv_n·h (position-level Coulomb friction, Δv_n the normal
    /// velocity change (1 + e)·approach speed, so the cone is the same for every method);
    /// the velocity gets the same restitution and at most μ·Δv_n of tangential loss.
    Projection,
}

/// Which contact response a scene uses, without its settings (documents spell it as scene
/// files do).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ResponseKind {
    /// [`Response::Impulse`].
    Impulse,
    /// [`Response::Penalty`].
    Penalty,
    /// [`Response::Projection`].
    Projection,
}

impl ResponseKind {
    /// The name as written in scene files.
    pub fn name(self) -> &'static str {
        match self {
            ResponseKind::Impulse => "impulse",
            ResponseKind::Penalty => "penalty",
            ResponseKind::Projection => "projection",
        }
    }
}

impl std::fmt::Display for ResponseKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.name())
    }
}

impl Response {
    /// The response's kind.
    pub fn kind(&self) -> ResponseKind {
        match self {
            Response::Impulse => ResponseKind::Impulse,
            Response::Penalty { .. } => ResponseKind::Penalty,
            Response::Projection => ResponseKind::Projection,
        }
    }

    /// The response's name as written in scene files.
    pub fn name(&self) -> &'static str {
        self.kind().name()
    }
}

/// A scene's obstacles and how contacts with them are resolved (present only with obstacles).
#[derive(Debug, Clone, PartialEq)]
pub struct CollisionSetup {
    /// The obstacles, in file order.
    pub obstacles: Vec<ObstacleDef>,
    /// The contact response.
    pub response: Response,
}

/// Damping ratio of a linear spring-dashpot contact that gives restitution `e` (contact ends
/// when the penetration returns to zero): ζ = −ln e / √(π² + ln² e); 1 (critical) for e = 0.
pub fn damping_ratio_for_restitution(e: f64) -> f64 {
    if e <= 0.0 {
        return 1.0;
    }
    let l = e.ln();
    -l / (std::f64::consts::PI.powi(2) + l * l).sqrt()
}

/// Restitution of a linear spring-dashpot contact with damping ratio ζ (contact ends when the
/// penetration returns to zero): e = exp(−ζπ/√(1−ζ²)) for ζ < 1, 0 otherwise.
pub fn restitution_for_damping_ratio(zeta: f64) -> f64 {
    if zeta >= 1.0 {
        0.0
    } else {
        (-zeta * std::f64::consts::PI / (1.0 - zeta * zeta).sqrt()).exp()
    }
}
