//! Obstacles as parry shapes at their poses, a broad phase over them, and the per-particle
//! queries every response uses: signed distance, outward normal and contact point by point
//! projection, and swept (ray) tests between steps.
//!
//! Why point projection: in parry 0.31, `query::contact` with a ball first and a half-space
//! second returns wrong distances (see `tests/physics/collide_shapes.rs`); projecting the particle
//! centre and subtracting its radius is exact for every shape and needs no ball shape at all.

use super::counter::{count_build, count_query};
use super::def::{ObstacleDef, ShapeDef};
use crate::model::Vec3;
use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};
use parry3d_f64::query::Ray;
use parry3d_f64::shape::{SharedShape, TriMeshFlags};

/// nalgebra → glam.
pub(crate) fn to_g(v: &Vec3) -> Vector {
    Vector::new(v.x, v.y, v.z)
}
/// glam → nalgebra.
pub(crate) fn from_g(v: Vector) -> Vec3 {
    Vec3::new(v.x, v.y, v.z)
}

/// One obstacle as parry sees it.
#[derive(Clone)]
pub struct Obstacle {
    /// The parry shape in its local frame.
    pub shape: SharedShape,
    /// Its pose in the world.
    pub pose: Pose,
    /// Coefficient of restitution.
    pub restitution: f64,
    /// Coulomb friction coefficient.
    pub friction: f64,
    /// Shape kind.
    pub kind: super::def::ShapeKind,
    /// An open mesh: a two-sided thin sheet with no inside (see [`super::mesh`]).
    pub two_sided: bool,
}

impl std::fmt::Debug for Obstacle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let s = &self.shape;
        // The shape's own dimensions (and a mesh's vertices and triangles), so two obstacles
        // that differ print differently.
        let dims = if let Some(b) = s.as_ball() {
            format!("{b:?}")
        } else if let Some(c) = s.as_cuboid() {
            format!("{c:?}")
        } else if let Some(c) = s.as_capsule() {
            format!("{c:?}")
        } else if let Some(h) = s.as_halfspace() {
            format!("{h:?}")
        } else if let Some(m) = s.as_trimesh() {
            format!("{:?} {:?}", m.vertices(), m.indices())
        } else {
            format!("{:?}", s.compute_local_aabb())
        };
        f.debug_struct("Obstacle")
            .field("kind", &self.kind)
            .field("shape", &dims)
            .field("pose", &self.pose)
            .field("restitution", &self.restitution)
            .field("friction", &self.friction)
            .field("two_sided", &self.two_sided)
            .finish()
    }
}

/// A particle's relation to one obstacle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// Obstacle index (file order).
    pub obstacle: usize,
    /// Signed distance of the particle centre to the surface (m, negative inside).
    pub distance: f64,
    /// `distance − radius`: the gap between the particle's surface and the obstacle
    /// (negative: penetration depth).
    pub gap: f64,
    /// Unit outward surface normal at the contact point.
    pub normal: Vec3,
    /// Closest point on the obstacle's surface.
    pub point: Vec3,
}

/// Where a straight path first enters an obstacle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepHit {
    /// Obstacle index.
    pub obstacle: usize,
    /// Fraction of the path travelled at the hit, in (0, 1].
    pub toi: f64,
    /// Hit point on the surface.
    pub point: Vec3,
    /// Unit outward normal there (facing the path's start).
    pub normal: Vec3,
}

/// Relative clearance (× (1 + |x|) m) at which a response leaves a particle off a two-sided
/// sheet, on the side it came from: a point particle lying exactly on a sheet would have no
/// side, and its next path could not tell leaving from crossing.
pub const SHEET_CLEARANCE: f64 = 1e-9;

