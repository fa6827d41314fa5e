//! [`FlatSurface`]: the input triangles themselves, with the corner normals interpolated
//! linearly and normalized (Phong's normals). It builds nothing: it reads the mesh it borrows.
//!
//! It exists for one case: a level-1 tessellation writes only the lattice's corners, and every
//! output corner is the input vertex's own position and its normalized input normal, read from
//! the mesh by the tessellator without asking the surface (the surface is asked only where an
//! input normal has no direction). So the G² and PN surfaces, whose nets cost about 600 ns of
//! CPU and 88 bytes per input triangle to build, change no bit of a level-1 output wherever
//! every input normal normalizes; the pipeline hands the tessellator this surface instead
//! there ([`flat_is_exact`]). It deliberately is a true surface everywhere (not one that only
//! answers at corners), so that nothing that happens to read it can get a wrong value.

use glam::DVec3;

use super::{Surface, SurfacePoint};
use crate::mesh::TriMesh;

/// The flat triangles of a mesh with linearly interpolated normals (see the module docs).
#[derive(Debug, Clone, Copy)]
pub struct FlatSurface<'a> {
    mesh: &'a TriMesh,
}

impl<'a> FlatSurface<'a> {
    /// The flat surface of `mesh`.
    pub fn new(mesh: &'a TriMesh) -> Self {
        FlatSurface { mesh }
    }
}

impl Surface for FlatSurface<'_> {
    /// `Σ λ_i p_i`, with the normal `Σ λ_i n_i` normalized (the face normal where that sum has
    /// no direction, +z where the face has none either). At a corner: the vertex's own position
    /// and normalized normal, bit for bit, as the trait asks.
    fn evaluate(&self, tri: usize, bary: [f64; 3]) -> SurfacePoint {
        let t = self.mesh.triangles[tri];
        let p = t.map(|v| self.mesh.positions[v as usize]);
        let n = t.map(|v| self.mesh.normals[v as usize]);
        let face = || (p[1] - p[0]).cross(p[2] - p[0]).normalize_or(DVec3::Z);
        if let Some(c) = bary.iter().position(|&x| x == 1.0) {
            return SurfacePoint {
                position: p[c],
                normal: n[c].try_normalize().unwrap_or_else(face),
            };
        }
        let [a, b, c] = bary;
        SurfacePoint {
            position: a * p[0] + b * p[1] + c * p[2],
            normal: (a * n[0] + b * n[1] + c * n[2])
                .try_normalize()
                .unwrap_or_else(face),
        }
    }
}

/// Whether a level-1 tessellation of `mesh` on [`FlatSurface`] writes what it writes on any
/// surface that interpolates the input's corners: every input normal normalizes, so the
/// tessellator never asks the surface for a corner (see the module docs). One parallel pass
/// over the normals.
pub fn flat_is_exact(mesh: &TriMesh) -> bool {
    use rayon::prelude::*;
    mesh.normals
        .par_chunks(1 << 14)
        .all(|c| c.iter().all(|n| n.try_normalize().is_some()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners_are_the_vertices_and_inside_is_the_flat_triangle() {
        let mesh = TriMesh {
            positions: vec![
                DVec3::new(-0.0, 1.0, 2.0),
                DVec3::new(3.0, -1.0, 0.5),
                DVec3::new(1.0, 2.0, -0.25),
            ],
            normals: vec![DVec3::new(0.0, 0.0, 2.0), DVec3::X, DVec3::Y],
            triangles: vec![[0, 1, 2]],
        };
        let s = FlatSurface::new(&mesh);
        for c in 0..3 {
            let mut bary = [0.0; 3];
            bary[c] = 1.0;
            let at = s.evaluate(0, bary);
            // Bit for bit, sign of zero included.
            assert_eq!(
                at.position.to_array().map(f64::to_bits),
                mesh.positions[c].to_array().map(f64::to_bits)
            );
            assert_eq!(at.normal, mesh.normals[c].normalize());
        }
        let mid = s.evaluate(0, [0.25, 0.25, 0.5]);
        let expected =
            0.25 * mesh.positions[0] + 0.25 * mesh.positions[1] + 0.5 * mesh.positions[2];
        assert!((mid.position - expected).length() < 1e-15);
        assert!((mid.normal.length() - 1.0).abs() < 1e-15);
        assert!(flat_is_exact(&mesh));
        let mut broken = mesh.clone();
        broken.normals[1] = DVec3::ZERO;
        assert!(!flat_is_exact(&broken));
    }
}
