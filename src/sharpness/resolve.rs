//! Precedence: picks, for every welded edge, the most specific source that sets its h (see the
//! list in [`super`]). It deliberately parses nothing itself and reads no files.

use std::collections::HashMap;

use rayon::prelude::*;

use super::entries::{at, fmt_point, Block, EdgeEntry, Located};
use super::error::{Location, Problem, SharpnessError};
use super::explain::HSource;
use super::extras::{parse_block, Owner};
use super::naming::EdgeNamer;
use super::rules::{is_hard_edge, CreaseTest};
use super::{mesh_label, AssetSharpness, EdgeParams, EffectiveH, MeshContext, SharpnessWarning};
use crate::mesh::TriMesh;
use crate::topology::{Edge, EdgeId, EdgeKind, Topology};

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
    // The crease angle and extras default on the side of triangles outside every primitive.
    let outside_crease = section
        .and_then(|b| b.crease_angle.as_ref())
        .or(mesh_block.as_ref().and_then(|b| b.crease_angle.as_ref()))
        .or(sidecar_asset.and_then(|b| b.crease_angle.as_ref()));
    let outside_h = mesh_block
        .as_ref()
        .and_then(|b| b.h.as_ref())
        .map(|h| (h, false));
    let side_crease = |p: u32| match p {
        NO_PRIMITIVE => outside_crease,
        p => crease_of_prim[p as usize],
    };
    let side_h = |p: u32| match p {
        NO_PRIMITIVE => outside_h,
        p => extras_h_of_prim[p as usize],
    };

    // The crease rule of each side's angle, set up once rather than per edge.
    let default_test = CreaseTest::new(asset.defaults.crease_angle);
    let test_of =
        |angle: Option<&Located<f64>>| angle.map_or(default_test, |a| CreaseTest::new(a.value));
    let test_of_prim: Vec<CreaseTest> = crease_of_prim.iter().map(|a| test_of(*a)).collect();
    let outside_test = test_of(outside_crease);
    let side_test = |p: u32| match p {
        NO_PRIMITIVE => outside_test,
        p => test_of_prim[p as usize],
    };

    // Edges are independent: resolved in parallel, collected in edge order.
    let source_of = |(e, edge): (usize, Edge<'_>)| {
        let id = EdgeId(e as u32);
        // The primitives on the edge's sides, read straight from its uses: the sharpest
        // value wins, ties going to the lowest primitive (triangles outside every
        // primitive first), whatever the order of the uses.
        let sides = || edge.tris.iter().map(|u| prim_of_tri[u.at().0]);
        let (value, source) = if let Some(x) = sidecar_edges.get(&id) {
            (x.value, HSource::SidecarEdge(x.at.clone()))
        } else if let Some(x) = prim_edges.get(&id) {
            (x.value, HSource::PrimitiveExtrasEdge(x.at.clone()))
        } else if let Some(x) = mesh_edges.get(&id) {
            (x.value, HSource::MeshExtrasEdge(x.at.clone()))
        } else if let Some(rule) = crease_rule(
            &edge,
            topo,
            sharpest(sides(), |p| {
                side_crease(p).map_or(asset.defaults.crease_angle, |a| a.value)
            })
            .map_or((default_test, None), |p| (side_test(p), side_crease(p))),
        ) {
            (0.0, rule)
        } else if asset.defaults.keep_hard_edges && is_hard_edge(&edge) {
            (0.0, HSource::HardEdge)
        } else if let Some(x) = section.and_then(|b| b.h.as_ref()) {
            (x.value, HSource::SidecarMeshDefault(x.at.clone()))
        } else if let Some((x, on_prim)) = sharpest(sides().filter(|&p| side_h(p).is_some()), |p| {
            side_h(p).map_or(f64::INFINITY, |x| x.0.value)
        })
        .and_then(side_h)
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
        (value, EffectiveH::of_edge(edge.kind, value), source)
    };
    // The sources (32 bytes per edge) are kept only for `--explain-h`.
    let (h, (effective, sources)): (Vec<f64>, (Vec<f64>, Vec<HSource>)) = if asset.keep_sources {
        topo.par_edges()
            .enumerate()
            .map(|e| {
                let (value, effective, source) = source_of(e);
                (value, (effective, source))
            })
            .unzip()
    } else {
        let (h, effective) = topo
            .par_edges()
            .enumerate()
            .map(|e| {
                let (value, effective, _) = source_of(e);
                (value, effective)
            })
            .unzip();
        (h, (effective, Vec::new()))
    };
    Ok(EdgeParams {
        h,
        effective: EffectiveH::from_rule(effective),
        sources,
        warnings,
    })
}

/// The side (a primitive, or [`NO_PRIMITIVE`]) with the smallest `value`, ties going to the
/// smallest side with [`NO_PRIMITIVE`] first: the order a sorted, deduplicated list of sides
/// gives, without building one per edge.
fn sharpest(sides: impl Iterator<Item = u32>, value: impl Fn(u32) -> f64) -> Option<u32> {
    let rank = |p: u32| p.wrapping_add(1);
    sides
        .map(|p| (value(p), p))
        .min_by(|a, b| a.0.total_cmp(&b.0).then(rank(a.1).cmp(&rank(b.1))))
        .map(|(_, p)| p)
}

/// The crease rule for one edge under the sharpest of its sides' crease angles (`side`: that
/// side's rule, and where its angle was set, `None` for the options' angle): h = 0 if the faces
/// meet at more than that angle.
fn crease_rule(
    edge: &Edge<'_>,
    topo: &Topology,
    side: (CreaseTest, Option<&Located<f64>>),
) -> Option<HSource> {
    let (test, set_by) = side;
    let dihedral = test.dihedral_if_crease(edge, topo)?;
    Some(HSource::Crease {
        dihedral,
        crease_angle: test.crease_angle(),
        set_by: set_by.map(|a| a.at.clone()),
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

/// Marks a triangle outside every primitive in [`primitive_of_triangle`].
const NO_PRIMITIVE: u32 = u32::MAX;

/// Which entry of `ctx.primitives` each triangle came from, by its first corner's vertex range;
/// [`NO_PRIMITIVE`] for none (4 bytes a triangle where `Option<usize>` took 16).
fn primitive_of_triangle(ctx: &MeshContext<'_>, mesh: &TriMesh) -> Vec<u32> {
    let mut by_offset: Vec<usize> = (0..ctx.primitives.len()).collect();
    by_offset.sort_by_key(|&p| ctx.primitives[p].vertex_offset);
    mesh.triangles
        .par_iter()
        .map(|t| {
            let v = t[0];
            let after = by_offset.partition_point(|&p| ctx.primitives[p].vertex_offset <= v);
            let Some(&p) = after.checked_sub(1).and_then(|i| by_offset.get(i)) else {
                return NO_PRIMITIVE;
            };
            let prim = &ctx.primitives[p];
            if v - prim.vertex_offset < prim.vertex_count {
                p as u32
            } else {
                NO_PRIMITIVE
            }
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
