//! The `h` picture: a mesh's welded edges drawn over its shading, coloured by what the
//! surface does across them (the picture of `--explain-h`).
//!
//! Blended edges shade from light to deep blue as h grows to [`H_MAX`]; creases (h = 0) are
//! red, open (boundary) edges orange, non-manifold edges magenta, degenerate ones dark grey.
//! Edges hidden behind the surface are not drawn.

use std::collections::BTreeMap;

use glam::{DVec3, Vec3};

use super::camera::Camera;
use super::raster::Frame;
use super::scene::Scene;
use super::shade::Rgb;
use crate::sharpness::H_MAX;
use crate::topology::{EdgeKind, Topology};

/// What one welded edge is to the surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EdgeClass {
    /// Interior and blended with this h > 0.
    Blended(f64),
    /// Interior with h = 0: a crease.
    Crease,
    /// On the boundary (one triangle).
    Open,
    /// Shared by three or more triangles.
    NonManifold,
    /// Of zero length, or used by a degenerate triangle.
    Degenerate,
}

impl EdgeClass {
    /// The class of an edge of kind `kind` with resolved blend width `h`.
    pub fn of(kind: EdgeKind, h: f64) -> EdgeClass {
        match kind {
            EdgeKind::Interior if h > 0.0 => EdgeClass::Blended(h),
            EdgeKind::Interior => EdgeClass::Crease,
            EdgeKind::Boundary => EdgeClass::Open,
            EdgeKind::NonManifold => EdgeClass::NonManifold,
            EdgeKind::Degenerate => EdgeClass::Degenerate,
        }
    }

    /// Its colour in the picture.
    pub fn colour(self) -> Rgb {
        match self {
            EdgeClass::Blended(h) => {
                let t = (h / H_MAX).clamp(0.0, 1.0) as f32;
                let (light, deep) = ([130.0, 205.0, 255.0], [10.0, 45.0, 185.0]);
                [0, 1, 2].map(|k| (light[k] + (deep[k] - light[k]) * t).round() as u8)
            }
            EdgeClass::Crease => [225, 30, 30],
            EdgeClass::Open => [255, 150, 0],
            EdgeClass::NonManifold => [200, 0, 200],
            EdgeClass::Degenerate => [60, 60, 60],
        }
    }

    /// Drawing order: later classes are drawn over earlier ones where they meet.
    fn layer(self) -> u8 {
        match self {
            EdgeClass::Blended(_) => 0,
            EdgeClass::Degenerate => 1,
            EdgeClass::Open => 2,
            EdgeClass::NonManifold => 3,
            EdgeClass::Crease => 4,
        }
    }
}

/// One mesh's welded edges with their classes, in the mesh's own space.
#[derive(Debug, Clone, Default)]
pub struct MeshEdges {
    /// The glTF mesh.
    pub mesh: usize,
    /// Welded vertex positions.
    pub positions: Vec<Vec3>,
    /// End points (into `positions`) and class of each edge.
    pub edges: Vec<([u32; 2], EdgeClass)>,
}

impl MeshEdges {
    /// The edges of `topo` (mesh `mesh`) under the resolved blend widths `h`, one per edge.
    pub fn from_topology(mesh: usize, topo: &Topology, h: &[f64]) -> MeshEdges {
        MeshEdges {
            mesh,
            positions: topo
                .welded_positions
                .iter()
                .map(|p: &DVec3| p.as_vec3())
                .collect(),
            edges: topo
                .edges()
                .enumerate()
                .map(|(e, edge)| {
                    let class = EdgeClass::of(edge.kind, h.get(e).copied().unwrap_or(0.0));
                    (edge.verts.map(|v| v.0), class)
                })
                .collect(),
        }
    }
}

/// Draws the visible parts of `meshes`' edges, placed as `scene` places their meshes, into
/// `pixels` (the shaded `frame`).
pub fn draw(
    pixels: &mut [Rgb],
    frame: &Frame,
    scene: &Scene,
    camera: &Camera,
    meshes: &[MeshEdges],
) {
    let width = (frame.size / 300).max(1) as i64;
    // A point on the surface may lie this far (in depth) in front of the nearest surface at
    // its pixel centre: a few pixels' worth, for surfaces seen at a grazing angle.
    let slack = 3.0 / camera.scale;
    let by_mesh: BTreeMap<usize, Vec<&MeshEdges>> =
        meshes.iter().fold(BTreeMap::new(), |mut map, m| {
            map.entry(m.mesh).or_insert_with(Vec::new).push(m);
            map
        });
    for layer in 0..=4 {
        for (mesh, world) in &scene.instances {
            for m in by_mesh.get(mesh).into_iter().flatten() {
                for &([a, b], class) in m.edges.iter().filter(|e| e.1.layer() == layer) {
                    let (Some(pa), Some(pb)) =
                        (m.positions.get(a as usize), m.positions.get(b as usize))
                    else {
                        continue;
                    };
                    let pa = camera.project(world.transform_point3(*pa));
                    let pb = camera.project(world.transform_point3(*pb));
                    line(pixels, frame, pa, pb, width, slack, class.colour());
                }
            }
        }
    }
}

/// A line of `width` pixels from `a` to `b`, drawn where it is not behind the surface.
fn line(
    pixels: &mut [Rgb],
    frame: &Frame,
    a: [f32; 3],
    b: [f32; 3],
    width: i64,
    slack: f32,
    colour: Rgb,
) {
    if !(a.iter().chain(&b).all(|v| v.is_finite())) {
        return;
    }
    let size = frame.size as i64;
    let steps = (b[0] - a[0])
        .abs()
        .max((b[1] - a[1]).abs())
        .ceil()
        .min(4.0 * size as f32) as usize
        + 1;
    for s in 0..=steps {
        let t = s as f32 / steps as f32;
        let x = a[0] + (b[0] - a[0]) * t;
        let y = a[1] + (b[1] - a[1]) * t;
        let z = a[2] + (b[2] - a[2]) * t;
        let (cx, cy) = (x.floor() as i64, y.floor() as i64);
        if cx < 0 || cy < 0 || cx >= size || cy >= size {
            continue;
        }
        if z > frame.depth[(cy * size + cx) as usize] + slack {
            continue;
        }
        let lo = -(width - 1) / 2;
        for dy in lo..lo + width {
            for dx in lo..lo + width {
                let (px, py) = (cx + dx, cy + dy);
                if px >= 0 && py >= 0 && px < size && py < size {
                    pixels[(py * size + px) as usize] = colour;
                }
            }
        }
    }
}
