//! MikkTSpace tangents for the dense output, so normal maps baked against the standard tangent
//! basis keep working on the smooth mesh.
//!
//! Tangents are regenerated rather than interpolated: the input's tangents belong to the flat
//! low-poly surface, and MikkTSpace is what bakers and engines assume. It works on one indexed
//! triangle list; it does not decide whether tangents are wanted (the pipeline does).

use bevy_mikktspace::{generate_tangents, Geometry, TangentSpace};

struct Indexed<'a> {
    positions: &'a [[f32; 3]],
    normals: &'a [[f32; 3]],
    uvs: &'a [[f32; 2]],
    indices: &'a [u32],
    tangents: Vec<Option<[f32; 4]>>,
}

impl Indexed<'_> {
    fn vertex(&self, face: usize, vert: usize) -> usize {
        self.indices[face * 3 + vert] as usize
    }
}

impl Geometry for Indexed<'_> {
    fn num_faces(&self) -> usize {
        self.indices.len() / 3
    }
    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }
    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.positions[self.vertex(face, vert)]
    }
    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.normals[self.vertex(face, vert)]
    }
    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        self.uvs[self.vertex(face, vert)]
    }
    fn set_tangent(&mut self, tangent: Option<TangentSpace>, face: usize, vert: usize) {
        let v = self.vertex(face, vert);
        // MikkTSpace welds identical vertices itself, so every corner of one output vertex
        // receives the same tangent; keep the first.
        if self.tangents[v].is_none() {
            self.tangents[v] = tangent.map(|t| t.tangent_encoded());
        }
    }
}

/// One unit tangent with handedness (`w` = ±1) per vertex of an indexed triangle list.
///
/// A vertex MikkTSpace gives nothing for (only degenerate faces around it) gets a unit vector
/// perpendicular to its normal, so the output stays valid glTF.
pub fn generate(
    positions: &[[f32; 3]],
    normals: &[[f32; 3]],
    uvs: &[[f32; 2]],
    indices: &[u32],
) -> Vec<[f32; 4]> {
    let mut geometry = Indexed {
        positions,
        normals,
        uvs,
        indices,
        tangents: vec![None; positions.len()],
    };
    // The error type has no variants: generation cannot fail.
    let _ = generate_tangents(&mut geometry);
    geometry
        .tangents
        .iter()
        .zip(normals)
        .map(|(t, n)| match t {
            Some(t) if t[..3].iter().all(|x| x.is_finite()) && t[..3] != [0.0; 3] => *t,
            _ => perpendicular(*n),
        })
        .collect()
}

/// A unit vector perpendicular to `n`, with `w` = 1.
fn perpendicular(n: [f32; 3]) -> [f32; 4] {
    let n = glam::Vec3::from(n);
    let t = n.any_orthonormal_vector();
    let t = if t.is_finite() { t } else { glam::Vec3::X };
    [t.x, t.y, t.z, 1.0]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_quad_tangent_follows_u() {
        let positions = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let normals = [[0.0, 0.0, 1.0]; 4];
        let uvs = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let t = generate(&positions, &normals, &uvs, &[0, 1, 2, 0, 2, 3]);
        for tangent in t {
            assert!((tangent[0] - 1.0).abs() < 1e-6 && tangent[1].abs() < 1e-6);
            assert_eq!(tangent[3], 1.0);
        }
    }

    #[test]
    fn mirrored_uvs_flip_handedness() {
        let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let normals = [[0.0, 0.0, 1.0]; 3];
        let uvs = [[1.0, 0.0], [0.0, 0.0], [1.0, 1.0]];
        let t = generate(&positions, &normals, &uvs, &[0, 1, 2]);
        assert!(t.iter().all(|t| t[3] == -1.0));
    }
}
