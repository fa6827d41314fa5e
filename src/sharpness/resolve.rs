//! Precedence: picks, for every welded edge, the most specific source that sets its h (see the
//! list in [`super`]). It deliberately parses nothing itself and reads no files.

use std::collections::HashMap;

use super::entries::{at, fmt_point, Block, EdgeEntry, Located};
use super::error::{Location, Problem, SharpnessError};
use super::explain::HSource;
use super::extras::{parse_block, Owner};
use super::naming::EdgeNamer;
use super::rules::{dihedral_degrees, is_crease, is_hard_edge};
use super::{mesh_label, AssetSharpness, EdgeParams, MeshContext, SharpnessWarning};
use crate::mesh::TriMesh;
use crate::topology::{EdgeId, EdgeKind, Topology};

pub(crate) fn resolve(
    asset: &AssetSharpness,
    ctx: &MeshContext<'_>,
    mesh: &TriMesh,
    topo: &Topology,
) -> Result<EdgeParams, SharpnessError> {
    check_context(ctx, mesh, topo)?;
    let label = mesh_label(ctx.index, ctx.name);
    let base = format!("meshes[{}]", ctx.index);
    let mesh_block = parse_block(&asset.asset, &base, ctx.extras, Owner::Mesh)?;
    let prim_blocks = ctx
        .primitives
        .iter()
        .map(|p| {
            let base = format!("{base}.primitives[{}]", p.index);
            parse_block(&asset.asset, &base, p.extras, Owner::Primitive)
        })
        .collect::<Result<Vec<_>, _>>()?;
    let sidecar_asset = asset.sidecar.as_ref().map(|sc| &sc.asset);
    let section = asset
        .section_of_mesh
        .get(&ctx.index)
        .and_then(|&s| asset.sidecar.as_ref().map(|sc| &sc.meshes[s].block));

    // Levels 1 and 2: explicit edge entries, each level checked for conflicting duplicates.
    let namer = EdgeNamer::new(mesh, topo, ctx.primitives, &label);
    let mut warnings = Vec::new();
    let mut explicit = Explicit {
        namer: &namer,
        topo,
        warnings: &mut warnings,
    };
    let sidecar_edges = explicit.level(section.into_iter().map(|b| (b, None)))?;
    let prim_edges = explicit.level(
        prim_blocks
            .iter()
            .zip(ctx.primitives)
            .filter_map(|(b, p)| b.as_ref().map(|b| (b, Some(p.index)))),
    )?;
    let mesh_edges = explicit.level(mesh_block.iter().map(|b| (b, None)))?;

    // Per primitive: the crease angle and the extras default h that apply on its side.
    let crease_of_prim: Vec<Option<&Located<f64>>> = prim_blocks
        .iter()
        .map(|pb| {
            section
                .and_then(|b| b.crease_angle.as_ref())
                .or(pb.as_ref().and_then(|b| b.crease_angle.as_ref()))
                .or(mesh_block.as_ref().and_then(|b| b.crease_angle.as_ref()))
                .or(sidecar_asset.and_then(|b| b.crease_angle.as_ref()))
        })
        .collect();
    let extras_h_of_prim: Vec<Option<(&Located<f64>, bool)>> = prim_blocks
        .iter()
        .map(|pb| {
            let prim = pb.as_ref().and_then(|b| b.h.as_ref()).map(|h| (h, true));
            prim.or(mesh_block
                .as_ref()
                .and_then(|b| b.h.as_ref())
                .map(|h| (h, false)))
        })
        .collect();
    let prim_of_tri = primitive_of_triangle(ctx, mesh);

    let mut h = Vec::with_capacity(topo.edges.len());
    let mut effective = Vec::with_capacity(topo.edges.len());
    let mut sources = Vec::with_capacity(topo.edges.len());
    for (e, edge) in topo.edges.iter().enumerate() {
        let id = EdgeId(e as u32);
        // The primitives on the edge's sides; `None` for triangles outside every primitive.
        let mut sides: Vec<Option<usize>> = edge
            .tris
            .iter()
            .map(|&(t, _)| prim_of_tri[t.0 as usize])
            .collect();
        sides.sort_unstable();
        sides.dedup();
        let side_crease = |p: &Option<usize>| match p {
            Some(p) => crease_of_prim[*p],
            None => section
                .and_then(|b| b.crease_angle.as_ref())
                .or(mesh_block.as_ref().and_then(|b| b.crease_angle.as_ref()))
                .or(sidecar_asset.and_then(|b| b.crease_angle.as_ref())),
        };
        let side_h = |p: &Option<usize>| match p {
            Some(p) => extras_h_of_prim[*p],
            None => mesh_block
                .as_ref()
                .and_then(|b| b.h.as_ref())
                .map(|h| (h, false)),
        };

        let (value, source) = if let Some(x) = sidecar_edges.get(&id) {
            (x.value, HSource::SidecarEdge(x.at.clone()))
        } else if let Some(x) = prim_edges.get(&id) {
            (x.value, HSource::PrimitiveExtrasEdge(x.at.clone()))
        } else if let Some(x) = mesh_edges.get(&id) {
            (x.value, HSource::MeshExtrasEdge(x.at.clone()))
        } else if let Some(rule) = crease_rule(
            edge,
            topo,
            sides.iter().map(side_crease),
            asset.defaults.crease_angle,
        ) {
            (0.0, rule)
        } else if asset.defaults.keep_hard_edges && is_hard_edge(edge) {
            (0.0, HSource::HardEdge)
        } else if let Some(x) = section.and_then(|b| b.h.as_ref()) {
            (x.value, HSource::SidecarMeshDefault(x.at.clone()))
        } else if let Some((x, on_prim)) = sides
            .iter()
            .filter_map(side_h)
            .min_by(|a, b| a.0.value.total_cmp(&b.0.value))
        {
            let at = x.at.clone();
            let source = if on_prim {
                HSource::PrimitiveExtrasDefault(at)
            } else {
                HSource::MeshExtrasDefault(at)
            };
            (x.value, source)
        } else if let Some(x) = sidecar_asset.and_then(|b| b.h.as_ref()) {
            (x.value, HSource::SidecarAssetDefault(x.at.clone()))
        } else {
            (asset.defaults.h, HSource::Options)
        };
        effective.push(effective_h(edge.kind, value));
        h.push(value);
        sources.push(source);
    }
    Ok(EdgeParams {
        h,
        effective,
        sources,
        warnings,
    })
}

