//! Everything the pipeline repaired, ignored or found odd in a mesh, as one typed value per
//! warning: which mesh, primitive, accessor, edge, triangle or vertex, how many, and the
//! fallback applied.
//!
//! The stages hand these facts to the report unformatted; the text users read is made only at
//! the edge, by [`std::fmt::Display`] (the CLI's lines, the JSON report's `message`, the HTML
//! report). The JSON report also writes each warning as an object (`kind`, its location and
//! counts, `message`), so a build can gate on a kind without parsing sentences.
//!
//! Numbering: triangles and vertices of the geometry checks count over the mesh's triangle
//! primitives joined in file order (the first primitive's first), after a primitive without
//! normals had its vertices split where its generated normals are; edges and welded vertices
//! are those of the welded mesh, as `--explain-h` lists them; vertices of the normal warnings
//! are the primitive's own, as read.

use std::fmt;

use serde::ser::SerializeMap;
use serde::{Serialize, Serializer};

use crate::sharpness::{Location, SharpnessWarning};
use crate::surface::scheme;
use crate::topology::{EdgeId, EdgeKind};

/// One warning of one mesh, with the facts that locate it.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum Warning {
    /// Zero-area triangles (`triangles`: the first few): kept flat, their edges not blended.
    DegenerateTriangles {
        mesh: usize,
        count: usize,
        triangles: Vec<usize>,
    },
    /// Triangles with an angle below 0.06° (`triangles`: the first few): smoothed like the others.
    SliverTriangles {
        mesh: usize,
        count: usize,
        triangles: Vec<usize>,
    },
    /// Triangles with the corners of an earlier one (`triangles`: the first few): kept, their shared
    /// edges not blended.
    DuplicateTriangles {
        mesh: usize,
        count: usize,
        triangles: Vec<usize>,
    },
    /// Vertices no triangle uses (`vertices`: the first few): not written.
    UnusedVertices {
        mesh: usize,
        count: usize,
        vertices: Vec<usize>,
    },
    /// Triangles whose three normals face away from their winding (`triangles`: the first few): the
    /// surface follows the normals.
    NormalsFacingAway {
        mesh: usize,
        count: usize,
        triangles: Vec<usize>,
    },
    /// Open boundary edges: not blended, the surface follows the input there.
    BoundaryEdges { mesh: usize, count: usize },
    /// Edges of three or more triangles (`edges`: the first few welded edges): not blended.
    NonManifoldEdges {
        mesh: usize,
        count: usize,
        edges: Vec<usize>,
    },
    /// Interior edges between triangles of opposite winding (`edges`: the first few welded edges): smoothed
    /// as usual.
    OppositeWindingEdges {
        mesh: usize,
        count: usize,
        edges: Vec<usize>,
    },
    /// Welded vertices where triangle fans touch only at the vertex (`vertices`: the
    /// first few welded vertices): each fan smoothed on its own.
    BowTieVertices {
        mesh: usize,
        count: usize,
        vertices: Vec<usize>,
    },
    /// More disconnected pieces than a welded mesh would have: each smoothed on its own.
    ManyPieces { mesh: usize, pieces: usize },
    /// Normals not of unit length within the validator's tolerance: normalized.
    NormalsRescaled {
        mesh: usize,
        primitive: usize,
        /// The NORMAL accessor, when known.
        accessor: Option<usize>,
        count: usize,
        /// The first such vertex of the primitive, and its normal's length.
        vertex: usize,
        length: f32,
    },
    /// Zero-length normals: replaced by the angle-weighted normal of their faces.
    NormalsRepaired {
        mesh: usize,
        primitive: usize,
        accessor: Option<usize>,
        count: usize,
        /// The first such vertex of the primitive.
        vertex: usize,
    },
    /// A primitive without NORMAL: normals generated, split at `crease_angle` degrees.
    NormalsGenerated {
        mesh: usize,
        primitive: usize,
        crease_angle: f64,
    },
    /// An h entry asks for h > 0 on an edge that is never blended: it has no effect.
    UnblendedEdgeEntry {
        mesh: usize,
        /// The welded edge the entry names.
        edge: usize,
        #[serde(serialize_with = "serialize_edge_kind")]
        edge_kind: EdgeKind,
        h: f64,
        /// Where the entry is (sidecar line or glTF extras path).
        #[serde(serialize_with = "serialize_location")]
        at: Location,
    },
    /// The hybrid scheme found no projection plane for `count` folded interior edges (the first:
    /// welded edge `edge`): they are creases. `targets` names the morph targets whose surfaces
    /// said so (empty: the base's).
    NoProjectionPlane {
        mesh: usize,
        targets: Vec<usize>,
        count: usize,
        edge: usize,
    },
    /// A node showing a mesh with a LOD chain cannot carry `MSFT_lod` (`reason` says why): it
    /// shows the finest level only.
    LodNodeNotLinked {
        mesh: usize,
        node: usize,
        reason: String,
    },
    /// No node can show the coarser levels of a mesh's LOD chain: only the finest is written.
    LodNotShown { mesh: usize },
}

