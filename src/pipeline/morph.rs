//! Morph targets on the smooth surface: each target's displaced mesh is smoothed with the same
//! topology, h and lattice (or per-edge counts), so its dense vertices correspond one to one with the base's.
//!
//! Interpolating the input deltas instead would move the dense vertices along the flat
//! low-poly triangles; re-evaluating the surface keeps the morphed shape as smooth as the base.
//! It deliberately computes absolute positions and normals only; deltas are taken where the
//! output primitive is built.

use std::ops::Range;

use glam::DVec3;

use super::density::Density;
use super::primitive_out::Prepared;
use crate::gltf_io::MorphDeltas;
use crate::mesh::TriMesh;
use crate::optimize::remap_stream;
use crate::options::Options;
use crate::sharpness::EffectiveH;
use crate::surface::scheme;
use crate::topology::Topology;

/// The surface of one morph target at the output vertices of one primitive.
#[derive(Debug, Clone, Default)]
pub struct TargetSurface {
    /// Absolute positions of the morphed surface.
    pub positions: Vec<[f32; 3]>,
    /// Its unit normals.
    pub normals: Vec<[f32; 3]>,
}

/// Per primitive, per target: the morphed surface at that primitive's output vertices; and
/// the warnings the targets' surfaces gave, each with its target (the report merges them with
/// the base surface's).
///
/// `remaps` are the vertex orders [`crate::optimize::order_for_overdraw`] gave each primitive (`None`
/// where it did not run).
#[allow(clippy::too_many_arguments)]
pub fn targets(
    mesh: &TriMesh,
    topo: &Topology,
    h: &EffectiveH,
    prepared: &[Prepared],
    groups: &[Range<usize>],
    density: &Density,
    options: &Options,
    remaps: &[Option<Vec<u32>>],
) -> (Vec<Vec<TargetSurface>>, Vec<(usize, scheme::Warning)>) {
    let count = prepared
        .iter()
        .map(|p| p.data.targets.len())
        .max()
        .unwrap_or(0);
    let mut out: Vec<Vec<TargetSurface>> = vec![Vec::with_capacity(count); prepared.len()];
    let mut warnings = Vec::new();
    for t in 0..count {
        let moved = displaced(mesh, prepared, t);
        // At a uniform level 1 the targets' output is their corners, as the base mesh's.
        let corners_only = matches!(density, Density::Level(1));
        let (surface, said) =
            super::mesh_job::surface_for(options, corners_only, false, &moved, topo, h);
        warnings.extend(said.into_iter().map(|w| (t, w)));
        let dense = density
            .tessellate(&moved, topo, h, surface.as_ref(), groups)
            .finish();
        for (k, d) in dense.into_iter().enumerate() {
            let (positions, normals) = match &remaps[k] {
                Some(remap) => {
                    let used = remap.iter().filter(|&&r| r != u32::MAX).count();
                    (
                        remap_stream(&d.positions, remap, used),
                        remap_stream(&d.normals, remap, used),
                    )
                }
                None => (d.positions, d.normals),
            };
            out[k].push(TargetSurface { positions, normals });
        }
    }
    (out, warnings)
}

/// The joined mesh displaced by target `t` (a primitive without that target stays put).
fn displaced(mesh: &TriMesh, prepared: &[Prepared], t: usize) -> TriMesh {
    let mut moved = mesh.clone();
    for p in prepared {
        let Some(target) = p.data.targets.get(t) else {
            continue;
        };
        let offset = p.vertex_offset as usize;
        let deltas = MorphDeltas::of(target);
        let len = moved.positions.len();
        let slots = |d: &[f32]| len.min(offset + d.len() / 3);
        let delta = |c: &[f32]| DVec3::new(c[0].into(), c[1].into(), c[2].into());
        if let Some(d) = deltas.positions {
            for (v, c) in (offset..slots(d)).zip(d.chunks_exact(3)) {
                moved.positions[v] += delta(c);
            }
        }
        if let Some(d) = deltas.normals {
            for (v, c) in (offset..slots(d)).zip(d.chunks_exact(3)) {
                let n = (mesh.normals[v] + delta(c)).normalize_or_zero();
                if n != DVec3::ZERO {
                    moved.normals[v] = n;
                }
            }
        }
    }
    moved
}
