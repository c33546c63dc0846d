//! Validation of `[[obstacle]]` and `[collision]` into a [`CollisionSetup`], with the field
//! path of every impossible value (`obstacle[2].normal: ...`). Mesh files are read here,
//! relative to the scene file, so a built scene never touches the disk again.

use super::file::{ScenarioFile, Triple};
use super::obj::parse_obj;
use super::obstacle_file::{CollisionSpec, ObstacleSpec};
use crate::collide::{CollisionSetup, ObstacleDef, PenaltyDamping, Response, ShapeDef};
use crate::error::{Error, Result};
use crate::model::Vec3;
use std::path::Path;

/// Shape names and the keys each takes (besides shape, restitution, friction).
const SHAPES: &[(&str, &[&str])] = &[
    ("plane", &["point", "normal"]),
    ("sphere", &["center", "radius"]),
    ("box", &["center", "half_extents", "rotation"]),
    ("capsule", &["a", "b", "radius"]),
    ("mesh", &["file", "vertices", "triangles"]),
];

struct Ck<'a> {
    file: &'a Path,
}

impl Ck<'_> {
    fn err(&self, field: impl Into<String>, msg: impl Into<String>) -> Error {
        Error::invalid(self.file, field, msg)
    }
    fn need<T: Copy>(&self, f: &str, key: &str, shape: &str, v: Option<T>) -> Result<T> {
        v.ok_or_else(|| {
            self.err(
                format!("{f}.{key}"),
                format!("missing: a {shape} needs `{key}`"),
            )
        })
    }
    fn triple(&self, field: &str, t: Triple) -> Result<Vec3> {
        for (k, c) in t.iter().enumerate() {
            if !c.is_finite() {
                return Err(self.err(
                    format!("{field}[{k}]"),
                    format!("must be a finite number, got {}", crate::error::num(*c)),
                ));
            }
        }
        Ok(Vec3::from(t))
    }
    fn positive(&self, field: &str, x: f64) -> Result<f64> {
        if x.is_finite() && x > 0.0 {
            Ok(x)
        } else {
            Err(self.err(
                field,
                format!("must be a finite number > 0, got {}", crate::error::num(x)),
            ))
        }
    }
    fn non_negative(&self, field: &str, x: f64) -> Result<f64> {
        if x.is_finite() && x >= 0.0 {
            Ok(x)
        } else {
            Err(self.err(
                field,
                format!("must be a finite number >= 0, got {}", crate::error::num(x)),
            ))
        }
    }
    fn unit(&self, field: &str, x: f64) -> Result<f64> {
        if x.is_finite() && (0.0..=1.0).contains(&x) {
            Ok(x)
        } else {
            Err(self.err(
                field,
                format!("must be between 0 and 1, got {}", crate::error::num(x)),
            ))
        }
    }
}

/// Keys present in an obstacle table, by name.
fn present(o: &ObstacleSpec) -> Vec<&'static str> {
    let mut keys = Vec::new();
    let mut add = |name, there: bool| {
        if there {
            keys.push(name)
        }
    };
    add("point", o.point.is_some());
    add("normal", o.normal.is_some());
    add("center", o.center.is_some());
    add("radius", o.radius.is_some());
    add("half_extents", o.half_extents.is_some());
    add("rotation", o.rotation.is_some());
    add("a", o.a.is_some());
    add("b", o.b.is_some());
    add("file", o.file.is_some());
    add("vertices", o.vertices.is_some());
    add("triangles", o.triangles.is_some());
    keys
}

/// Validates the obstacles and collision settings of `raw` (`file` labels errors and anchors
/// mesh paths); `None` when the scene has no obstacles.
pub fn validate_collision(raw: &ScenarioFile, file: &Path) -> Result<Option<CollisionSetup>> {
    let ck = Ck { file };
    let mut obstacles = Vec::new();
    for (k, o) in raw.obstacle.iter().enumerate() {
        obstacles.push(obstacle(&ck, &format!("obstacle[{k}]"), o)?);
    }
    let response = response(&ck, raw.collision.as_ref())?;
    if obstacles.is_empty() {
        return Ok(None);
    }
    Ok(Some(CollisionSetup {
        obstacles,
        response,
    }))
}