impl Warning {
    /// The glTF mesh it is about.
    pub fn mesh(&self) -> usize {
        match self {
            Warning::DegenerateTriangles { mesh, .. }
            | Warning::SliverTriangles { mesh, .. }
            | Warning::DuplicateTriangles { mesh, .. }
            | Warning::UnusedVertices { mesh, .. }
            | Warning::NormalsFacingAway { mesh, .. }
            | Warning::BoundaryEdges { mesh, .. }
            | Warning::NonManifoldEdges { mesh, .. }
            | Warning::OppositeWindingEdges { mesh, .. }
            | Warning::BowTieVertices { mesh, .. }
            | Warning::ManyPieces { mesh, .. }
            | Warning::NormalsRescaled { mesh, .. }
            | Warning::NormalsRepaired { mesh, .. }
            | Warning::NormalsGenerated { mesh, .. }
            | Warning::UnblendedEdgeEntry { mesh, .. }
            | Warning::NoProjectionPlane { mesh, .. }
            | Warning::LodNodeNotLinked { mesh, .. }
            | Warning::LodNotShown { mesh } => *mesh,
        }
    }

    /// The sharpness stage's warning about mesh `mesh`.
    pub fn from_sharpness(mesh: usize, w: &SharpnessWarning) -> Warning {
        match w {
            SharpnessWarning::EntryOnUnblendedEdge { at, edge, kind, h } => {
                Warning::UnblendedEdgeEntry {
                    mesh,
                    edge: edge.0 as usize,
                    edge_kind: *kind,
                    h: *h,
                    at: at.clone(),
                }
            }
        }
    }

    /// A surface's warning about mesh `mesh`, from the base surface (`target` `None`) or the
    /// surface of one morph target.
    pub fn from_surface(mesh: usize, target: Option<usize>, w: &scheme::Warning) -> Warning {
        let targets: Vec<usize> = target.into_iter().collect();
        match w {
            scheme::Warning::NoProjectionPlane { edges, first } => Warning::NoProjectionPlane {
                mesh,
                targets,
                count: *edges,
                edge: first.0 as usize,
            },
        }
    }

    /// The morph targets whose surfaces gave it (empty for everything else).
    pub fn targets(&self) -> &[usize] {
        match self {
            Warning::NoProjectionPlane { targets, .. } => targets,
            _ => &[],
        }
    }

    /// Whether `self` and `other` say the same thing, whichever surfaces said it.
    fn same_but_targets(&self, other: &Warning) -> bool {
        let mut a = self.clone();
        let mut b = other.clone();
        a.set_targets(Vec::new());
        b.set_targets(Vec::new());
        a == b
    }

    fn set_targets(&mut self, to: Vec<usize>) {
        if let Warning::NoProjectionPlane { targets, .. } = self {
            *targets = to;
        }
    }
}

