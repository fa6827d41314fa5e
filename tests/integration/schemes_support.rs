//! Shared by the scheme tests: distance of a surface to the exact sphere or torus its mesh was
//! sampled from, per-edge continuity (to tell smooth edges from creases), and small literal
//! meshes for the fallbacks (a knife edge, a non-manifold fan).
#![allow(dead_code)]

use g2tess::continuity::angle_deg;
use g2tess::mesh::TriMesh;
use g2tess::surface::blend::map_point;
use g2tess::surface::{lattice_bary, Surface};
use g2tess::topology::{EdgeKind, Topology, TriId};
use glam::DVec3;

/// An exact surface that a test mesh samples.
#[derive(Debug, Clone, Copy)]
pub enum Exact {
    /// The unit sphere.
    Sphere,
    /// The torus of `support::torus`: major radius 1, minor 0.4, around z.
    Torus,
}

impl Exact {
    /// Unsigned distance from `p` to the surface.
    pub fn distance(self, p: DVec3) -> f64 {
        match self {
            Exact::Sphere => (p.length() - 1.0).abs(),
            Exact::Torus => {
                let rho = (p.x * p.x + p.y * p.y).sqrt();
                (((rho - 1.0).powi(2) + p.z * p.z).sqrt() - 0.4).abs()
            }
        }
    }
}

/// Max and RMS distance to `exact` over the level-`level` lattice of every triangle.
pub fn distance(surface: &dyn Surface, triangles: usize, exact: Exact, level: u32) -> (f64, f64) {
    let (mut max, mut sum, mut n) = (0.0f64, 0.0, 0usize);
    for t in 0..triangles {
        for j in 0..=level {
            for i in 0..=level - j {
                let d = exact.distance(surface.evaluate(t, lattice_bary(level, i, j)).position);
                max = max.max(d);
                sum += d * d;
                n += 1;
            }
        }
    }
    (max, (sum / n as f64).sqrt())
}

/// Per interior edge: its id, the largest position gap and the largest normal angle (degrees)
/// between the two sides at `per_edge` points, leaving out `margin` at each end.
pub fn edge_jumps(
    surface: &dyn Surface,
    topo: &Topology,
    per_edge: usize,
    margin: f64,
) -> Vec<(usize, f64, f64)> {
    let mut out = Vec::new();
    for (e, edge) in topo.edges().enumerate() {
        if edge.kind != EdgeKind::Interior {
            continue;
        }
        let (f, k) = edge.tris[0].at();
        let n = topo.neighbour(TriId(f as u32), k).expect("interior");
        let (g, slots) = (n.tri.0 as usize, n.slots.map(usize::from));
        let (mut gap, mut angle) = (0.0f64, 0.0f64);
        for m in 0..per_edge {
            let x = margin + (1.0 - 2.0 * margin) * m as f64 / (per_edge - 1) as f64;
            let mut l = [0.0; 3];
            l[(k + 1) % 3] = 1.0 - x;
            l[(k + 2) % 3] = x;
            let a = surface.evaluate(f, l);
            let b = surface.evaluate(g, map_point(k, slots, l));
            gap = gap.max((a.position - b.position).length());
            angle = angle.max(angle_deg(a.normal, b.normal));
        }
        out.push((e, gap, angle));
    }
    out
}

/// Two triangles folded back onto each other along the x axis (a thin fin, dihedral about 3°),
/// with the end normals pointing away from the fin's tip: no projection plane sees both faces.
pub fn knife_edge() -> TriMesh {
    let tip = DVec3::new(0.0, 1.0, 0.0);
    TriMesh {
        positions: vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.5, 1.0, 0.0),
            DVec3::new(0.5, 1.0, 0.05),
        ],
        normals: vec![-tip, -tip, tip, tip],
        triangles: vec![[0, 1, 2], [1, 0, 3]],
    }
}

/// Three triangles sharing the edge from (0,0,0) to (1,0,0), each with its own apex.
pub fn non_manifold_fan() -> TriMesh {
    let apex = [
        DVec3::new(0.5, 1.0, 0.0),
        DVec3::new(0.5, -0.5, 0.8),
        DVec3::new(0.5, -0.5, -0.8),
    ];
    let mut mesh = TriMesh {
        positions: vec![DVec3::ZERO, DVec3::X],
        normals: vec![
            DVec3::new(-1.0, 0.2, 0.3).normalize(),
            DVec3::new(1.0, 0.2, 0.3).normalize(),
        ],
        triangles: Vec::new(),
    };
    for (i, a) in apex.iter().enumerate() {
        mesh.positions.push(*a);
        mesh.normals.push(a.normalize());
        mesh.triangles.push([0, 1, 2 + i as u32]);
    }
    mesh
}
