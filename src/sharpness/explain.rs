//! Which source set each edge's h, for `--explain-h`: one [`HSource`] per edge and printable
//! [`ExplainRow`]s. It deliberately does not print; the binary decides where rows go.

use std::fmt;
use std::sync::Arc;

use glam::DVec3;

use super::error::Location;
use super::EdgeParams;
use crate::topology::{EdgeId, EdgeKind, Topology, VertId};

/// The source that set an edge's h, in precedence order (first wins).
#[derive(Debug, Clone, PartialEq)]
pub enum HSource {
    /// An `edges` entry in the sidecar.
    SidecarEdge(Arc<Location>),
    /// An `edges` entry in a primitive's `extras`.
    PrimitiveExtrasEdge(Arc<Location>),
    /// An `edges` entry in the mesh's `extras`.
    MeshExtrasEdge(Arc<Location>),
    /// The crease-angle rule: h = 0 because the faces meet at `dihedral` > `crease_angle` degrees.
    Crease {
        dihedral: f64,
        crease_angle: f64,
        /// Where the crease angle came from; `None`: the options.
        set_by: Option<Arc<Location>>,
    },
    /// A hard edge in the input (split normals), kept because `keep_hard_edges` is on.
    HardEdge,
    /// The `h` of the mesh's sidecar section.
    SidecarMeshDefault(Arc<Location>),
    /// The `h` in a primitive's `extras` (the smallest, if the edge joins several primitives).
    PrimitiveExtrasDefault(Arc<Location>),
    /// The `h` in the mesh's `extras`.
    MeshExtrasDefault(Arc<Location>),
    /// The top-level `h` of the sidecar.
    SidecarAssetDefault(Arc<Location>),
    /// `--h` or `config/default.toml`.
    Options,
}

impl HSource {
    /// 1 (strongest) to 7 (weakest), the numbering of the precedence list in the module docs.
    pub fn rank(&self) -> u8 {
        match self {
            HSource::SidecarEdge(_) => 1,
            HSource::PrimitiveExtrasEdge(_) | HSource::MeshExtrasEdge(_) => 2,
            HSource::Crease { .. } | HSource::HardEdge => 3,
            HSource::SidecarMeshDefault(_) => 4,
            HSource::PrimitiveExtrasDefault(_) | HSource::MeshExtrasDefault(_) => 5,
            HSource::SidecarAssetDefault(_) => 6,
            HSource::Options => 7,
        }
    }

    /// Where the deciding value was written, if in a file.
    pub fn location(&self) -> Option<&Location> {
        match self {
            HSource::SidecarEdge(at)
            | HSource::PrimitiveExtrasEdge(at)
            | HSource::MeshExtrasEdge(at)
            | HSource::SidecarMeshDefault(at)
            | HSource::PrimitiveExtrasDefault(at)
            | HSource::MeshExtrasDefault(at)
            | HSource::SidecarAssetDefault(at) => Some(at),
            HSource::Crease { set_by, .. } => set_by.as_deref(),
            HSource::HardEdge | HSource::Options => None,
        }
    }
}

impl fmt::Display for HSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            HSource::SidecarEdge(at) => write!(f, "sidecar edge entry ({at})"),
            HSource::PrimitiveExtrasEdge(at) => write!(f, "primitive extras edge entry ({at})"),
            HSource::MeshExtrasEdge(at) => write!(f, "mesh extras edge entry ({at})"),
            HSource::Crease {
                dihedral,
                crease_angle,
                set_by,
            } => {
                write!(
                    f,
                    "crease: faces meet at {dihedral:.2}° > crease_angle {crease_angle}° ("
                )?;
                match set_by {
                    Some(at) => write!(f, "{at})"),
                    None => f.write_str("options)"),
                }
            }
            HSource::HardEdge => {
                f.write_str("hard edge in the input (split normals, keep_hard_edges)")
            }
            HSource::SidecarMeshDefault(at) => write!(f, "sidecar mesh default ({at})"),
            HSource::PrimitiveExtrasDefault(at) => write!(f, "primitive extras default ({at})"),
            HSource::MeshExtrasDefault(at) => write!(f, "mesh extras default ({at})"),
            HSource::SidecarAssetDefault(at) => write!(f, "sidecar asset default ({at})"),
            HSource::Options => f.write_str("default h from the options (--h or config)"),
        }
    }
}

/// One edge, its h and why.
#[derive(Debug, Clone, PartialEq)]
pub struct ExplainRow {
    pub edge: EdgeId,
    pub verts: [VertId; 2],
    pub from: DVec3,
    pub to: DVec3,
    pub kind: EdgeKind,
    pub h: f64,
    pub source: HSource,
}

impl fmt::Display for ExplainRow {
    /// `edge 4  [0, 1, 0] – [0, 1, 1]  h = 0.0500  sidecar edge entry (robot.g2tess.toml:12: edges[1])`,
    /// with the edge kind added when the surface will not blend it whatever h says.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let p = |v: DVec3| format!("[{}, {}, {}]", v.x, v.y, v.z);
        write!(
            f,
            "edge {}  {} – {}  h = {:.4}  {}",
            self.edge.0,
            p(self.from),
            p(self.to),
            self.h,
            self.source
        )?;
        match self.kind {
            EdgeKind::Interior => Ok(()),
            EdgeKind::Boundary => f.write_str("  [boundary: not blended]"),
            EdgeKind::NonManifold => f.write_str("  [non-manifold: not blended]"),
            EdgeKind::Degenerate => f.write_str("  [degenerate: not blended]"),
        }
    }
}

/// One row per edge, in edge order, from `params` resolved
/// [`super::AssetSharpness::with_sources`] (without the sources there are no rows).
pub fn explain_rows(params: &EdgeParams, topo: &Topology) -> Vec<ExplainRow> {
    debug_assert_eq!(
        params.sources.len(),
        params.h.len(),
        "resolved with sources"
    );
    topo.edges()
        .zip(params.h.iter().zip(&params.sources))
        .enumerate()
        .map(|(i, (edge, (&h, source)))| ExplainRow {
            edge: EdgeId(i as u32),
            verts: edge.verts,
            from: topo.welded_positions[edge.verts[0].0 as usize],
            to: topo.welded_positions[edge.verts[1].0 as usize],
            kind: edge.kind,
            h,
            source: source.clone(),
        })
        .collect()
}
