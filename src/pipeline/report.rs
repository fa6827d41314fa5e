//! What processing a file did, for people (`g2tess` prints a summary) and for machines
//! (`--report FILE.json`): counts per primitive, time per stage, continuity per mesh, warnings.
//!
//! Field names are part of the command line's interface (documented in the README); rename
//! none without a reason.

use rayon::prelude::*;
use serde::Serialize;

use super::density::AdaptiveFigures;
use super::warning::{Warning, Warnings};
use crate::continuity::angle_deg;
use crate::optimize::CacheFigures;
use crate::surface::blend::map_point;
use crate::surface::Surface;
use crate::topology::{EdgeId, EdgeKind, Topology, TriId};

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
    /// meshoptimizer's cache figures of the written index buffer (`None` unless asked for,
    /// see [`crate::options::Options::report_figures`]).
    pub cache: Option<CacheFigures>,
}

/// The mesh's edges by kind, and the continuity of the surface across them, sampled at three
/// points per edge away from the corners (where only G¹ is expected) when asked for
/// ([`crate::options::Options::report_figures`]).
///
/// The counts read every edge's h, which a uniform level 1 on the flat surface otherwise never
/// resolves: there, unless figures are asked for, they are left 0.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct EdgeFigures {
    /// Interior edges blended (h > 0).
    pub smooth_edges: usize,
    /// Interior edges left sharp (h = 0): creases.
    pub crease_edges: usize,
    /// Boundary, non-manifold and degenerate edges (never blended).
    pub open_edges: usize,
    /// Largest angle between the two sides' normals across a smooth edge, in degrees (`None`
    /// when not measured).
    pub max_normal_jump_deg: Option<f64>,
    /// Largest distance between the two sides' positions across any interior edge, relative
    /// to the mean edge length (0 means watertight before any sharing of samples; `None` when
    /// not measured).
    pub max_gap: Option<f64>,
}

/// Edges one task of [`EdgeFigures::count`] counts.
const COUNT_BLOCK: usize = 1 << 14;

/// The lattice whose edge points are measured: 4 segments put points at a quarter, half and
/// three quarters of every edge.
const MEASURE_LEVEL: u32 = 4;

/// Lattice point `(i, j)` of level [`MEASURE_LEVEL`] at barycentrics `b` (multiples of 1/4).
fn lattice_point(b: [f64; 3]) -> (u32, u32) {
    let n = f64::from(MEASURE_LEVEL);
    ((b[1] * n).round() as u32, (b[2] * n).round() as u32)
}

impl EdgeFigures {
    /// Counts the edges of `topo` by kind under blend widths `h`, measuring nothing.
    ///
    /// Only each edge's kind is read (no edge view is assembled), in parallel blocks of
    /// `COUNT_BLOCK` edges whose counts are summed: a million-triangle mesh has a million and
    /// a half edges, which one thread took a few milliseconds to count while the other waited.
    pub fn count(topo: &Topology, h: &[f64]) -> EdgeFigures {
        let edges = topo.edge_count();
        (0..edges.div_ceil(COUNT_BLOCK))
            .into_par_iter()
            .map(|b| {
                let mut figures = EdgeFigures::default();
                for e in b * COUNT_BLOCK..((b + 1) * COUNT_BLOCK).min(edges) {
                    figures.add(&kind_count(e, topo.edge_kind(EdgeId(e as u32)), h));
                }
                figures
            })
            .reduce(EdgeFigures::default, |mut a, b| {
                a.add(&b);
                a
            })
    }

    /// Counts the edges of `topo` and measures `surface` across them.
    pub fn measure(surface: &dyn Surface, topo: &Topology, h: &[f64]) -> EdgeFigures {
        let mean = crate::continuity::mean_edge_length(topo).max(f64::MIN_POSITIVE);
        // Edges are measured in parallel; sums and maxima do not depend on the order.
        let (mut figures, jump, gap) = topo
            .par_edges()
            .enumerate()
            .map(|(e, edge)| {
                let counts = kind_count(e, edge.kind, h);
                let (mut jump, mut gap) = (0.0f64, 0.0f64);
                if edge.kind != EdgeKind::Interior {
                    return (counts, jump, gap);
                }
                let (f, k) = edge.tris[0].at();
                let Some(n) = topo.neighbour(TriId(f as u32), k) else {
                    return (counts, jump, gap);
                };
                let (g, slots) = (n.tri.0 as usize, n.slots.map(usize::from));
                // The points at a quarter, half and three quarters of the edge are points of
                // both triangles' level-4 lattices, so both sides evaluate them through the
                // surface's cached lattice weights (bit for bit what `evaluate` gives there).
                let (mut on_f, mut on_g) = ([(0, 0); 3], [(0, 0); 3]);
                for (m, x) in [0.25, 0.5, 0.75].into_iter().enumerate() {
                    let mut on_edge = [0.0; 3];
                    on_edge[(k + 1) % 3] = 1.0 - x;
                    on_edge[(k + 2) % 3] = x;
                    on_f[m] = lattice_point(on_edge);
                    on_g[m] = lattice_point(map_point(k, slots, on_edge));
                }
                let (mut a, mut b) = (Vec::with_capacity(3), Vec::with_capacity(3));
                surface.evaluate_lattice_points(f, MEASURE_LEVEL, &on_f, &mut a);
                surface.evaluate_lattice_points(g, MEASURE_LEVEL, &on_g, &mut b);
                for (a, b) in a.iter().zip(&b) {
                    gap = gap.max((a.position - b.position).length() / mean);
                    if counts.smooth_edges > 0 {
                        jump = jump.max(angle_deg(a.normal, b.normal));
                    }
                }
                (counts, jump, gap)
            })
            .reduce(
                || (EdgeFigures::default(), 0.0, 0.0),
                |mut a, b| {
                    a.0.add(&b.0);
                    (a.0, a.1.max(b.1), a.2.max(b.2))
                },
            );
        figures.max_normal_jump_deg = Some(jump);
        figures.max_gap = Some(gap);
        figures
    }

