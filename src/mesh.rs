//! The core's triangle mesh: positions, per-vertex unit normals and triangles, in `f64`.
//!
//! It deliberately carries no glTF attributes: the I/O layer maps accessors to and from it.

use glam::DVec3;

/// An indexed triangle mesh as the surface code sees it.
///
/// Vertices are not welded: two vertices may share a position (a UV seam or a hard edge);
/// [`crate::topology`] welds them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// One unit normal per vertex.
    pub normals: Vec<DVec3>,
    /// Corner indices into `positions`/`normals`, three per triangle.
    pub triangles: Vec<[u32; 3]>,
}