/// Adds the morph-target surfaces' warnings `from_targets` to `warnings` without noise: one
/// that the base surface (or an earlier warning) already says is dropped, and one that several
/// targets say becomes one warning naming them all. Quadratic in the number of warnings, which
/// is a handful per surface (one per kind), not per edge.
pub fn merge_target_warnings(warnings: &mut Vec<Warning>, from_targets: Vec<Warning>) {
    for w in from_targets {
        let base = warnings
            .iter()
            .position(|x| x.targets().is_empty() && x.same_but_targets(&w));
        if base.is_some() {
            continue;
        }
        match warnings
            .iter_mut()
            .find(|x| !x.targets().is_empty() && x.same_but_targets(&w))
        {
            Some(x) => {
                let mut targets = x.targets().to_vec();
                targets.extend_from_slice(w.targets());
                targets.sort_unstable();
                targets.dedup();
                x.set_targets(targets);
            }
            None => warnings.push(w),
        }
    }
}

/// The sentence users have always read: `mesh 0: 3 zero-area triangles (first: 4, 7, 9) …`,
/// or an accessor path for the normal warnings, or the sidecar line for an h entry. The
/// sharpness stage's and the surfaces' warnings keep the words of their own `Display`.
impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Warning::DegenerateTriangles {
                mesh,
                count,
                triangles,
            } => summary(
                f,
                *mesh,
                *count,
                triangles,
                "zero-area triangles",
                "are kept flat; their edges are not blended",
            ),
            Warning::SliverTriangles {
                mesh,
                count,
                triangles,
            } => summary(
                f,
                *mesh,
                *count,
                triangles,
                "sliver triangles",
                "(an angle below 0.06°) are smoothed like the others; their shading may be poor",
            ),
            Warning::DuplicateTriangles {
                mesh,
                count,
                triangles,
            } => summary(
                f,
                *mesh,
                *count,
                triangles,
                "duplicate triangles",
                "(same corners as an earlier one) are kept; their shared edges are not blended",
            ),
            Warning::UnusedVertices {
                mesh,
                count,
                vertices,
            } => summary(
                f,
                *mesh,
                *count,
                vertices,
                "vertices used by no triangle",
                "are not written",
            ),
            Warning::NormalsFacingAway {
                mesh,
                count,
                triangles,
            } => summary(
                f,
                *mesh,
                *count,
                triangles,
                "triangles whose normals all face away from their winding",
                "follow their normals (the surface is oriented by the normals, not the winding)",
            ),
            Warning::BoundaryEdges { mesh, count } => write!(
                f,
                "mesh {mesh}: {count} open boundary edges are not blended (the surface follows the input there)"
            ),
            Warning::NonManifoldEdges {
                mesh,
                count,
                edges,
            } => summary(
                f,
                *mesh,
                *count,
                edges,
                "non-manifold edges (three or more triangles)",
                "are not blended",
            ),
            Warning::OppositeWindingEdges {
                mesh,
                count,
                edges,
            } => summary(
                f,
                *mesh,
                *count,
                edges,
                "edges between triangles of opposite winding",
                "are smoothed as usual (the surface is oriented by the normals, not the winding)",
            ),
            Warning::BowTieVertices {
                mesh,
                count,
                vertices,
            } => summary(
                f,
                *mesh,
                *count,
                vertices,
                "bow-tie vertices (triangle fans that touch only at the vertex)",
                "are kept; each fan is smoothed on its own",
            ),
            Warning::LodNodeNotLinked { mesh, node, reason } => write!(
                f,
                "nodes[{node}]: mesh {mesh}'s coarser levels are not linked to this node: {reason}"
            ),
            Warning::LodNotShown { mesh } => write!(
                f,
                "meshes[{mesh}]: no node can show its coarser levels; only the finest level is written"
            ),
            Warning::ManyPieces { mesh, pieces } => write!(
                f,
                "mesh {mesh}: {pieces} disconnected pieces; each is smoothed on its own (expected a welded mesh?)"
            ),
            Warning::NormalsRescaled {
                mesh,
                primitive,
                accessor,
                count,
                vertex,
                length,
            } => write!(
                f,
                "meshes[{mesh}].primitives[{primitive}].attributes.NORMAL{}: {count} normals not of unit length (first: vertex {vertex}, length {length}) normalized",
                accessor_label(*accessor)
            ),
            Warning::NormalsRepaired {
                mesh,
                primitive,
                accessor,
                count,
                vertex,
            } => write!(
                f,
                "meshes[{mesh}].primitives[{primitive}].attributes.NORMAL{}: {count} zero-length normals (first: vertex {vertex}) replaced by the angle-weighted normal of their faces",
                accessor_label(*accessor)
            ),
            Warning::NormalsGenerated {
                mesh,
                primitive,
                crease_angle,
            } => write!(
                f,
                "meshes[{mesh}].primitives[{primitive}]: no NORMAL; normals generated (angle-weighted, split at {crease_angle}°)"
            ),
            Warning::UnblendedEdgeEntry {
                edge,
                edge_kind,
                h,
                at,
                ..
            } => SharpnessWarning::EntryOnUnblendedEdge {
                at: at.clone(),
                edge: EdgeId(*edge as u32),
                kind: *edge_kind,
                h: *h,
            }
            .fmt(f),
            Warning::NoProjectionPlane {
                mesh,
                targets,
                count,
                edge,
            } => {
                surface_prefix(f, *mesh, targets)?;
                scheme::Warning::NoProjectionPlane {
                    edges: *count,
                    first: EdgeId(*edge as u32),
                }
                .fmt(f)
            }
        }
    }
}

