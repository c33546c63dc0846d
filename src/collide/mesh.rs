//! Mesh sidedness: a closed triangle mesh (every edge shared by exactly two triangles) bounds a
//! solid and has an inside; an open mesh is a two-sided thin sheet, solid on neither side.
//!
//! A closed mesh wound inside-out (negative signed volume) is turned outward before parry sees
//! it, so its inside is the enclosed volume whatever the file's winding. An open mesh has no
//! inside: its signed distance is the plain distance to the sheet and its normal points to the
//! side the particle is on, so a particle on either side is pushed back to that side and never
//! through the sheet, whatever the winding.

use crate::model::Vec3;
use std::collections::HashMap;

/// Vertex indices with duplicate positions merged (exact coordinates), as parry's
/// `MERGE_DUPLICATE_VERTICES` does.
fn merged(vertices: &[Vec3]) -> Vec<usize> {
    let mut first: HashMap<[u64; 3], usize> = HashMap::with_capacity(vertices.len());
    vertices
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let key = [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
            *first.entry(key).or_insert(i)
        })
        .collect()
}

/// True when every edge of the mesh (duplicate vertices merged) belongs to exactly two
/// triangles: the mesh encloses a volume.
pub fn is_closed(vertices: &[Vec3], triangles: &[[u32; 3]]) -> bool {
    let id = merged(vertices);
    let mut edges: HashMap<(usize, usize), u32> = HashMap::new();
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (id[t[k] as usize], id[t[(k + 1) % 3] as usize]);
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    !edges.is_empty() && edges.values().all(|&n| n == 2)
}

/// Signed volume enclosed by the triangles (positive when wound counter-clockwise seen from
/// outside); meaningful for closed meshes.
pub fn signed_volume(vertices: &[Vec3], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum()
}

/// The triangles wound outward: reversed when the mesh is closed with negative volume.
pub fn outward(vertices: &[Vec3], triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    if is_closed(vertices, triangles) && signed_volume(vertices, triangles) < 0.0 {
        triangles.iter().map(|&[a, b, c]| [a, c, b]).collect()
    } else {
        triangles.to_vec()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetra() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let v = vec![Vec3::zeros(), Vec3::x(), Vec3::y(), Vec3::z()];
        (v, vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    }

    #[test]
    fn a_tetrahedron_is_closed_with_volume_one_sixth_and_a_sheet_is_open() {
        // Oracle: the unit right tetrahedron's volume is 1/6.
        let (v, t) = tetra();
        assert!(is_closed(&v, &t));
        assert!((signed_volume(&v, &t) - 1.0 / 6.0).abs() < 1e-15);
        let flipped: Vec<[u32; 3]> = t.iter().map(|&[a, b, c]| [a, c, b]).collect();
        assert!((signed_volume(&v, &flipped) + 1.0 / 6.0).abs() < 1e-15);
        assert_eq!(outward(&v, &flipped), t);
        assert!(!is_closed(&v, &t[..3]));
    }
}