fn obstacle(ck: &Ck, f: &str, o: &ObstacleSpec) -> Result<ObstacleDef> {
    let shape = o.shape.as_str();
    let Some(&(_, keys)) = SHAPES.iter().find(|(n, _)| *n == shape) else {
        let names: Vec<&str> = SHAPES.iter().map(|(n, _)| *n).collect();
        return Err(ck.err(
            format!("{f}.shape"),
            format!(
                "unknown shape '{shape}'; expected one of: {}",
                names.join(", ")
            ),
        ));
    };
    for key in present(o) {
        if !keys.contains(&key) {
            return Err(ck.err(
                format!("{f}.{key}"),
                format!(
                    "not used by a {shape} (a {shape} takes: {})",
                    keys.join(", ")
                ),
            ));
        }
    }
    let def = match shape {
        "plane" => {
            let point = ck.triple(&format!("{f}.point"), ck.need(f, "point", shape, o.point)?)?;
            let normal = ck.triple(
                &format!("{f}.normal"),
                ck.need(f, "normal", shape, o.normal)?,
            )?;
            let len = normal.norm();
            if !(len.is_finite() && len > 0.0) {
                return Err(ck.err(
                    format!("{f}.normal"),
                    "is the zero vector: a plane needs a direction",
                ));
            }
            ShapeDef::Plane {
                point,
                normal: normal / len,
            }
        }
        "sphere" => ShapeDef::Sphere {
            center: ck.triple(
                &format!("{f}.center"),
                ck.need(f, "center", shape, o.center)?,
            )?,
            radius: ck.positive(
                &format!("{f}.radius"),
                ck.need(f, "radius", shape, o.radius)?,
            )?,
        },
        "box" => {
            let center = ck.triple(
                &format!("{f}.center"),
                ck.need(f, "center", shape, o.center)?,
            )?;
            let he = ck.need(f, "half_extents", shape, o.half_extents)?;
            for (i, h) in he.iter().enumerate() {
                ck.positive(&format!("{f}.half_extents[{i}]"), *h)?;
            }
            let rotation = match o.rotation {
                Some(r) => ck.triple(&format!("{f}.rotation"), r)?,
                None => Vec3::zeros(),
            };
            ShapeDef::Box {
                center,
                half_extents: Vec3::from(he),
                rotation,
            }
        }
        "capsule" => ShapeDef::Capsule {
            a: ck.triple(&format!("{f}.a"), ck.need(f, "a", shape, o.a)?)?,
            b: ck.triple(&format!("{f}.b"), ck.need(f, "b", shape, o.b)?)?,
            radius: ck.positive(
                &format!("{f}.radius"),
                ck.need(f, "radius", shape, o.radius)?,
            )?,
        },
        _ => mesh(ck, f, o)?,
    };
    Ok(ObstacleDef {
        shape: def,
        restitution: match o.restitution {
            Some(e) => ck.unit(&format!("{f}.restitution"), e)?,
            None => 0.0,
        },
        friction: match o.friction {
            Some(mu) => ck.non_negative(&format!("{f}.friction"), mu)?,
            None => 0.0,
        },
    })
}