/// "mesh i: N things (first: a, b, c) fallback".
fn summary(
    f: &mut fmt::Formatter<'_>,
    mesh: usize,
    count: usize,
    first: &[usize],
    noun: &str,
    what: &str,
) -> fmt::Result {
    let list: Vec<String> = first.iter().map(ToString::to_string).collect();
    write!(
        f,
        "mesh {mesh}: {count} {noun} (first: {}) {what}",
        list.join(", ")
    )
}

/// "mesh i: " for the base surface, "mesh i, morph targets 1, 3: " for targets' surfaces.
fn surface_prefix(f: &mut fmt::Formatter<'_>, mesh: usize, targets: &[usize]) -> fmt::Result {
    match targets {
        [] => write!(f, "mesh {mesh}: "),
        [t] => write!(f, "mesh {mesh}, morph target {t}: "),
        many => {
            let list: Vec<String> = many.iter().map(ToString::to_string).collect();
            write!(f, "mesh {mesh}, morph targets {}: ", list.join(", "))
        }
    }
}

/// `" (accessors[3])"`, or nothing when the accessor is not known.
fn accessor_label(accessor: Option<usize>) -> String {
    accessor.map_or(String::new(), |a| format!(" (accessors[{a}])"))
}

/// The JSON name of an edge kind (the report's `edge_kind` field).
fn kind_name(kind: EdgeKind) -> &'static str {
    match kind {
        EdgeKind::Interior => "interior",
        EdgeKind::Boundary => "boundary",
        EdgeKind::NonManifold => "non_manifold",
        EdgeKind::Degenerate => "degenerate",
    }
}

fn serialize_edge_kind<S: Serializer>(kind: &EdgeKind, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(kind_name(*kind))
}

/// A location as `{"file": …, "line": …, "path": …}` (each only where it applies).
fn serialize_location<S: Serializer>(at: &Location, s: S) -> Result<S::Ok, S::Error> {
    let mut map = s.serialize_map(None)?;
    match at {
        Location::Json { file, path } => {
            map.serialize_entry("file", &file.display().to_string())?;
            map.serialize_entry("path", path)?;
        }
        Location::Toml { file, line, path } => {
            map.serialize_entry("file", &file.display().to_string())?;
            map.serialize_entry("line", line)?;
            if !path.is_empty() {
                map.serialize_entry("path", path)?;
            }
        }
        Location::File { file } => map.serialize_entry("file", &file.display().to_string())?,
        Location::Options => map.serialize_entry("file", "options")?,
    }
    map.end()
}

