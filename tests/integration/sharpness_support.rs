//! Small literal meshes and a one-call runner for the per-edge h tests.
#![allow(dead_code)]

use std::path::Path;

use g2tess::mesh::TriMesh;
use g2tess::sharpness::{
    AssetSharpness, Defaults, EdgeParams, MeshContext, PrimitiveContext, Sidecar,
};
use g2tess::topology::{EdgeId, Topology};
use glam::DVec3;
use serde_json::Value;

pub const ASSET: &str = "robot.glb";
pub const SIDECAR: &str = "robot.g2tess.toml";

/// The hinge's far corner for a dihedral angle of `phi` degrees (0 = flat).
fn hinge_tip(phi: f64) -> DVec3 {
    let r = phi.to_radians();
    DVec3::new(0.5, -r.cos(), r.sin())
}

/// Two triangles on the edge (0,0,0)–(1,0,0) meeting at `phi` degrees, shared vertices,
/// one primitive: vertices 0..4, the hinge edge is (0, 1).
pub fn hinge(phi: f64) -> Fixture {
    let positions = vec![
        DVec3::ZERO,
        DVec3::X,
        DVec3::new(0.5, 1.0, 0.0),
        hinge_tip(phi),
    ];
    Fixture {
        mesh: TriMesh {
            normals: vec![DVec3::Z; 4],
            positions,
            triangles: vec![[0, 1, 2], [1, 0, 3]],
        },
        prims: vec![(0, 4)],
    }
}

/// The hinge with one triangle per primitive and face normals on each side, so the hinge edge
/// is a hard edge: primitive 0 is vertices 0..3, primitive 1 is vertices 3..6 (local 0 = (1,0,0),
/// local 1 = (0,0,0)).
pub fn hinge_two_prims(phi: f64) -> Fixture {
    let tip = hinge_tip(phi);
    let nb = (DVec3::ZERO - DVec3::X).cross(tip - DVec3::X).normalize();
    Fixture {
        mesh: TriMesh {
            positions: vec![
                DVec3::ZERO,
                DVec3::X,
                DVec3::new(0.5, 1.0, 0.0),
                DVec3::X,
                DVec3::ZERO,
                tip,
            ],
            normals: vec![DVec3::Z, DVec3::Z, DVec3::Z, nb, nb, nb],
            triangles: vec![[0, 1, 2], [3, 4, 5]],
        },
        prims: vec![(0, 3), (3, 3)],
    }
}

/// The unit cube with 8 shared vertices (vertex i at (i & 1, i >> 1 & 1, i >> 2 & 1)), outward
/// winding: 12 edges at 90°, 6 face diagonals at 0°.
pub fn cube() -> Fixture {
    let positions: Vec<DVec3> = (0..8)
        .map(|i| DVec3::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2 & 1) as f64))
        .collect();
    let normals = positions
        .iter()
        .map(|p| (*p - DVec3::splat(0.5)).normalize())
        .collect();
    let quads = [
        [0, 2, 3, 1], // z = 0
        [4, 5, 7, 6], // z = 1
        [0, 1, 5, 4], // y = 0
        [2, 6, 7, 3], // y = 1
        [0, 4, 6, 2], // x = 0
        [1, 3, 7, 5], // x = 1
    ];
    let triangles = quads
        .iter()
        .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
        .collect();
    Fixture {
        mesh: TriMesh {
            positions,
            normals,
            triangles,
        },
        prims: vec![(0, 8)],
    }
}

pub struct Fixture {
    pub mesh: TriMesh,
    /// (vertex offset, vertex count) per primitive, primitive index = position in this list.
    pub prims: Vec<(u32, u32)>,
}

pub fn defaults() -> Defaults {
    Defaults {
        h: 0.08,
        crease_angle: 180.0,
        keep_hard_edges: false,
    }
}

/// Everything one resolution needs; fields left default mean "source absent".
pub struct Case {
    pub fixture: Fixture,
    pub sidecar: Option<&'static str>,
    pub mesh_extras: Option<Value>,
    pub prim_extras: Vec<Option<Value>>,
    pub defaults: Defaults,
    pub mesh_names: Vec<Option<&'static str>>,
    /// Resolve which source set each edge (`--explain-h`'s data); on unless a test turns it off.
    pub sources: bool,
    /// Resolve only the effective widths (what smoothing reads); off unless a test turns it on.
    pub effective_only: bool,
    /// Check the edge entries alone, picking no width (what a run that reads none does); off
    /// unless a test turns it on.
    pub entries_only: bool,
}