/// Static obstacles with a broad phase built once: a parry [`Bvh`] over the bounded
/// obstacles' AABBs (a plain scan of the AABBs when there are fewer than
/// `BVH_MIN_OBSTACLES`, 8); unbounded ones (planes) are always tested.
#[derive(Debug)]
pub struct ObstacleSet {
    obstacles: Vec<Obstacle>,
    /// Indices of unbounded obstacles (half-spaces).
    unbounded: Vec<usize>,
    /// BVH over bounded obstacles; leaf data = index into `bounded`.
    bvh: Bvh,
    /// Indices of bounded obstacles, increasing.
    bounded: Vec<usize>,
    /// The bounded obstacles' AABBs, the BVH's leaves, in the order of `bounded`.
    aabbs: Vec<Aabb>,
    /// Per obstacle, a cheap lower bound on a point's distance to it.
    bounds: Vec<Bound>,
}

/// A lower bound on a point's distance to an obstacle, a few flops against a parry query's
/// hundreds: a query whose bound already clears the reach by [`BOUND_SLACK`] cannot find a
/// contact and is skipped, so every answer is the one the query would give.
#[derive(Debug, Clone, Copy)]
enum Bound {
    /// A half-space: the signed distance n·(p − o), exact (n unit, outward).
    Plane { normal: Vec3, origin: Vec3 },
    /// parry's bounding sphere of the obstacle (the ball itself for a sphere): |p − c| − r,
    /// exact outside a ball and below the distance outside any shape it holds.
    Sphere { center: Vec3, radius: f64 },
}

/// Relative margin (× (1 + |p| + the obstacle's extent) m) by which a bound must clear a
/// reach before a query is skipped: far above the round-off by which a parry projection's
/// distance can differ from the bound's.
const BOUND_SLACK: f64 = 1e-9;

impl Bound {
    /// The bound of `shape` at `pose`.
    fn of(shape: &SharedShape, pose: &Pose) -> Self {
        if let Some(hs) = shape.as_halfspace() {
            return Bound::Plane {
                normal: from_g(pose.rotation * hs.normal),
                origin: from_g(pose.translation),
            };
        }
        let sphere = shape.compute_bounding_sphere(pose);
        Bound::Sphere {
            center: from_g(sphere.center()),
            radius: sphere.radius(),
        }
    }

    /// The lower bound at `p`, and the slack it must clear a reach by.
    fn at(&self, p: &Vec3) -> (f64, f64) {
        let (d, extent) = match self {
            Bound::Plane { normal, origin } => (normal.dot(&(p - origin)), origin.amax()),
            Bound::Sphere { center, radius } => {
                ((p - center).norm() - radius, center.amax() + radius)
            }
        };
        (d, BOUND_SLACK * (1.0 + p.amax() + extent))
    }

