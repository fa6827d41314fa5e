//! Turns an edge entry's name (`a`/`b` of a primitive, or `from`/`to` positions) into a welded
//! [`EdgeId`]. It deliberately assigns no h and knows no file formats.
//!
//! Positions match a welded vertex when they lie within [`DEFAULT_POSITION_TOLERANCE`] times the
//! diagonal of the mesh's bounding box: relative, so it works for a millimetre screw and a
//! kilometre terrain alike, and far below any real edge length.

use std::collections::HashMap;
use std::sync::OnceLock;

use glam::DVec3;

use super::entries::{at, fmt_point, EdgeEntry, EdgeName};
use super::error::{Problem, SharpnessError};
use super::{PrimitiveContext, DEFAULT_POSITION_TOLERANCE};
use crate::mesh::TriMesh;
use crate::topology::{EdgeId, Topology, VertId};

/// Names edges of one mesh; the position grid is only built if a `from`/`to` entry needs it.
pub(crate) struct EdgeNamer<'a> {
    pub mesh: &'a TriMesh,
    pub topo: &'a Topology,
    pub primitives: &'a [PrimitiveContext<'a>],
    /// `mesh "Body"` or `mesh 3`, for messages.
    pub mesh_label: &'a str,
    pub tolerance: f64,
    grid: OnceLock<HashMap<[i64; 3], Vec<VertId>>>,
}

impl<'a> EdgeNamer<'a> {
    pub fn new(
        mesh: &'a TriMesh,
        topo: &'a Topology,
        primitives: &'a [PrimitiveContext<'a>],
        mesh_label: &'a str,
    ) -> Self {
        EdgeNamer {
            mesh,
            topo,
            primitives,
            mesh_label,
            tolerance: DEFAULT_POSITION_TOLERANCE * bbox_diagonal(&topo.welded_positions),
            grid: OnceLock::new(),
        }
    }

    /// The welded edge an entry names; `implied` is the primitive whose extras hold the entry.
    pub fn edge_of(
        &self,
        entry: &EdgeEntry,
        implied: Option<usize>,
    ) -> Result<EdgeId, SharpnessError> {
        let fail = |p| at(&entry.at, p);
        match entry.name {
            EdgeName::Indices { primitive, a, b } => {
                let prim = self.primitive(implied.or(primitive)).map_err(fail)?;
                let (va, vb) = (
                    self.vertex(prim, a).map_err(fail)?,
                    self.vertex(prim, b).map_err(fail)?,
                );
                let (wa, wb) = (self.welded(va), self.welded(vb));
                if wa == wb {
                    return Err(fail(Problem::DegenerateEdge {
                        mesh: self.mesh_label.to_string(),
                    }));
                }
                let missing = || Problem::NoSuchEdge {
                    a,
                    b,
                    primitive: prim.index,
                    mesh: self.mesh_label.to_string(),
                };
                let edge = self
                    .topo
                    .edge_between(wa, wb)
                    .ok_or_else(|| fail(missing()))?;
                // The welded edge may exist only through another primitive's triangles.
                let in_primitive = self.topo.edge(edge).tris.iter().any(|u| {
                    let first = self.mesh.triangles[u.at().0][0];
                    first.wrapping_sub(prim.vertex_offset) < prim.vertex_count
                });
                if in_primitive {
                    Ok(edge)
                } else {
                    Err(fail(missing()))
                }
            }
            EdgeName::Positions { from, to } => {
                let wa = self.vertex_at(from).map_err(fail)?;
                let wb = self.vertex_at(to).map_err(fail)?;
                if wa == wb {
                    return Err(fail(Problem::DegenerateEdge {
                        mesh: self.mesh_label.to_string(),
                    }));
                }
                self.topo.edge_between(wa, wb).ok_or_else(|| {
                    fail(Problem::NoEdgeBetween {
                        from: fmt_point(from),
                        to: fmt_point(to),
                        mesh: self.mesh_label.to_string(),
                    })
                })
            }
        }
    }

    fn primitive(&self, index: Option<usize>) -> Result<&PrimitiveContext<'a>, Problem> {
        let index = match (index, self.primitives) {
            (Some(i), _) => i,
            (None, [only]) => only.index,
            (None, all) => {
                return Err(Problem::PrimitiveRequired {
                    mesh: self.mesh_label.to_string(),
                    count: all.len(),
                })
            }
        };
        self.primitives
            .iter()
            .find(|p| p.index == index)
            .ok_or_else(|| Problem::NoSuchPrimitive {
                primitive: index,
                mesh: self.mesh_label.to_string(),
                known: self
                    .primitives
                    .iter()
                    .map(|p| p.index.to_string())
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }

    /// A primitive-local vertex index to the combined mesh's vertex index.
    fn vertex(&self, prim: &PrimitiveContext<'_>, local: u64) -> Result<usize, Problem> {
        if local < u64::from(prim.vertex_count) {
            Ok(prim.vertex_offset as usize + local as usize)
        } else {
            Err(Problem::VertexOutOfRange {
                index: local,
                primitive: prim.index,
                mesh: self.mesh_label.to_string(),
                count: prim.vertex_count,
            })
        }
    }

    fn welded(&self, vertex: usize) -> VertId {
        self.topo.welded_of_vertex[vertex]
    }

    /// The one welded vertex within the tolerance of `p`; none or several is an error.
    fn vertex_at(&self, p: DVec3) -> Result<VertId, Problem> {
        let cell = self.cell_size();
        let grid = self.grid.get_or_init(|| {
            let mut grid: HashMap<[i64; 3], Vec<VertId>> = HashMap::new();
            for (i, &q) in self.topo.welded_positions.iter().enumerate() {
                grid.entry(cell_of(q, cell))
                    .or_default()
                    .push(VertId(i as u32));
            }
            grid
        });
        let c = cell_of(p, cell);
        let mut found = Vec::new();
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let key = [c[0] + dx, c[1] + dy, c[2] + dz];
                    for &v in grid.get(&key).into_iter().flatten() {
                        if self.topo.welded_positions[v.0 as usize].distance(p) <= self.tolerance {
                            found.push(v);
                        }
                    }
                }
            }
        }
        match found.as_slice() {
            [v] => Ok(*v),
            [] => Err(Problem::NoVertexAt {
                at: fmt_point(p),
                tolerance: self.tolerance,
                mesh: self.mesh_label.to_string(),
            }),
            _ => Err(Problem::AmbiguousVertex {
                at: fmt_point(p),
                count: found.len(),
                tolerance: self.tolerance,
                mesh: self.mesh_label.to_string(),
            }),
        }
    }

    /// Cells as wide as the tolerance, so a match is always in one of the 27 cells around `p`.
    fn cell_size(&self) -> f64 {
        if self.tolerance > 0.0 {
            self.tolerance
        } else {
            1.0
        }
    }
}

fn cell_of(p: DVec3, cell: f64) -> [i64; 3] {
    // `as` saturates, so far-away queries land in an empty cell instead of overflowing.
    (p / cell).floor().to_array().map(|c| c as i64)
}

fn bbox_diagonal(points: &[DVec3]) -> f64 {
    let Some(&first) = points.first() else {
        return 0.0;
    };
    let (lo, hi) = points
        .iter()
        .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    (hi - lo).length()
}
