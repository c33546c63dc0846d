//! A minimal Wavefront OBJ reader: `v x y z` and `f a b c ...` lines (1-based or negative
//! indices, `a/b/c` forms allowed, polygons fanned into triangles); every other line is ignored.

/// A mesh read from OBJ text.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjMesh {
    /// Vertex positions.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as 0-based vertex indices.
    pub triangles: Vec<[u32; 3]>,
}

/// Vertices and 0-based triangles read from OBJ text; `Err` carries line number and reason.
pub fn parse_obj(text: &str) -> Result<ObjMesh, String> {
    let mut vertices: Vec<[f64; 3]> = Vec::new();
    let mut triangles = Vec::new();
    for (ln, line) in text.lines().enumerate() {
        let line_no = ln + 1;
        let line = line.split('#').next().unwrap_or("").trim();
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let mut c = [0.0; 3];
                for (k, slot) in c.iter_mut().enumerate() {
                    let tok = it.next().ok_or(format!(
                        "line {line_no}: vertex has {k} coordinates, need 3"
                    ))?;
                    *slot = tok
                        .parse::<f64>()
                        .ok()
                        .filter(|x| x.is_finite())
                        .ok_or(format!("line {line_no}: '{tok}' is not a finite number"))?;
                }
                vertices.push(c);
            }
            Some("f") => {
                let mut idx = Vec::new();
                for tok in it {
                    let first = tok.split('/').next().unwrap_or("");
                    let i: i64 = first
                        .parse()
                        .map_err(|_| format!("line {line_no}: '{tok}' is not a vertex index"))?;
                    let n = vertices.len() as i64;
                    let z = if i > 0 { i - 1 } else { n + i };
                    if i == 0 || z < 0 || z >= n {
                        return Err(format!(
                            "line {line_no}: vertex index {i} does not exist ({n} vertices defined so far)"
                        ));
                    }
                    idx.push(z as u32);
                }
                if idx.len() < 3 {
                    return Err(format!(
                        "line {line_no}: a face needs at least 3 vertices, got {}",
                        idx.len()
                    ));
                }
                for k in 1..idx.len() - 1 {
                    triangles.push([idx[0], idx[k], idx[k + 1]]);
                }
            }
            _ => {}
        }
    }
    if triangles.is_empty() {
        return Err("no faces ('f' lines) found".into());
    }
    Ok(ObjMesh {
        vertices,
        triangles,
    })
}