/// The h an edge is built with, decided here once for every later stage: the resolved value
/// (already in range, the printed bound clamped to √2/4) on interior edges, 0 on boundary,
/// non-manifold and degenerate edges, which the surface never blends. An explicit entry asking
/// for more on such an edge is warned about where it is read ([`Explicit::note`]); a default
/// that merely covers it is not, so an open mesh at default settings gives no warning.
fn effective_h(kind: EdgeKind, value: f64) -> f64 {
    if kind == EdgeKind::Interior {
        crate::options::clamp_h(value)
    } else {
        0.0
    }
}

/// The crease rule for one edge: the sharpest crease angle over its sides (the options' when no
/// side sets one), and h = 0 if the faces meet at more than that.
fn crease_rule<'a>(
    edge: &crate::topology::Edge,
    topo: &Topology,
    side_angles: impl Iterator<Item = Option<&'a Located<f64>>>,
    default_angle: f64,
) -> Option<HSource> {
    let dihedral = dihedral_degrees(edge, topo)?;
    let (crease_angle, set_by) = side_angles
        .map(|a| a.map_or((default_angle, None), |a| (a.value, Some(a.at.clone()))))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap_or((default_angle, None));
    is_crease(dihedral, crease_angle).then_some(HSource::Crease {
        dihedral,
        crease_angle,
        set_by,
    })
}