    fn add(&mut self, other: &EdgeFigures) {
        self.smooth_edges += other.smooth_edges;
        self.crease_edges += other.crease_edges;
        self.open_edges += other.open_edges;
    }
}

/// The count of one edge of kind `kind` with blend width `h[e]`.
fn kind_count(e: usize, kind: EdgeKind, h: &[f64]) -> EdgeFigures {
    let mut one = EdgeFigures::default();
    if kind != EdgeKind::Interior {
        one.open_edges = 1;
    } else if h.get(e).is_some_and(|&v| v > 0.0) {
        one.smooth_edges = 1;
    } else {
        one.crease_edges = 1;
    }
    one
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
    /// Tolerance, measured chord error and triangle shape, when tessellated to a tolerance
    /// or budget.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub adaptive: Option<AdaptiveFigures>,
    /// With a LOD chain, each level, finest first: what it reached and where it was written.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub lod: Vec<LodReport>,
    /// What was repaired or ignored, typed; written as the `warnings` sentences and the
    /// `warning_details` objects.
    #[serde(flatten)]
    pub warnings: Warnings,
    /// Its stage times.
    #[serde(skip)]
    pub times: StageTimes,
}

/// One level of a mesh's LOD chain.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct LodReport {
    /// 0 for the finest.
    pub level: usize,
    /// The budget this level was made for, when the chain is of budgets.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub triangle_budget: Option<u64>,
    /// Triangles of the level, all primitives.
    pub triangles: usize,
    /// Vertices of the level, all primitives.
    pub vertices: usize,
    /// Target tolerance, measured chord error (the tolerance reached) and worst shape.
    #[serde(flatten)]
    pub figures: AdaptiveFigures,
    /// The glTF mesh holding the level in the output (level 0: the mesh itself); `None` where
    /// the level was not linked (a `--lod-files` run, or no node could carry it).
    pub mesh: Option<usize>,
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
        // Coarser levels are written too: they count as output.
        for level in mesh.lod.iter().skip(1) {
            self.triangles_out += level.triangles;
            self.vertices_out += level.vertices;
        }
        self.times.add(&mesh.times);
        self.meshes.push(mesh);
    }

    /// Every warning of every mesh, in mesh order; its [`std::fmt::Display`] is the sentence
    /// users read.
    pub fn warnings(&self) -> impl Iterator<Item = &Warning> + Clone {
        self.meshes.iter().flat_map(|m| m.warnings.0.iter())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::TriMesh;
    use glam::DVec3;

    /// The block counts add up to the count edge by edge, on any thread count: an open grid
    /// (boundary and interior edges) of more than one block of edges, a copy of one triangle
    /// (a non-manifold edge), with every seventh width 0 (creases) and one NaN.
    #[test]
    fn the_counts_of_blocks_are_the_counts_of_edges() {
        let n = 120u32;
        let mut mesh = TriMesh::default();
        for i in 0..=n {
            for j in 0..=n {
                mesh.positions.push(DVec3::new(
                    f64::from(i),
                    f64::from(j),
                    f64::from((i * j) % 3),
                ));
            }
        }
        let at = |i: u32, j: u32| i * (n + 1) + j;
        for i in 0..n {
            for j in 0..n {
                mesh.triangles
                    .push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                mesh.triangles
                    .push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        mesh.triangles.push([at(0, 0), at(1, 1), at(0, 1)]);
        mesh.normals = vec![DVec3::Z; mesh.positions.len()];
        let topo = Topology::build(&mesh);
        assert!(topo.edge_count() > 2 * COUNT_BLOCK);
        let mut h: Vec<f64> = (0..topo.edge_count())
            .map(|e| if e % 7 == 0 { 0.0 } else { 0.1 })
            .collect();
        h[5] = f64::NAN;
        let mut want = EdgeFigures::default();
        for (e, edge) in topo.edges().enumerate() {
            match edge.kind {
                EdgeKind::Interior if h[e] > 0.0 => want.smooth_edges += 1,
                EdgeKind::Interior => want.crease_edges += 1,
                _ => want.open_edges += 1,
            }
        }
        assert!(want.smooth_edges > 0 && want.crease_edges > 0 && want.open_edges > 0);
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            assert_eq!(pool.install(|| EdgeFigures::count(&topo, &h)), want);
        }
    }
}
