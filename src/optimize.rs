//! GPU-friendly ordering of a dense mesh with meshoptimizer: vertex cache order for the
//! triangles, then vertex fetch order for the vertices, optionally overdraw order in between.
//!
//! Every per-vertex stream of the [`DenseMesh`] is remapped together, so attributes carried
//! afterwards from `sources` follow. It deliberately leaves quantization and compression to the
//! writer.

use crate::tessellate::DenseMesh;
use meshopt::VertexDataAdapter;

/// meshoptimizer's cache statistics of an index buffer (ACMR: transformed vertices per
/// triangle; ATVR: per vertex), reported so the ordering's effect can be measured.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct CacheFigures {
    /// Average cache miss ratio: vertex shader invocations per triangle (0.5 is ideal).
    pub acmr: f32,
    /// Average transformed vertex ratio: invocations per vertex (1.0 is ideal).
    pub atvr: f32,
}

/// Cache figures of `mesh` for a 16-entry FIFO, meshoptimizer's reference model.
pub fn cache_figures(mesh: &DenseMesh) -> CacheFigures {
    let stats = meshopt::analyze_vertex_cache(&mesh.indices, mesh.positions.len(), 16, 0, 0);
    CacheFigures {
        acmr: stats.acmr,
        atvr: stats.atvr,
    }
}

/// Reorders `mesh` in place: vertex cache, optional overdraw (threshold 1.05, meshoptimizer's
/// recommended value), then vertex fetch. Deterministic.
///
/// Returns the vertex remap (old index → new index, `u32::MAX` for a vertex no triangle uses),
/// so that streams computed later for the same vertices (morph targets) can follow with
/// [`remap_stream`].
pub fn optimize(mesh: &mut DenseMesh, overdraw: bool) -> Vec<u32> {
    let vertex_count = mesh.positions.len();
    if mesh.indices.is_empty() || vertex_count == 0 {
        return (0..vertex_count as u32).collect();
    }
    meshopt::optimize_vertex_cache_in_place(&mut mesh.indices, vertex_count);
    if overdraw {
        let bytes = meshopt::typed_to_bytes(&mesh.positions);
        if let Ok(adapter) = VertexDataAdapter::new(bytes, 12, 0) {
            meshopt::optimize_overdraw_in_place(&mut mesh.indices, &adapter, 1.05);
        }
    }
    fetch_order(mesh)
}

/// Overdraw order (threshold 1.05) for a mesh whose triangles are already in vertex cache
/// order, as the tessellator emits them, then vertex fetch order. Returns the vertex remap like
/// [`optimize`].
pub fn order_for_overdraw(mesh: &mut DenseMesh) -> Vec<u32> {
    let vertex_count = mesh.positions.len();
    if mesh.indices.is_empty() || vertex_count == 0 {
        return (0..vertex_count as u32).collect();
    }
    let bytes = meshopt::typed_to_bytes(&mesh.positions);
    if let Ok(adapter) = VertexDataAdapter::new(bytes, 12, 0) {
        meshopt::optimize_overdraw_in_place(&mut mesh.indices, &adapter, 1.05);
    }
    fetch_order(mesh)
}

/// Renumbers vertices in order of first use by the index buffer; every stream follows.
fn fetch_order(mesh: &mut DenseMesh) -> Vec<u32> {
    let vertex_count = mesh.positions.len();
    let remap = meshopt::optimize_vertex_fetch_remap(&mesh.indices, vertex_count);
    let used = remap.iter().filter(|&&r| r != u32::MAX).count();
    mesh.indices = meshopt::remap_index_buffer(Some(&mesh.indices), vertex_count, &remap);
    mesh.positions = meshopt::remap_vertex_buffer(&mesh.positions, used, &remap);
    mesh.normals = meshopt::remap_vertex_buffer(&mesh.normals, used, &remap);
    mesh.sources = remap_stream(&mesh.sources, &remap, used);
    remap
}

/// Applies a remap from [`optimize`] to one more per-vertex stream; `used` is the number of
/// vertices kept.
pub fn remap_stream<T: Copy>(stream: &[T], remap: &[u32], used: usize) -> Vec<T> {
    let mut out: Vec<Option<T>> = vec![None; used];
    for (old, &new) in remap.iter().enumerate() {
        if new != u32::MAX {
            out[new as usize] = Some(stream[old]);
        }
    }
    out.into_iter().flatten().collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tessellate::VertexSource;

    #[test]
    fn reordering_keeps_every_triangle_and_improves_cache() {
        // A strip of 200 quads emitted in a cache-hostile order (every other quad).
        let cols = 200u32;
        let mut mesh = DenseMesh::default();
        for i in 0..=cols {
            for j in 0..2 {
                mesh.positions.push([i as f32, j as f32, 0.0]);
                mesh.normals.push([0.0, 0.0, 1.0]);
                mesh.sources.push(VertexSource::lattice(i, 1, j, 0));
            }
        }
        let quad = |i: u32| [2 * i, 2 * i + 2, 2 * i + 1, 2 * i + 2, 2 * i + 3, 2 * i + 1];
        for i in (0..cols).step_by(2).chain((1..cols).step_by(2)) {
            mesh.indices.extend_from_slice(&quad(i));
        }
        let triangles = |m: &DenseMesh| {
            let mut t: Vec<[[u32; 3]; 3]> = m
                .indices
                .chunks(3)
                .map(|c| {
                    let mut tri = [0; 3].map(|_| [0u32; 3]);
                    for k in 0..3 {
                        tri[k] = m.positions[c[k] as usize].map(f32::to_bits);
                    }
                    // Rotate so the smallest corner is first: same triangle, same winding.
                    let r = (0..3).min_by_key(|&k| tri[k]).unwrap();
                    [tri[r], tri[(r + 1) % 3], tri[(r + 2) % 3]]
                })
                .collect();
            t.sort();
            t
        };
        let before = triangles(&mesh);
        let acmr_before = cache_figures(&mesh).acmr;
        optimize(&mut mesh, false);
        assert_eq!(triangles(&mesh), before);
        assert!(cache_figures(&mesh).acmr < acmr_before);
        // Sources still travel with their positions.
        for (p, s) in mesh.positions.iter().zip(&mesh.sources) {
            assert_eq!(p[0], s.tri as f32);
            assert_eq!(p[1], s.bary()[1]);
        }
    }
}