fn mesh(ck: &Ck, f: &str, o: &ObstacleSpec) -> Result<ShapeDef> {
    let (vertices, triangles): (Vec<Triple>, Vec<[i64; 3]>) = match (&o.file, &o.vertices, &o.triangles) {
        (Some(path), None, None) => {
            let base = ck.file.parent().unwrap_or(Path::new(""));
            let full = base.join(path);
            let limit = super::parse::MAX_MESH_BYTES;
            let bytes = super::parse::read_limited(&full, limit)
                .map_err(|e| {
                    ck.err(format!("{f}.file"), format!("cannot read mesh '{}': {e}", full.display()))
                })?
                .ok_or_else(|| {
                    ck.err(
                        format!("{f}.file"),
                        format!("mesh '{}' is larger than the limit of {} MiB", full.display(), limit >> 20),
                    )
                })?;
            let text = String::from_utf8(bytes).map_err(|_| {
                ck.err(format!("{f}.file"), format!("mesh '{}' is not UTF-8 text", full.display()))
            })?;
            let m = parse_obj(&text)
                .map_err(|why| ck.err(format!("{f}.file"), format!("{}: {why}", full.display())))?;
            (m.vertices, m.triangles.into_iter().map(|t| t.map(i64::from)).collect())
        }
        (None, Some(v), Some(t)) => (v.clone(), t.clone()),
        (Some(_), _, _) => {
            return Err(ck.err(
                format!("{f}.file"),
                "give either `file` or `vertices` + `triangles`, not both",
            ))
        }
        (None, Some(_), None) => {
            return Err(ck.err(format!("{f}.triangles"), "missing: inline `vertices` need `triangles`"))
        }
        (None, None, Some(_)) => {
            return Err(ck.err(format!("{f}.vertices"), "missing: inline `triangles` need `vertices`"))
        }
        (None, None, None) => {
            return Err(ck.err(
                format!("{f}.file"),
                "missing: a mesh needs `file` (an OBJ path relative to the scene) or `vertices` + `triangles`",
            ))
        }
    };
    let n = vertices.len();
    let mut verts = Vec::with_capacity(n);
    for (i, v) in vertices.iter().enumerate() {
        verts.push(ck.triple(&format!("{f}.vertices[{i}]"), *v)?);
    }
    if triangles.is_empty() {
        return Err(ck.err(
            format!("{f}.triangles"),
            "is empty: a mesh needs at least one triangle",
        ));
    }
    let mut tris = Vec::with_capacity(triangles.len());
    for (j, t) in triangles.iter().enumerate() {
        let mut tri = [0u32; 3];
        for c in 0..3 {
            if t[c] < 0 || t[c] as u64 >= n as u64 {
                return Err(ck.err(
                    format!("{f}.triangles[{j}][{c}]"),
                    format!(
                        "vertex index {} does not exist (the mesh has {n} vertices, 0..{})",
                        t[c],
                        n.saturating_sub(1)
                    ),
                ));
            }
            tri[c] = t[c] as u32;
        }
        let (a, b, c) = (
            verts[tri[0] as usize],
            verts[tri[1] as usize],
            verts[tri[2] as usize],
        );
        if (b - a).cross(&(c - a)).norm() == 0.0 {
            return Err(ck.err(format!("{f}.triangles[{j}]"), "is degenerate (zero area)"));
        }
        tris.push(tri);
    }
    Ok(ShapeDef::Mesh {
        vertices: verts,
        triangles: tris,
    })
}

fn response(ck: &Ck, c: Option<&CollisionSpec>) -> Result<Response> {
    let Some(c) = c else {
        return Ok(Response::Impulse);
    };
    let name = c.response.as_deref().unwrap_or("impulse");
    let penalty_only = |key: &str, given: bool| -> Result<()> {
        if given {
            Err(ck.err(
                format!("collision.{key}"),
                format!("only used by the penalty response, not by '{name}'"),
            ))
        } else {
            Ok(())
        }
    };
    match name {
        "impulse" | "projection" => {
            penalty_only("stiffness", c.stiffness.is_some())?;
            penalty_only("damping", c.damping.is_some())?;
            penalty_only("restitution", c.restitution.is_some())?;
            Ok(if name == "impulse" {
                Response::Impulse
            } else {
                Response::Projection
            })
        }
        "penalty" => {
            let k = c.stiffness.ok_or_else(|| {
                ck.err(
                    "collision.stiffness",
                    "missing: the penalty response needs a contact stiffness (N/m)",
                )
            })?;
            let stiffness = ck.positive("collision.stiffness", k)?;
            let damping = match (c.damping, c.restitution) {
                (Some(_), Some(_)) => {
                    return Err(ck.err(
                        "collision.restitution",
                        "give either `damping` or `restitution`, not both",
                    ))
                }
                (Some(d), None) => {
                    PenaltyDamping::Coefficient(ck.non_negative("collision.damping", d)?)
                }
                (None, Some(e)) => {
                    PenaltyDamping::Restitution(ck.unit("collision.restitution", e)?)
                }
                (None, None) => PenaltyDamping::PerObstacle,
            };
            Ok(Response::Penalty { stiffness, damping })
        }
        other => Err(ck.err(
            "collision.response",
            format!("unknown response '{other}'; expected one of: impulse, penalty, projection"),
        )),
    }
}
