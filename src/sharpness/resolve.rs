//! Precedence: picks, for every welded edge, the most specific source that sets its h (see the
//! list in [`super`]). It deliberately parses nothing itself and reads no files.

use std::collections::HashMap;

use glam::DVec3;
use rayon::prelude::*;

use super::entries::{at, fmt_point, Block, EdgeEntry, Located};
use super::error::{Location, Problem, SharpnessError};
use super::explain::HSource;
use super::extras::{parse_block, Owner};
use super::naming::EdgeNamer;
use super::rules::{face_normals, is_hard_edge, CreaseTest};
use super::{mesh_label, AssetSharpness, EdgeParams, EffectiveH, MeshContext, SharpnessWarning};

use crate::mesh::TriMesh;
use crate::topology::{Edge, EdgeId, EdgeKind, Topology};

/// Resolves every edge's h for the mesh `ctx` describes; with `widths` off, only binds and
/// checks the edge entries (their errors and warnings), and picks no edge's h.
pub(crate) fn resolve(
    asset: &AssetSharpness,
    ctx: &MeshContext<'_>,
    mesh: &TriMesh,
    topo: &Topology,
    widths: bool,
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
    // Every error and warning of a resolution is found above: what follows only picks.
    if !widths {
        return Ok(EdgeParams {
            h: Vec::new(),
            effective: EffectiveH::default(),
            sources: Vec::new(),
            warnings,
        });
    }

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
    // Where every side agrees (one primitive, or several with the same blocks, covering every
    // vertex: the common case), an edge's sides need not be looked up at all, nor each
    // triangle's primitive found.
    let uniform = uniform_sides(ctx, mesh, &crease_of_prim, &extras_h_of_prim)
        .map(|(crease, h)| (test_of(crease), crease, h));
    let prim_of_tri = match uniform {
        Some(_) => Vec::new(),
        None => primitive_of_triangle(ctx, mesh),
    };

    // Each triangle's face normal once, for the crease rule on its three edges.
    let faces = face_normals(topo);
    // Edges are independent: resolved in parallel, collected in edge order.
    let pick = |(e, edge): &(usize, Edge<'_>)| {
        let id = EdgeId(*e as u32);
        // The primitives on the edge's sides, read straight from its uses: the sharpest
        // value wins, ties going to the lowest primitive (triangles outside every
        // primitive first), whatever the order of the uses.
        let sides = || edge.tris.iter().map(|u| prim_of_tri[u.at().0]);
        let uniform = uniform.filter(|_| !edge.tris.is_empty());
        if let Some(x) = entry_of(&sidecar_edges, id) {
            return Pick::SidecarEdge(x);
        }
        if let Some(x) = entry_of(&prim_edges, id) {
            return Pick::PrimitiveExtrasEdge(x);
        }
        if let Some(x) = entry_of(&mesh_edges, id) {
            return Pick::MeshExtrasEdge(x);
        }
        let crease_side = match uniform {
            Some((test, crease, _)) => (test, crease),
            None => sharpest(sides(), |p| {
                side_crease(p).map_or(asset.defaults.crease_angle, |a| a.value)
            })
            .map_or((default_test, None), |p| (side_test(p), side_crease(p))),
        };
        if let Some(rule) = crease_rule(edge, topo, &faces, crease_side) {
            return rule;
        }
        if asset.defaults.keep_hard_edges && is_hard_edge(edge) {
            return Pick::HardEdge;
        }
        if let Some(x) = section.and_then(|b| b.h.as_ref()) {
            return Pick::SidecarMeshDefault(x);
        }
        let side_default = match uniform {
            Some((_, _, h)) => h,
            None => sharpest(sides().filter(|&p| side_h(p).is_some()), |p| {
                side_h(p).map_or(f64::INFINITY, |x| x.0.value)
            })
            .and_then(side_h),
        };
        match (side_default, sidecar_asset.and_then(|b| b.h.as_ref())) {
            (Some((x, true)), _) => Pick::PrimitiveExtrasDefault(x),
            (Some((x, false)), _) => Pick::MeshExtrasDefault(x),
            (None, Some(x)) => Pick::SidecarAssetDefault(x),
            (None, None) => Pick::Options(asset.defaults.h),
        }
    };
    // The sources (32 bytes per edge) are kept only for `--explain-h`; the others never clone
    // a location.
    let (h, (effective, sources)): (Vec<f64>, (Vec<f64>, Vec<HSource>)) = if asset.keep_sources {
        topo.par_edges()
            .enumerate()
            .map(|e| {
                let picked = pick(&e);
                let value = picked.value();
                (
                    value,
                    (EffectiveH::of_edge(e.1.kind, value), picked.source()),
                )
            })
            .unzip()
    } else if asset.keep_requested {
        let (h, effective) = topo
            .par_edges()
            .enumerate()
            .map(|e| {
                let value = pick(&e).value();
                (value, EffectiveH::of_edge(e.1.kind, value))
            })
            .unzip();
        (h, (effective, Vec::new()))
    } else {
        let effective = topo
            .par_edges()
            .enumerate()
            .map(|e| EffectiveH::of_edge(e.1.kind, pick(&e).value()))
            .collect();
        (Vec::new(), (effective, Vec::new()))
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
fn crease_rule<'a>(
    edge: &Edge<'_>,
    topo: &Topology,
    faces: &[DVec3],
    side: (CreaseTest, Option<&'a Located<f64>>),
) -> Option<Pick<'a>> {
    let (test, set_by) = side;
    let dihedral = test.dihedral_if_crease(edge, topo, faces)?;
    Some(Pick::Crease {
        dihedral,
        crease_angle: test.crease_angle(),
        set_by,
    })
}

/// The entry of one precedence level for edge `id`; an empty level (the common case) is not
/// hashed into.
fn entry_of(level: &HashMap<EdgeId, Located<f64>>, id: EdgeId) -> Option<&Located<f64>> {
    if level.is_empty() {
        None
    } else {
        level.get(&id)
    }
}

/// The source that decided an edge's h, as [`HSource`] names it, holding references: turned
/// into an [`HSource`] (which shares each location) only where the sources are kept, so the
/// run without `--explain-h` touches no reference count per edge.
#[derive(Debug, Clone, Copy)]
enum Pick<'a> {
    SidecarEdge(&'a Located<f64>),
    PrimitiveExtrasEdge(&'a Located<f64>),
    MeshExtrasEdge(&'a Located<f64>),
    Crease {
        dihedral: f64,
        crease_angle: f64,
        set_by: Option<&'a Located<f64>>,
    },
    HardEdge,
    SidecarMeshDefault(&'a Located<f64>),
    PrimitiveExtrasDefault(&'a Located<f64>),
    MeshExtrasDefault(&'a Located<f64>),
    SidecarAssetDefault(&'a Located<f64>),
    /// The options' h.
    Options(f64),
}

impl Pick<'_> {
    /// The h this source asks for.
    fn value(self) -> f64 {
        match self {
            Pick::SidecarEdge(x)
            | Pick::PrimitiveExtrasEdge(x)
            | Pick::MeshExtrasEdge(x)
            | Pick::SidecarMeshDefault(x)
            | Pick::PrimitiveExtrasDefault(x)
            | Pick::MeshExtrasDefault(x)
            | Pick::SidecarAssetDefault(x) => x.value,
            Pick::Crease { .. } | Pick::HardEdge => 0.0,
            Pick::Options(h) => h,
        }
    }

    fn source(self) -> HSource {
        match self {
            Pick::SidecarEdge(x) => HSource::SidecarEdge(x.at.clone()),
            Pick::PrimitiveExtrasEdge(x) => HSource::PrimitiveExtrasEdge(x.at.clone()),
            Pick::MeshExtrasEdge(x) => HSource::MeshExtrasEdge(x.at.clone()),
            Pick::Crease {
                dihedral,
                crease_angle,
                set_by,
            } => HSource::Crease {
                dihedral,
                crease_angle,
                set_by: set_by.map(|a| a.at.clone()),
            },
            Pick::HardEdge => HSource::HardEdge,
            Pick::SidecarMeshDefault(x) => HSource::SidecarMeshDefault(x.at.clone()),
            Pick::PrimitiveExtrasDefault(x) => HSource::PrimitiveExtrasDefault(x.at.clone()),
            Pick::MeshExtrasDefault(x) => HSource::MeshExtrasDefault(x.at.clone()),
            Pick::SidecarAssetDefault(x) => HSource::SidecarAssetDefault(x.at.clone()),
            Pick::Options(_) => HSource::Options,
        }
    }
}

/// The crease angle and extras default h shared by every side of every edge, where there is
/// one: the primitives cover every vertex of the mesh (so no triangle lies outside them) and
/// all carry the same ones (the same block's, or none). `None` where sides may differ.
#[allow(clippy::type_complexity)]
fn uniform_sides<'a>(
    ctx: &MeshContext<'_>,
    mesh: &TriMesh,
    crease_of_prim: &[Option<&'a Located<f64>>],
    extras_h_of_prim: &[Option<(&'a Located<f64>, bool)>],
) -> Option<(Option<&'a Located<f64>>, Option<(&'a Located<f64>, bool)>)> {
    let mut ranges: Vec<(u32, u32)> = ctx
        .primitives
        .iter()
        .map(|p| (p.vertex_offset, p.vertex_count))
        .collect();
    ranges.sort_unstable();
    let mut end = 0u64;
    for (offset, count) in ranges {
        if u64::from(offset) != end {
            return None;
        }
        end += u64::from(count);
    }
    if end != mesh.positions.len() as u64 {
        return None;
    }
    let same_place = |a: Option<&Located<f64>>, b: Option<&Located<f64>>| match (a, b) {
        (Some(a), Some(b)) => std::ptr::eq(a, b),
        (a, b) => a.is_none() && b.is_none(),
    };
    let (&crease, &h) = (crease_of_prim.first()?, extras_h_of_prim.first()?);
    let agree = crease_of_prim.iter().all(|&c| same_place(c, crease))
        && extras_h_of_prim.iter().all(|&x| {
            same_place(x.map(|x| x.0), h.map(|h| h.0)) && x.map(|x| x.1) == h.map(|h| h.1)
        });
    agree.then_some((crease, h))
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

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use glam::DVec3;

    use super::*;
    use crate::sharpness::PrimitiveContext;

    fn located(value: f64) -> Located<f64> {
        Located {
            value,
            at: Arc::new(Location::Options),
        }
    }

    fn context<'a>(primitives: &'a [PrimitiveContext<'a>]) -> MeshContext<'a> {
        MeshContext {
            index: 0,
            name: None,
            extras: None,
            primitives,
        }
    }

    fn primitive(vertex_offset: u32, vertex_count: u32) -> PrimitiveContext<'static> {
        PrimitiveContext {
            index: 0,
            extras: None,
            vertex_offset,
            vertex_count,
        }
    }

    fn mesh(vertices: usize) -> TriMesh {
        TriMesh {
            positions: vec![DVec3::ZERO; vertices],
            normals: vec![DVec3::Z; vertices],
            triangles: Vec::new(),
        }
    }

    /// Sides are taken as one only where every triangle lies in a primitive and every
    /// primitive reads its crease angle and extras h from the same place: a gap in the vertex
    /// ranges (triangles outside every primitive), or two blocks that merely hold equal
    /// values, keep the per-edge lookup.
    #[test]
    fn sides_are_uniform_only_where_every_side_reads_the_same_blocks() {
        let (a, b) = (located(30.0), located(30.0));
        let (h, other_h) = (located(0.1), located(0.1));
        let two = [primitive(0, 4), primitive(4, 6)];
        let m = mesh(10);

        let same = uniform_sides(&context(&two), &m, &[Some(&a), Some(&a)], &[None, None]);
        assert!(same.is_some_and(|(c, x)| c.is_some_and(|c| std::ptr::eq(c, &a)) && x.is_none()));
        let none = uniform_sides(&context(&two), &m, &[None, None], &[None, None]);
        assert_eq!(
            none.map(|(c, x)| (c.is_none(), x.is_none())),
            Some((true, true))
        );

        // Equal values from two places: where each came from differs.
        assert!(uniform_sides(&context(&two), &m, &[Some(&a), Some(&b)], &[None, None]).is_none());
        assert!(uniform_sides(&context(&two), &m, &[Some(&a), None], &[None, None]).is_none());
        let hs = [Some((&h, true)), Some((&other_h, true))];
        assert!(uniform_sides(&context(&two), &m, &[None, None], &hs).is_none());
        let mesh_or_prim = [Some((&h, true)), Some((&h, false))];
        assert!(uniform_sides(&context(&two), &m, &[None, None], &mesh_or_prim).is_none());

        // Vertices outside every primitive: a gap, or past the last.
        let gap = [primitive(0, 4), primitive(5, 5)];
        assert!(uniform_sides(&context(&gap), &m, &[None, None], &[None, None]).is_none());
        assert!(uniform_sides(&context(&two), &mesh(11), &[None, None], &[None, None]).is_none());
        // In any order.
        let swapped = [primitive(4, 6), primitive(0, 4)];
        assert!(uniform_sides(&context(&swapped), &m, &[None, None], &[None, None]).is_some());
    }
}
