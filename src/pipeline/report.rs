//! What processing a file did, for people (`g2tess` prints a summary) and for machines
//! (`--report FILE.json`): counts per primitive, time per stage, continuity per mesh, warnings.
//!
//! Field names are part of the command line's interface (documented in the README); rename
//! none without a reason.

use rayon::prelude::*;
use serde::Serialize;

use crate::continuity::angle_deg;
use crate::optimize::CacheFigures;
use crate::surface::blend::map_point;
use crate::surface::Surface;
use crate::topology::{EdgeKind, Topology};

/// Seconds spent per stage. Mesh stages are summed over meshes (which may run in parallel, so
/// the sum can exceed the wall time).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct StageTimes {
    /// Reading and decoding the file.
    pub read: f64,
    /// Decoding the triangle primitives.
    pub decode: f64,
    /// Checking the primitives, welding them and resolving per-edge h.
    pub sharpness: f64,
    /// Building the surface and measuring its continuity.
    pub surface: f64,
    /// Evaluating and connecting the dense lattice.
    pub tessellate: f64,
    /// Vertex cache and fetch ordering.
    pub optimize: f64,
    /// Carrying attributes, tangents and morph targets.
    pub attributes: f64,
    /// Storing the new arrays as accessors and writing the output.
    pub write: f64,
    /// The whole file, wall time.
    pub total: f64,
}

/// One line for `--timings`: every stage in pipeline order, then the wall time, in seconds.
impl std::fmt::Display for StageTimes {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let stages = [
            ("read", self.read),
            ("decode", self.decode),
            ("sharpness", self.sharpness),
            ("surface", self.surface),
            ("tessellate", self.tessellate),
            ("optimize", self.optimize),
            ("attributes", self.attributes),
            ("write", self.write),
        ];
        for (name, s) in stages {
            write!(f, "{name} {s:.3} s, ")?;
        }
        write!(f, "total {:.3} s", self.total)
    }
}

impl StageTimes {
    fn add(&mut self, other: &StageTimes) {
        self.sharpness += other.sharpness;
        self.surface += other.surface;
        self.tessellate += other.tessellate;
        self.optimize += other.optimize;
        self.attributes += other.attributes;
    }
}

/// One replaced primitive.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PrimitiveReport {
    /// Its index in the mesh.
    pub primitive: usize,
    /// Triangles read.
    pub triangles_in: usize,
    /// Vertices read.
    pub vertices_in: usize,
    /// Triangles written.
    pub triangles_out: usize,
    /// Vertices written.
    pub vertices_out: usize,
    /// meshoptimizer's cache figures of the written index buffer.
    pub cache: CacheFigures,
}

/// Continuity of the surface across the mesh's edges, sampled at three points per edge away
/// from the corners (where only G¹ is expected).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct EdgeFigures {
    /// Interior edges blended (h > 0).
    pub smooth_edges: usize,
    /// Interior edges left sharp (h = 0): creases.
    pub crease_edges: usize,
    /// Boundary, non-manifold and degenerate edges (never blended).
    pub open_edges: usize,
    /// Largest angle between the two sides' normals across a smooth edge, in degrees.
    pub max_normal_jump_deg: f64,
    /// Largest distance between the two sides' positions across any interior edge, relative
    /// to the mean edge length (0 means watertight before any sharing of samples).
    pub max_gap: f64,
}

impl EdgeFigures {
    /// Measures `surface` over every edge of `topo` with blend widths `h`.
    pub fn measure(surface: &dyn Surface, topo: &Topology, h: &[f64]) -> EdgeFigures {
        let mean = crate::continuity::mean_edge_length(topo).max(f64::MIN_POSITIVE);
        // Edges are measured in parallel; sums and maxima do not depend on the order.
        topo.edges
            .par_iter()
            .enumerate()
            .map(|(e, edge)| {
                let mut figures = EdgeFigures::default();
                if edge.kind != EdgeKind::Interior {
                    figures.open_edges += 1;
                    return figures;
                }
                let smooth = h.get(e).is_some_and(|&v| v > 0.0);
                if smooth {
                    figures.smooth_edges += 1;
                } else {
                    figures.crease_edges += 1;
                }
                let (f, k) = (edge.tris[0].0 .0 as usize, edge.tris[0].1 as usize);
                let Some(n) = topo.neighbours[f][k] else {
                    return figures;
                };
                let (g, slots) = (n.tri.0 as usize, n.slots.map(usize::from));
                for x in [0.25, 0.5, 0.75] {
                    let mut on_edge = [0.0; 3];
                    on_edge[(k + 1) % 3] = 1.0 - x;
                    on_edge[(k + 2) % 3] = x;
                    let a = surface.evaluate(f, on_edge);
                    let b = surface.evaluate(g, map_point(k, slots, on_edge));
                    figures.max_gap = figures
                        .max_gap
                        .max((a.position - b.position).length() / mean);
                    if smooth {
                        figures.max_normal_jump_deg = figures
                            .max_normal_jump_deg
                            .max(angle_deg(a.normal, b.normal));
                    }
                }
                figures
            })
            .reduce(EdgeFigures::default, |a, b| EdgeFigures {
                smooth_edges: a.smooth_edges + b.smooth_edges,
                crease_edges: a.crease_edges + b.crease_edges,
                open_edges: a.open_edges + b.open_edges,
                max_normal_jump_deg: a.max_normal_jump_deg.max(b.max_normal_jump_deg),
                max_gap: a.max_gap.max(b.max_gap),
            })
    }
}

/// One mesh.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct MeshReport {
    /// Its index in the document.
    pub mesh: usize,
    /// Its name.
    pub name: Option<String>,
    /// Its replaced primitives.
    pub primitives: Vec<PrimitiveReport>,
    /// Continuity across its edges.
    pub edges: EdgeFigures,
    /// What was repaired or ignored, one sentence each.
    pub warnings: Vec<String>,
    /// Its stage times.
    #[serde(skip)]
    pub times: StageTimes,
}

/// One file.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct FileReport {
    /// The tessellation level used (from the sidecar or the options).
    pub level: u32,
    /// Triangle primitives replaced.
    pub primitives: usize,
    /// Triangles read.
    pub triangles_in: usize,
    /// Triangles written.
    pub triangles_out: usize,
    /// Vertices written.
    pub vertices_out: usize,
    /// Input file size in bytes.
    pub bytes_in: u64,
    /// Output file size in bytes (0 when nothing was written).
    pub bytes_out: u64,
    /// Seconds per stage.
    pub times: StageTimes,
    /// Per mesh.
    pub meshes: Vec<MeshReport>,
}

impl FileReport {
    /// Adds one mesh's figures.
    pub fn add_mesh(&mut self, mesh: MeshReport) {
        for p in &mesh.primitives {
            self.primitives += 1;
            self.triangles_in += p.triangles_in;
            self.triangles_out += p.triangles_out;
            self.vertices_out += p.vertices_out;
        }
        self.times.add(&mesh.times);
        self.meshes.push(mesh);
    }

    /// Every warning of every mesh.
    pub fn warnings(&self) -> impl Iterator<Item = &str> {
        self.meshes
            .iter()
            .flat_map(|m| m.warnings.iter().map(String::as_str))
    }
}