impl Case {
    pub fn new(fixture: Fixture) -> Self {
        Case {
            fixture,
            sidecar: None,
            mesh_extras: None,
            prim_extras: Vec::new(),
            defaults: defaults(),
            mesh_names: vec![Some("Body")],
            sources: true,
            effective_only: false,
            entries_only: false,
        }
    }

    pub fn sidecar(mut self, text: &'static str) -> Self {
        self.sidecar = Some(text);
        self
    }

    pub fn mesh_extras(mut self, v: Value) -> Self {
        self.mesh_extras = Some(v);
        self
    }

    pub fn prim_extras(mut self, p: usize, v: Value) -> Self {
        self.prim_extras.resize(self.fixture.prims.len(), None);
        self.prim_extras[p] = Some(v);
        self
    }

    pub fn run(&self) -> Result<Resolved, String> {
        let sidecar = self
            .sidecar
            .map(|text| Sidecar::parse(Path::new(SIDECAR), text))
            .transpose()
            .map_err(|e| e.to_string())?;
        let mut asset =
            AssetSharpness::new(Path::new(ASSET), sidecar, &self.mesh_names, self.defaults)
                .map_err(|e| e.to_string())?;
        if self.sources {
            asset = asset.with_sources();
        }
        if self.effective_only {
            asset = asset.effective_only();
        }
        let prims: Vec<PrimitiveContext> = self
            .fixture
            .prims
            .iter()
            .enumerate()
            .map(|(i, &(offset, count))| PrimitiveContext {
                index: i,
                extras: self.prim_extras.get(i).and_then(Option::as_ref),
                vertex_offset: offset,
                vertex_count: count,
            })
            .collect();
        let ctx = MeshContext {
            index: 0,
            name: self.mesh_names[0],
            extras: self.mesh_extras.as_ref(),
            primitives: &prims,
        };
        let topo = Topology::build(&self.fixture.mesh);
        let params = if self.entries_only {
            asset.check_mesh(&ctx, &self.fixture.mesh, &topo)
        } else {
            asset.resolve_mesh(&ctx, &self.fixture.mesh, &topo)
        }
        .map_err(|e| e.to_string())?;
        Ok(Resolved { params, topo })
    }

    /// The error message; panics (failing the test) if resolution succeeded.
    pub fn error(&self) -> String {
        match self.run() {
            Ok(_) => panic!("expected an error"),
            Err(e) => e,
        }
    }
}

pub struct Resolved {
    pub params: EdgeParams,
    pub topo: Topology,
}

impl Resolved {
    /// The edge between the welded vertices at `p` and `q`.
    pub fn edge(&self, p: [f64; 3], q: [f64; 3]) -> EdgeId {
        let find = |p: [f64; 3]| {
            let p = DVec3::from_array(p);
            let i = self
                .topo
                .welded_positions
                .iter()
                .position(|&w| w.distance(p) < 1e-12)
                .expect("vertex exists");
            g2tess::topology::VertId(i as u32)
        };
        self.topo
            .edge_between(find(p), find(q))
            .expect("edge exists")
    }

    pub fn h(&self, p: [f64; 3], q: [f64; 3]) -> f64 {
        self.params.h[self.edge(p, q).0 as usize]
    }

    pub fn source(&self, p: [f64; 3], q: [f64; 3]) -> String {
        self.params.sources[self.edge(p, q).0 as usize].to_string()
    }

    /// h of every edge whose faces meet at about `dihedral` degrees.
    pub fn h_at_dihedral(&self, dihedral: f64) -> Vec<f64> {
        self.topo
            .edges()
            .zip(&self.params.h)
            .filter(|(e, _)| {
                g2tess::sharpness::dihedral_degrees(e, &self.topo)
                    .is_some_and(|d| (d - dihedral).abs() < 1e-6)
            })
            .map(|(_, &h)| h)
            .collect()
    }
}