    /// True when no point of the segment `p0 → p1` comes within the slack of the obstacle,
    /// so no ray cast along it can hit.
    fn misses(&self, p0: &Vec3, p1: &Vec3) -> bool {
        match self {
            Bound::Plane { .. } => {
                let ((d0, s0), (d1, s1)) = (self.at(p0), self.at(p1));
                d0 > s0 && d1 > s1
            }
            Bound::Sphere { center, .. } => {
                let d = p1 - p0;
                let t = ((center - p0).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
                let (gap, slack) = self.at(&(p0 + d * t));
                gap > slack + BOUND_SLACK * (1.0 + p0.amax() + p1.amax())
            }
        }
    }
}

/// Bounded obstacles from which the broad phase walks the BVH; fewer are scanned in order,
/// which finds the same candidates (the leaves' AABBs, the same inclusive test) without
/// the tree walk a per-particle query would otherwise pay for one sphere or box.
pub const BVH_MIN_OBSTACLES: usize = 8;

/// Most broad-phase candidates a query keeps on the stack; more fall back to an ordered scan
/// of every bounded obstacle.
const MAX_CANDIDATES: usize = 16;

/// Relative size below which a projection's offset is treated as zero (the point is on the
/// surface) and the normal is taken from the surface feature instead.
const ON_SURFACE: f64 = 1e-12;

impl ObstacleSet {
    /// Builds parry shapes and the broad phase for `defs` (validated definitions).
    ///
    /// # Panics
    /// On a mesh without triangles (validation rejects it).
    pub fn build(defs: &[ObstacleDef]) -> Self {
        count_build();
        let mut obstacles = Vec::with_capacity(defs.len());
        for d in defs {
            let (shape, pose) = match &d.shape {
                ShapeDef::Plane { point, normal } => (
                    SharedShape::halfspace(to_g(&normal.normalize())),
                    Pose::from_translation(to_g(point)),
                ),
                ShapeDef::Sphere { center, radius } => (
                    SharedShape::ball(*radius),
                    Pose::from_translation(to_g(center)),
                ),
                ShapeDef::Box {
                    center,
                    half_extents: h,
                    rotation,
                } => (
                    SharedShape::cuboid(h.x, h.y, h.z),
                    Pose::new(to_g(center), to_g(rotation)),
                ),
                ShapeDef::Capsule { a, b, radius } => (
                    SharedShape::capsule(to_g(a), to_g(b), *radius),
                    Pose::IDENTITY,
                ),
                ShapeDef::Mesh {
                    vertices,
                    triangles,
                } => {
                    // ORIENTED: pseudo-normals make inside tests (and so signed distances) valid
                    // for closed meshes, wound outward here whatever the file's winding.
                    let flags = TriMeshFlags::ORIENTED | TriMeshFlags::MERGE_DUPLICATE_VERTICES;
                    let shape = SharedShape::trimesh_with_flags(
                        vertices.iter().map(to_g).collect(),
                        super::mesh::outward(vertices, triangles),
                        flags,
                    )
                    .expect("validated mesh has triangles");
                    (shape, Pose::IDENTITY)
                }
            };
            obstacles.push(Obstacle {
                shape,
                pose,
                restitution: d.restitution,
                friction: d.friction,
                kind: d.shape.kind(),
                two_sided: match &d.shape {
                    ShapeDef::Mesh {
                        vertices,
                        triangles,
                    } => !super::mesh::is_closed(vertices, triangles),
                    _ => false,
                },
            });
        }
        let mut unbounded = Vec::new();
        let mut bounded = Vec::new();
        let mut aabbs = Vec::new();
        for (k, o) in obstacles.iter().enumerate() {
            let aabb = o.shape.compute_aabb(&o.pose);
            if aabb.mins.is_finite() && aabb.maxs.is_finite() {
                bounded.push(k);
                aabbs.push(aabb);
            } else {
                unbounded.push(k);
            }
        }
        let bounds = obstacles
            .iter()
            .map(|o| Bound::of(&o.shape, &o.pose))
            .collect();
        let bvh = if aabbs.is_empty() {
            Bvh::new()
        } else {
            Bvh::from_leaves(BvhBuildStrategy::Binned, &aabbs)
        };
        ObstacleSet {
            obstacles,
            unbounded,
            bvh,
            bounded,
            aabbs,
            bounds,
        }
    }

    /// True when particle `p` with `reach` (radius plus margin) clearly cannot touch obstacle
    /// `k` by its bound: its query would find a gap above the margin.
    fn clearly_apart(&self, k: usize, p: &Vec3, reach: f64) -> bool {
        let (d, slack) = self.bounds[k].at(p);
        d > reach + slack
    }

    /// The bounded obstacles whose AABB meets `aabb` (touching counts), in obstacle order,
    /// written to `out`: their number, or None when there are more than `out` holds.
    fn candidates(&self, aabb: &Aabb, out: &mut [usize; MAX_CANDIDATES]) -> Option<usize> {
        let mut n = 0;
        if self.bounded.len() < BVH_MIN_OBSTACLES {
            for (b, &k) in self.aabbs.iter().zip(&self.bounded) {
                if b.intersects(aabb) {
                    out[n] = k;
                    n += 1;
                }
            }
            return Some(n);
        }
        // Candidate order from the BVH is fixed for a given tree; sort for obstacle order.
        for leaf in self.bvh.intersect_aabb(aabb) {
            if n == out.len() {
                return None;
            }
            out[n] = self.bounded[leaf as usize];
            n += 1;
        }
        out[..n].sort_unstable();
        Some(n)
    }