/// Collects one precedence level of edge entries into a map, rejecting two different h for one
/// edge and noting entries that ask for blending where the surface never blends.
struct Explicit<'n, 'a> {
    namer: &'n EdgeNamer<'a>,
    topo: &'n Topology,
    warnings: &'n mut Vec<SharpnessWarning>,
}

impl Explicit<'_, '_> {
    fn level<'b>(
        &mut self,
        blocks: impl Iterator<Item = (&'b Block, Option<usize>)>,
    ) -> Result<HashMap<EdgeId, Located<f64>>, SharpnessError> {
        let mut level: HashMap<EdgeId, Located<f64>> = HashMap::new();
        for (block, implied) in blocks {
            for entry in &block.edges {
                let id = self.namer.edge_of(entry, implied)?;
                self.note(id, entry);
                match level.get(&id) {
                    Some(first) if first.value != entry.h => {
                        return Err(at(&entry.at, self.conflict(id, entry.h, first)));
                    }
                    Some(_) => {}
                    None => {
                        level.insert(
                            id,
                            Located {
                                value: entry.h,
                                at: entry.at.clone(),
                            },
                        );
                    }
                }
            }
        }
        Ok(level)
    }

    fn note(&mut self, id: EdgeId, entry: &EdgeEntry) {
        let kind = self.topo.edge(id).kind;
        if kind != EdgeKind::Interior && entry.h > 0.0 {
            self.warnings.push(SharpnessWarning::EntryOnUnblendedEdge {
                at: Location::clone(&entry.at),
                edge: id,
                kind,
                h: entry.h,
            });
        }
    }

    fn conflict(&self, id: EdgeId, h: f64, first: &Located<f64>) -> Problem {
        let [a, b] = self.topo.edge(id).verts;
        let p = |v: crate::topology::VertId| fmt_point(self.topo.welded_positions[v.0 as usize]);
        Problem::Conflict {
            edge: format!("{}–{}", p(a), p(b)),
            h,
            other_h: first.value,
            other: first.at.to_string(),
        }
    }
}

/// Which entry of `ctx.primitives` each triangle came from, by its first corner's vertex range.
fn primitive_of_triangle(ctx: &MeshContext<'_>, mesh: &TriMesh) -> Vec<Option<usize>> {
    let mut by_offset: Vec<usize> = (0..ctx.primitives.len()).collect();
    by_offset.sort_by_key(|&p| ctx.primitives[p].vertex_offset);
    mesh.triangles
        .iter()
        .map(|t| {
            let v = t[0];
            let after = by_offset.partition_point(|&p| ctx.primitives[p].vertex_offset <= v);
            let p = *by_offset.get(after.checked_sub(1)?)?;
            let prim = &ctx.primitives[p];
            (v - prim.vertex_offset < prim.vertex_count).then_some(p)
        })
        .collect()
}

/// The caller's context must fit the mesh it describes; a mismatch is a pipeline bug.
fn check_context(
    ctx: &MeshContext<'_>,
    mesh: &TriMesh,
    topo: &Topology,
) -> Result<(), SharpnessError> {
    let internal =
        |message: String| SharpnessError::new(Location::Options, Problem::Internal { message });
    for p in ctx.primitives {
        let end = u64::from(p.vertex_offset) + u64::from(p.vertex_count);
        if end > mesh.positions.len() as u64 {
            return Err(internal(format!(
                "primitive {} of mesh {} claims vertices up to {end}, the combined mesh has {}",
                p.index,
                ctx.index,
                mesh.positions.len()
            )));
        }
    }
    if topo.welded_of_vertex.len() != mesh.positions.len()
        || topo.tri_verts.len() != mesh.triangles.len()
    {
        return Err(internal(format!(
            "the topology of mesh {} was built from a different mesh",
            ctx.index
        )));
    }
    Ok(())
}
