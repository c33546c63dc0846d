//! Malformed obstacle and collision fields give clear errors naming the file and field.
//!
//! Oracle: a list of impossible values; each error must carry the field path.

use springlab::scenario::Scenario;
use std::io::Write;

const BASE: &str = "[[particle]]\nposition = [0.0, 1.0, 0.0]\nmass = 1.0\n";

fn err_of(extra: &str) -> String {
    match Scenario::from_toml_str(&format!("{BASE}{extra}"), "scene.toml") {
        Ok(_) => panic!("accepted:\n{extra}"),
        Err(e) => e.to_string(),
    }
}

fn expect(extra: &str, field: &str, words: &str) {
    let msg = err_of(extra);
    assert!(msg.contains("scene.toml"), "no file in: {msg}");
    assert!(msg.contains(field), "no field '{field}' in: {msg}");
    assert!(msg.contains(words), "no '{words}' in: {msg}");
}

const PLANE: &str =
    "[[obstacle]]\nshape = \"plane\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 1.0, 0.0]\n";

#[test]
fn obstacle_fields() {
    expect(
        &format!("{PLANE}{PLANE}[[obstacle]]\nshape = \"plane\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 0.0]\n"),
        "obstacle[2].normal",
        "zero vector",
    );
    expect(
        "[[obstacle]]\nshape = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = -1.0\n",
        "obstacle[0].radius",
        "> 0",
    );
    expect(
        "[[obstacle]]\nshape = \"box\"\ncenter = [0.0, 0.0, 0.0]\nhalf_extents = [1.0, 0.0, 1.0]\n",
        "obstacle[0].half_extents[1]",
        "> 0",
    );
    expect(
        "[[obstacle]]\nshape = \"box\"\ncenter = [0.0, 0.0, 0.0]\n",
        "obstacle[0].half_extents",
        "missing",
    );
    expect(
        "[[obstacle]]\nshape = \"cone\"\n",
        "obstacle[0].shape",
        "unknown shape 'cone'",
    );
    expect(
        &format!("{PLANE}radius = 1.0\n"),
        "obstacle[0].radius",
        "not used by a plane",
    );
    expect(
        &format!("{PLANE}restitution = 1.5\n"),
        "obstacle[0].restitution",
        "between 0 and 1",
    );
    expect(
        &format!("{PLANE}friction = -0.1\n"),
        "obstacle[0].friction",
        ">= 0",
    );
    expect(
        &format!("{PLANE}colour = \"red\"\n"),
        "obstacle[0]",
        "unknown field `colour`",
    );
    expect(
        "[[obstacle]]\nshape = \"mesh\"\nvertices = [[0.0,0.0,0.0],[1.0,0.0,0.0],[0.0,0.0,1.0]]\ntriangles = [[0, 1, 3]]\n",
        "obstacle[0].triangles[0][2]",
        "vertex index 3 does not exist",
    );
    expect(
        "[[obstacle]]\nshape = \"mesh\"\n",
        "obstacle[0].file",
        "missing",
    );
}

#[test]
fn mesh_files() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.toml");
    let write = |name: &str, text: &str| {
        std::fs::File::create(dir.path().join(name))
            .unwrap()
            .write_all(text.as_bytes())
            .unwrap();
    };
    let with_file = |file: &str| {
        std::fs::write(
            &scene,
            format!("{BASE}[[obstacle]]\nshape = \"mesh\"\nfile = \"{file}\"\n"),
        )
        .unwrap();
        Scenario::from_file(&scene)
    };
    // Missing: the path is resolved relative to the scene file and named.
    let e = with_file("nope.obj").unwrap_err().to_string();
    assert!(
        e.contains("obstacle[0].file") && e.contains("nope.obj") && e.contains("cannot read"),
        "{e}"
    );
    // Malformed OBJ: line and reason.
    write("bad.obj", "v 0 0 0\nv 1 0 x\n");
    let e = with_file("bad.obj").unwrap_err().to_string();
    assert!(
        e.contains("obstacle[0].file") && e.contains("line 2") && e.contains("'x'"),
        "{e}"
    );
    write("idx.obj", "v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 4\n");
    let e = with_file("idx.obj").unwrap_err().to_string();
    assert!(
        e.contains("line 4") && e.contains("vertex index 4 does not exist"),
        "{e}"
    );
    // A good one loads, relative to the scene's directory.
    write("ok.obj", "v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 3 2\n");
    let s = with_file("ok.obj").unwrap();
    assert_eq!(s.collision.unwrap().obstacles.len(), 1);
}

#[test]
fn collision_fields() {
    expect(
        &format!("{PLANE}[collision]\nresponse = \"penalty\"\n"),
        "collision.stiffness",
        "missing",
    );
    expect(
        &format!("{PLANE}[collision]\nresponse = \"spring\"\n"),
        "collision.response",
        "unknown response 'spring'",
    );
    expect(
        &format!("{PLANE}[collision]\nresponse = \"impulse\"\nstiffness = 1e4\n"),
        "collision.stiffness",
        "only used by the penalty",
    );
    expect(
        &format!("{PLANE}[collision]\nresponse = \"penalty\"\nstiffness = 1e4\ndamping = 1.0\nrestitution = 0.5\n"),
        "collision.restitution",
        "not both",
    );
    expect(
        &format!("{PLANE}[collision]\nresponse = \"penalty\"\nstiffness = -5.0\n"),
        "collision.stiffness",
        "> 0",
    );
}
