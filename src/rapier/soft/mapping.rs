//! A scene as Rapier soft bodies: which particles form each body, the rest pose its edges are
//! built in, each edge's softness, and what the soft bodies cannot express (refused with the
//! reason). Pure data, computed from the scene alone.

use crate::model::{System, Vec3};

/// Relative tolerance within which a placement realises a spring's rest length.
const REST_TOLERANCE: f64 = 1e-9;

/// One edge of a soft body: two local particle indices and the spring it stands for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SoftEdge {
    /// Local indices of the two particles.
    pub ends: [u32; 2],
    /// Natural frequency of the edge (Hz): √(k/m_eff)/2π.
    pub frequency: f64,
    /// Damping ratio of the edge: c/(2√(k·m_eff)).
    pub damping_ratio: f64,
}

/// One soft body: a connected set of particles and the springs between them.
#[derive(Debug, Clone, PartialEq)]
pub struct SoftBodyPlan {
    /// The scene's particle index of each local particle.
    pub particles: Vec<usize>,
    /// Positions at which every edge has its spring's rest length (the build pose).
    pub rest: Vec<Vec3>,
    /// The body's edges.
    pub edges: Vec<SoftEdge>,
    /// Linear damping rate of every particle (1/s): the scene's drag over the particles' mass.
    pub damping: f64,
    /// Contact radius of the body's edges (m): the largest radius of its particles.
    pub radius: f64,
}

/// The soft bodies of a scene (each lists the scene particles it holds).
#[derive(Debug, Clone, PartialEq)]
pub struct SoftPlan {
    /// The bodies.
    pub bodies: Vec<SoftBodyPlan>,
    /// True when the scene has obstacles (the bodies then collide through their edges).
    pub collides: bool,
}

/// One spring of the scene as an edge: ends, stiffness (N/m), damper (N·s/m), rest length (m).
struct Spring {
    a: usize,
    b: usize,
    k: f64,
    c: f64,
    l0: f64,
}

/// The scene's springs and compliant rods, or why one has no soft-body edge.
fn springs(sys: &System) -> Result<Vec<Spring>, String> {
    let sp = &sys.springs;
    let mut out: Vec<Spring> = (0..sp.len())
        .map(|s| Spring {
            a: sp.i[s] as usize,
            b: sp.j[s] as usize,
            k: sp.k[s],
            c: sp.c[s],
            l0: sp.l0[s],
        })
        .collect();
    for dc in &sys.constraints {
        if dc.compliance <= 0.0 {
            return Err("a rigid rod has no soft-body edge (an edge is a spring of finite stiffness); rapier_impulse holds it as a rope joint".into());
        }
        out.push(Spring {
            a: dc.i,
            b: dc.j,
            k: 1.0 / dc.compliance,
            c: 0.0,
            l0: dc.length,
        });
    }
    if let Some(s) = out.iter().find(|s| s.k <= 0.0 && s.c > 0.0) {
        return Err(format!(
            "the damper between particles {} and {} has no spring: a soft-body edge's damping is a ratio of its spring's",
            s.a, s.b
        ));
    }
    if let Some(s) = out.iter().find(|s| s.k > 0.0 && s.l0 <= 0.0) {
        return Err(format!(
            "the spring between particles {} and {} has rest length 0: a soft-body edge's direction is undefined at zero length",
            s.a, s.b
        ));
    }
    out.retain(|s| s.k > 0.0 && s.a != s.b);
    Ok(out)
}

/// The edge of spring `s`: Rapier normalises softness by the edge's effective mass
/// m_eff = 1/(1/m_a + 1/m_b) (a pinned end has 1/m = 0).
fn edge(sys: &System, s: &Spring, ends: [u32; 2]) -> SoftEdge {
    let w = |p: usize| if sys.free[p] { 1.0 / sys.mass[p] } else { 0.0 };
    let inv = w(s.a) + w(s.b);
    let m_eff = if inv > 0.0 { 1.0 / inv } else { f64::INFINITY };
    let omega = (s.k / m_eff).sqrt();
    SoftEdge {
        ends,
        frequency: omega / std::f64::consts::TAU,
        damping_ratio: if m_eff.is_finite() {
            s.c / (2.0 * (s.k * m_eff).sqrt())
        } else {
            0.0
        },
    }
}

/// Connected sets of particles over `springs`, each in first-seen order.
fn components(n: usize, springs: &[Spring]) -> Vec<Vec<usize>> {
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut p: usize) -> usize {
        while parent[p] != p {
            parent[p] = parent[parent[p]];
            p = parent[p];
        }
        p
    }
    for s in springs {
        let (ra, rb) = (root(&mut parent, s.a), root(&mut parent, s.b));
        if ra != rb {
            parent[ra.max(rb)] = ra.min(rb);
        }
    }
    let mut of_root = vec![usize::MAX; n];
    let mut out: Vec<Vec<usize>> = Vec::new();
    for p in 0..n {
        let r = root(&mut parent, p);
        if of_root[r] == usize::MAX {
            of_root[r] = out.len();
            out.push(Vec::new());
        }
        out[of_root[r]].push(p);
    }
    out
}