    /// The obstacles, in file order.
    pub fn obstacles(&self) -> &[Obstacle] {
        &self.obstacles
    }

    /// Number of obstacles.
    pub fn len(&self) -> usize {
        self.obstacles.len()
    }

    /// True without obstacles.
    pub fn is_empty(&self) -> bool {
        self.obstacles.is_empty()
    }

    /// Signed distance, normal and closest point of point `p` to obstacle `k` (one query).
    pub fn query(&self, k: usize, p: &Vec3, radius: f64) -> Contact {
        count_query();
        let o = &self.obstacles[k];
        let pg = to_g(p);
        let proj = o.shape.project_point(&o.pose, pg, false);
        let point = from_g(proj.point);
        let off = p - point;
        let dist = off.norm();
        let scale = 1.0 + p.norm();
        let (distance, normal) = if dist > ON_SURFACE * scale {
            // A two-sided sheet has no inside: the normal points to the particle's side.
            if proj.is_inside && !o.two_sided {
                (-dist, -off / dist)
            } else {
                (dist, off / dist)
            }
        } else {
            (0.0, self.surface_normal(k, p))
        };
        Contact {
            obstacle: k,
            distance,
            gap: distance - radius,
            normal,
            point,
        }
    }

    /// Outward normal at a point lying on obstacle `k`'s surface (from the surface feature).
    fn surface_normal(&self, k: usize, p: &Vec3) -> Vec3 {
        let o = &self.obstacles[k];
        if let Some(hs) = o.shape.as_halfspace() {
            return from_g(o.pose.rotation * hs.normal);
        }
        let local = o.pose.inverse_transform_point(to_g(p));
        let (proj, feature) = o.shape.project_local_point_and_get_feature(local);
        let n = o
            .shape
            .feature_normal_at_point(proj.subshape, feature, proj.point)
            .map(|n| o.pose.rotation * n);
        match n {
            Some(n) if n.length() > 0.0 => from_g(n.normalize()),
            // No feature normal: point away from the obstacle's bounding-box centre.
            _ => {
                let c = from_g(o.shape.compute_aabb(&o.pose).center());
                let d = p - c;
                if d.norm() > 0.0 {
                    d.normalize()
                } else {
                    Vec3::y()
                }
            }
        }
    }

    /// Calls `f` for every obstacle whose gap to the particle (centre `p`, `radius`) is below
    /// `margin` (m), in obstacle order. The broad phase limits the narrow queries.
    pub fn for_each_near(&self, p: &Vec3, radius: f64, margin: f64, mut f: impl FnMut(Contact)) {
        let reach = radius + margin.max(0.0);
        for &k in &self.unbounded {
            if self.clearly_apart(k, p, reach) {
                continue;
            }
            let c = self.query(k, p, radius);
            if c.gap < margin {
                f(c);
            }
        }
        if self.bounded.is_empty() {
            return;
        }
        let pg = to_g(p);
        let r = Vector::splat(reach);
        let aabb = Aabb::new(pg - r, pg + r);
        let mut hits = [usize::MAX; MAX_CANDIDATES];
        let near = match self.candidates(&aabb, &mut hits) {
            Some(n) => &hits[..n],
            // Many candidates: a plain ordered scan of the bounded ones.
            None => &self.bounded[..],
        };
        for &k in near {
            if self.clearly_apart(k, p, reach) {
                continue;
            }
            let c = self.query(k, p, radius);
            if c.gap < margin {
                f(c);
            }
        }
    }

