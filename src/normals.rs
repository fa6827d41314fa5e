//! Vertex normals for meshes that come without them: angle-weighted face normals over the
//! welded mesh, split where the dihedral angle exceeds the crease angle.
//!
//! This is what users of a smoothing tool expect (Blender's "shade auto smooth" does the same):
//! the surface needs a normal per vertex, and a mesh exported without normals (the Fox sample,
//! photogrammetry, CAD) should come out smooth across gentle edges and creased at sharp ones.
//! It works on positions and triangles only; it does not touch any other attribute, but returns
//! the vertex remapping so that the caller can duplicate them where a vertex was split.

use glam::DVec3;
use std::collections::HashMap;

/// Normals generated for a mesh, with the vertices split where one input vertex needs two
/// normals (it sits on a crease and the input shared it between both sides).
#[derive(Debug, Clone, PartialEq)]
pub struct GeneratedNormals {
    /// For each new vertex, the input vertex it copies (every other attribute follows this).
    pub source_vertex: Vec<u32>,
    /// One unit normal per new vertex.
    pub normals: Vec<DVec3>,
    /// The triangles, re-indexed to the new vertices.
    pub triangles: Vec<[u32; 3]>,
}

/// Generates normals; `crease_angle_deg` in [0, 180]: faces meeting at a welded vertex are
/// averaged together when their normals differ by at most that angle.
///
/// A degenerate face (zero area) contributes nothing; a vertex whose faces are all degenerate
/// gets +Z, so the output never contains NaN.
pub fn generate(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    crease_angle_deg: f64,
) -> GeneratedNormals {
    let cos_crease = crease_angle_deg.to_radians().cos();
    let face_normals: Vec<DVec3> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| positions[v as usize]);
            (b - a).cross(c - a).normalize_or_zero()
        })
        .collect();

    // Corners grouped by welded position (bit-equal, -0.0 == +0.0), in first-seen order.
    let key = |p: DVec3| {
        p.to_array()
            .map(|x| if x == 0.0 { 0u64 } else { x.to_bits() })
    };
    let mut welded: HashMap<[u64; 3], u32> = HashMap::new();
    let mut corners_of: Vec<Vec<(u32, u8)>> = Vec::new();
    for (t, tri) in triangles.iter().enumerate() {
        for (k, &v) in tri.iter().enumerate() {
            let next = corners_of.len() as u32;
            let w = *welded.entry(key(positions[v as usize])).or_insert(next);
            if w == next {
                corners_of.push(Vec::new());
            }
            corners_of[w as usize].push((t as u32, k as u8));
        }
    }

    let corner_angle = |t: usize, k: usize| -> f64 {
        let tri = triangles[t];
        let p = positions[tri[k] as usize];
        let e1 = positions[tri[(k + 1) % 3] as usize] - p;
        let e2 = positions[tri[(k + 2) % 3] as usize] - p;
        e1.angle_between(e2)
    };

    // Per corner: the smoothed normal over the faces of its welded vertex within the crease.
    let mut corner_normal = vec![[DVec3::ZERO; 3]; triangles.len()];
    for corners in &corners_of {
        for &(t, k) in corners {
            let nf = face_normals[t as usize];
            let mut sum = DVec3::ZERO;
            for &(t2, k2) in corners {
                let n2 = face_normals[t2 as usize];
                if nf == DVec3::ZERO || nf.dot(n2) >= cos_crease - 1e-12 {
                    let w = corner_angle(t2 as usize, k2 as usize);
                    if w.is_finite() {
                        sum += w * n2;
                    }
                }
            }
            let n = sum.normalize_or_zero();
            corner_normal[t as usize][k as usize] = if n == DVec3::ZERO { DVec3::Z } else { n };
        }
    }

    // One new vertex per (input vertex, distinct normal), in first-seen order.
    let mut split: HashMap<(u32, [u64; 3]), u32> = HashMap::new();
    let mut out = GeneratedNormals {
        source_vertex: Vec::new(),
        normals: Vec::new(),
        triangles: Vec::with_capacity(triangles.len()),
    };
    for (t, tri) in triangles.iter().enumerate() {
        let mut new_tri = [0u32; 3];
        for k in 0..3 {
            let n = corner_normal[t][k];
            let next = out.normals.len() as u32;
            let id = *split
                .entry((tri[k], n.to_array().map(f64::to_bits)))
                .or_insert(next);
            if id == next {
                out.source_vertex.push(tri[k]);
                out.normals.push(n);
            }
            new_tri[k] = id;
        }
        out.triangles.push(new_tri);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube as 8 shared vertices and 12 triangles, wound outward.
    fn shared_cube() -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let p: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let t = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        (p, t)
    }

    #[test]
    fn cube_is_split_into_flat_faces_below_ninety_degrees() {
        let (p, t) = shared_cube();
        let g = generate(&p, &t, 60.0);
        // Every corner sees three face directions: 8 vertices × 3 normals.
        assert_eq!(g.normals.len(), 24);
        for (tri, new) in t.iter().zip(&g.triangles) {
            let [a, b, c] = tri.map(|v| p[v as usize]);
            let face = (b - a).cross(c - a).normalize();
            for &v in new {
                assert!((g.normals[v as usize] - face).length() < 1e-12);
            }
        }
    }

    #[test]
    fn cube_is_smooth_above_ninety_degrees() {
        let (p, t) = shared_cube();
        let g = generate(&p, &t, 91.0);
        assert_eq!(g.normals.len(), 8);
        for (v, n) in g.normals.iter().enumerate() {
            let corner = p[g.source_vertex[v] as usize] - DVec3::splat(0.5);
            // Angle weighting makes every cube corner's normal the diagonal direction.
            assert!((n.dot(corner.normalize()) - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn degenerate_faces_never_give_nan() {
        let p = vec![DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
        let g = generate(&p, &[[0, 1, 2]], 30.0);
        assert!(g
            .normals
            .iter()
            .all(|n| n.is_finite() && (n.length() - 1.0).abs() < 1e-12));
    }
}