/// A pose of `particles` in which every spring has its rest length: the current positions when
/// they already do; else each particle placed from its neighbour along a spanning tree, at the
/// rest length in the current direction. `None` when a loop's springs cannot all be at rest.
fn rest_pose(
    x: &[Vec3],
    particles: &[usize],
    local: &[usize],
    springs: &[&Spring],
) -> Option<Vec<Vec3>> {
    let at_rest = |p: &[Vec3], s: &Spring| {
        let len = (p[local[s.b]] - p[local[s.a]]).norm();
        (len - s.l0).abs() <= REST_TOLERANCE * s.l0
    };
    let current: Vec<Vec3> = particles.iter().map(|&p| x[p]).collect();
    if springs.iter().all(|s| at_rest(&current, s)) {
        return Some(current);
    }
    let mut adj: Vec<Vec<(usize, usize)>> = vec![Vec::new(); particles.len()];
    for (k, s) in springs.iter().enumerate() {
        adj[local[s.a]].push((local[s.b], k));
        adj[local[s.b]].push((local[s.a], k));
    }
    let mut pose = current.clone();
    let mut placed = vec![false; particles.len()];
    placed[0] = true;
    let mut queue = std::collections::VecDeque::from([0usize]);
    while let Some(u) = queue.pop_front() {
        for &(v, k) in &adj[u] {
            if !placed[v] {
                let d = current[v] - current[u];
                let dir = if d.norm() > 0.0 {
                    d / d.norm()
                } else {
                    Vec3::x()
                };
                pose[v] = pose[u] + dir * springs[k].l0;
                placed[v] = true;
                queue.push_back(v);
            }
        }
    }
    springs.iter().all(|s| at_rest(&pose, s)).then_some(pose)
}

/// The soft bodies of `sys` with particles at `x`, or why its model has none. Without `x` (a
/// check before any state exists) every refusal but the rest pose's is made, and each body's
/// `rest` is left empty.
pub fn soft_plan(sys: &System, x: Option<&[Vec3]>) -> Result<SoftPlan, String> {
    let springs = springs(sys)?;
    let collides = crate::collide::of(sys).is_some();
    let mut bodies = Vec::new();
    let mut local = vec![0usize; sys.len()];
    let sets = components(sys.len(), &springs);
    let mut set_of = vec![0usize; sys.len()];
    for (k, set) in sets.iter().enumerate() {
        for &p in set {
            set_of[p] = k;
        }
    }
    let mut springs_of: Vec<Vec<&Spring>> = vec![Vec::new(); sets.len()];
    for s in &springs {
        springs_of[set_of[s.a]].push(s);
    }
    for (particles, mine) in sets.into_iter().zip(springs_of) {
        let free: Vec<usize> = particles.iter().copied().filter(|&p| sys.free[p]).collect();
        if free.is_empty() {
            continue; // fixed anchors alone: nothing moves
        }
        if collides && particles.len() == 1 {
            return Err(format!(
                "particle {} has no spring: a soft body meets obstacles through its edges; rapier_impulse models a lone particle as a ball",
                particles[0]
            ));
        }
        for (l, &p) in particles.iter().enumerate() {
            local[p] = l;
        }
        let rest = match x {
            None => Vec::new(),
            Some(x) => rest_pose(x, &particles, &local, &mine).ok_or_else(|| {
                format!(
                    "the springs among particles {}..={} cannot all be at their rest lengths at once (a loop of pre-stretched springs): a soft-body edge takes its rest length from the particles' positions when the body is built",
                    particles[0],
                    particles[particles.len() - 1]
                )
            })?,
        };
        let damping = match sys.drag {
            None => 0.0,
            Some(c) => {
                let m = sys.mass[free[0]];
                if free.iter().any(|&p| (sys.mass[p] - m).abs() > 1e-12 * m) {
                    return Err("drag on particles of unequal mass in one connected set: a soft body's particles share one linear damping rate, so −c·v cannot be set per particle".into());
                }
                c / m
            }
        };
        let edges = mine
            .iter()
            .map(|s| edge(sys, s, [local[s.a] as u32, local[s.b] as u32]))
            .collect();
        let radius = particles.iter().map(|&p| sys.radius[p]).fold(0.0, f64::max);
        bodies.push(SoftBodyPlan {
            particles,
            rest,
            edges,
            damping,
            radius,
        });
    }
    Ok(SoftPlan { bodies, collides })
}