/// A list of warnings as the report writes it: `warnings`, the sentences (what the report has
/// always held), and `warning_details`, one object per warning with its `kind`, facts and the
/// same sentence as `message`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Warnings(pub Vec<Warning>);

impl Serialize for Warnings {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        serialize_warnings(self.0.iter(), s)
    }
}

/// Serializes `warnings` as the two fields `warnings` and `warning_details` (see [`Warnings`]),
/// for flattening into a record.
fn serialize_warnings<'a, S: Serializer>(
    warnings: impl Iterator<Item = &'a Warning> + Clone,
    s: S,
) -> Result<S::Ok, S::Error> {
    #[derive(Serialize)]
    struct Detail<'a> {
        #[serde(flatten)]
        warning: &'a Warning,
        message: String,
    }
    let messages: Vec<String> = warnings.clone().map(ToString::to_string).collect();
    let details: Vec<Detail> = warnings
        .zip(&messages)
        .map(|(warning, m)| Detail {
            warning,
            message: m.clone(),
        })
        .collect();
    let mut map = s.serialize_map(Some(2))?;
    map.serialize_entry("warnings", &messages)?;
    map.serialize_entry("warning_details", &details)?;
    map.end()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(targets: Vec<usize>, count: usize) -> Warning {
        Warning::NoProjectionPlane {
            mesh: 2,
            targets,
            count,
            edge: 7,
        }
    }

    #[test]
    fn target_warnings_said_by_the_base_are_dropped_and_the_rest_merged() {
        let mut all = vec![plane(vec![], 3)];
        merge_target_warnings(
            &mut all,
            vec![
                plane(vec![0], 3),
                plane(vec![1], 5),
                plane(vec![2], 3),
                plane(vec![3], 5),
            ],
        );
        assert_eq!(all, vec![plane(vec![], 3), plane(vec![1, 3], 5)]);
        assert_eq!(
            all[1].to_string(),
            "mesh 2, morph targets 1, 3: no projection plane for 5 folded edge(s) (first: edge 7); they are creases"
        );
    }

    /// The sentences of the surfaces' and the sharpness stage's warnings are the ones their own
    /// `Display` gave, prefixed with the mesh as the report always did.
    #[test]
    fn surface_and_sharpness_sentences_are_unchanged() {
        let said = [scheme::Warning::NoProjectionPlane {
            edges: 3,
            first: EdgeId(9),
        }];
        for w in &said {
            assert_eq!(
                Warning::from_surface(5, None, w).to_string(),
                format!("mesh 5: {w}")
            );
        }
        let entry = SharpnessWarning::EntryOnUnblendedEdge {
            at: Location::Toml {
                file: "robot.g2tess.toml".into(),
                line: 2,
                path: "edges[0]".into(),
            },
            edge: EdgeId(3),
            kind: EdgeKind::Boundary,
            h: 0.1,
        };
        let typed = Warning::from_sharpness(1, &entry);
        assert_eq!(typed.to_string(), entry.to_string());
        assert_eq!(
            serde_json::to_value(&typed).unwrap(),
            serde_json::json!({
                "kind": "unblended_edge_entry",
                "mesh": 1,
                "edge": 3,
                "edge_kind": "boundary",
                "h": 0.1,
                "at": {"file": "robot.g2tess.toml", "line": 2, "path": "edges[0]"},
            })
        );
    }

    #[test]
    fn the_json_form_has_kind_facts_and_message() {
        let w = Warnings(vec![plane(vec![4], 3)]);
        let v = serde_json::to_value(&w).unwrap();
        assert_eq!(
            v,
            serde_json::json!({
                "warnings": ["mesh 2, morph target 4: no projection plane for 3 folded edge(s) (first: edge 7); they are creases"],
                "warning_details": [{
                    "kind": "no_projection_plane",
                    "mesh": 2,
                    "targets": [4],
                    "count": 3,
                    "edge": 7,
                    "message": "mesh 2, morph target 4: no projection plane for 3 folded edge(s) (first: edge 7); they are creases",
                }],
            })
        );
    }
}