    /// The obstacle nearest to the particle within `max_gap` (m), if any.
    pub fn nearest(&self, p: &Vec3, radius: f64, max_gap: f64) -> Option<Contact> {
        let mut best: Option<Contact> = None;
        let mut take = |c: Contact| {
            if best.is_none_or(|b| c.gap < b.gap) {
                best = Some(c);
            }
        };
        if max_gap.is_finite() {
            self.for_each_near(p, radius, max_gap, &mut take);
        } else {
            for k in 0..self.obstacles.len() {
                take(self.query(k, p, radius));
            }
        }
        best
    }

    /// The first obstacle surface the straight path `p0 → p1` enters from outside, if any:
    /// parry ray casts (solid; hollow for a two-sided sheet, so it is hit from either side)
    /// against obstacles whose AABB meets the path's. An obstacle the path starts inside of is
    /// skipped (point projection handles it).
    pub fn sweep(&self, p0: &Vec3, p1: &Vec3) -> Option<SweepHit> {
        let d = p1 - p0;
        if d.norm_squared() == 0.0 {
            return None;
        }
        let ray = Ray::new(to_g(p0), to_g(&d));
        let mut best: Option<SweepHit> = None;
        let test = |k: usize, best: &mut Option<SweepHit>| {
            if self.bounds[k].misses(p0, p1) {
                return;
            }
            let o = &self.obstacles[k];
            count_query();
            let Some(hit) = o
                .shape
                .cast_ray_and_get_normal(&o.pose, &ray, 1.0, !o.two_sided)
            else {
                return;
            };
            let toi = hit.time_of_impact;
            if toi <= 0.0 || best.is_some_and(|b| b.toi <= toi) {
                return;
            }
            // Entering only: the start must be outside this obstacle.
            if self.query(k, p0, 0.0).distance < 0.0 {
                return;
            }
            let mut n = from_g(hit.normal);
            if n.dot(&d) > 0.0 {
                n = -n;
            }
            let nn = n.norm();
            if nn == 0.0 {
                return;
            }
            *best = Some(SweepHit {
                obstacle: k,
                toi,
                point: p0 + d * toi,
                normal: n / nn,
            });
        };
        for &k in &self.unbounded {
            test(k, &mut best);
        }
        if !self.bounded.is_empty() {
            let a = to_g(p0);
            let b = to_g(p1);
            let aabb = Aabb::new(a.min(b), a.max(b));
            // No allocation in the common case: the candidates on the stack, in obstacle
            // order; more fall back to an ordered scan of every bounded obstacle.
            let mut cand = [usize::MAX; MAX_CANDIDATES];
            let near = match self.candidates(&aabb, &mut cand) {
                Some(n) => &cand[..n],
                None => &self.bounded[..],
            };
            for &k in near {
                test(k, &mut best);
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Oracle: parry's BVH over the same leaves. The ordered scan below BVH_MIN_OBSTACLES must
    // find exactly the obstacles the tree finds, touching boxes included, for queries that
    // miss, graze and cover them. Twin: a query box far from every sphere finds only the
    // half-space.
    #[test]
    fn the_scan_finds_what_the_tree_finds() {
        let sphere = |c: [f64; 3], r: f64| ObstacleDef {
            shape: ShapeDef::Sphere {
                center: Vec3::new(c[0], c[1], c[2]),
                radius: r,
            },
            restitution: 0.0,
            friction: 0.0,
        };
        let set = ObstacleSet::build(&[
            sphere([0.0, 0.0, 0.0], 1.0),
            ObstacleDef {
                shape: ShapeDef::Plane {
                    point: Vec3::zeros(),
                    normal: Vec3::new(0.0, 1.0, 0.0),
                },
                restitution: 0.0,
                friction: 0.0,
            },
            sphere([3.0, 0.0, 0.0], 0.5),
            sphere([0.0, 4.0, 1.0], 2.0),
        ]);
        assert!(set.bounded.len() < BVH_MIN_OBSTACLES);
        let mut checked = 0;
        for i in -12..=12 {
            for j in -12..=12 {
                for half in [0.0, 0.25, 1.0, 3.0] {
                    let c = Vector::new(0.5 * i as f64, 0.5 * j as f64, 0.5);
                    let q = Aabb::new(c - Vector::splat(half), c + Vector::splat(half));
                    let mut tree: Vec<usize> = set
                        .bvh
                        .intersect_aabb(&q)
                        .map(|l| set.bounded[l as usize])
                        .collect();
                    tree.sort_unstable();
                    let mut out = [usize::MAX; MAX_CANDIDATES];
                    let n = set.candidates(&q, &mut out).expect("few obstacles");
                    assert_eq!(&out[..n], &tree[..], "query {q:?}");
                    checked += usize::from(n > 0);
                }
            }
        }
        assert!(checked > 100, "only {checked} queries met an obstacle");
        let far = Aabb::new(Vector::splat(50.0), Vector::splat(51.0));
        let mut out = [usize::MAX; MAX_CANDIDATES];
        assert_eq!(set.candidates(&far, &mut out), Some(1));
        assert_eq!(
            out[0], 1,
            "only the half-space, whose box parry makes all of space"
        );
    }

    // Oracle: parry's own answers. Wherever a bound rules a query out, the query finds the
    // particle farther than its reach; wherever it rules a ray cast out, the cast hits nothing
    // on the segment. Points run from deep inside to far outside every shape, tilted, and
    // right at the reach (the slack's edge). Twin: points on or near each surface are not
    // ruled out (the bound skips nothing it must not, and still skips the far ones).
    #[test]
    fn a_bound_rules_out_only_what_the_query_would() {
        let def = |shape| ObstacleDef {
            shape,
            restitution: 0.0,
            friction: 0.0,
        };
        let set = ObstacleSet::build(&[
            def(ShapeDef::Plane {
                point: Vec3::new(0.1, -0.2, 0.3),
                normal: Vec3::new(0.2, 1.0, -0.1),
            }),
            def(ShapeDef::Sphere {
                center: Vec3::new(1.0, 0.5, -0.5),
                radius: 0.7,
            }),
            def(ShapeDef::Box {
                center: Vec3::new(-1.0, 0.3, 0.2),
                half_extents: Vec3::new(0.3, 0.25, 0.5),
                rotation: Vec3::new(0.1, 0.4, 0.2),
            }),
            def(ShapeDef::Capsule {
                a: Vec3::new(0.0, 1.0, 1.0),
                b: Vec3::new(0.5, 1.5, 1.2),
                radius: 0.2,
            }),
        ]);
        let (mut skipped, mut missed) = (0, 0usize);
        for i in 0..4000 {
            let f = i as f64;
            let p = Vec3::new(
                (f * 0.7311).sin() * 2.5,
                (f * 0.5127).cos() * 2.0,
                (f * 0.9173).sin() * 2.5,
            );
            let q = p + Vec3::new((f * 0.31).cos(), (f * 0.17).sin(), (f * 0.23).cos()) * 0.4;
            for k in 0..set.len() {
                let radius = 0.01 * (i % 3) as f64;
                let exact = set.query(k, &p, radius);
                for reach in [radius, radius + 0.05, exact.distance.max(0.0)] {
                    if set.clearly_apart(k, &p, reach) {
                        skipped += 1;
                        assert!(exact.distance > reach, "obstacle {k} at {p:?}");
                    }
                }
                // On the surface: the query's own closest point is never ruled out.
                assert!(!set.clearly_apart(k, &exact.point, 0.0), "obstacle {k}");
                if set.bounds[k].misses(&p, &q) {
                    missed += 1;
                    let o = &set.obstacles[k];
                    let ray = Ray::new(to_g(&p), to_g(&(q - p)));
                    let hit = o.shape.cast_ray(&o.pose, &ray, 1.0, true);
                    assert!(hit.is_none_or(|t| t <= 0.0), "obstacle {k}: {p:?} → {q:?}");
                }
            }
        }
        assert!(skipped > 10_000, "only {skipped} queries ruled out");
        assert!(missed > 5_000, "only {missed} ray casts ruled out");
    }
}
