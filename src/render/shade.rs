//! Colours of the rasterized pixels, per mode: the surface's own normals lit (`shaded`),
//! reflection-line stripes (`zebra`), face normals lit (`flat`).
//!
//! Every mode works in the camera's frame, so every view is lit and striped alike, and draws
//! both sides of a surface (a normal facing away from the viewer is turned round).

use glam::Vec3;
use rayon::prelude::*;

use super::camera::Camera;
use super::raster::{barycentric, Frame, EMPTY};
use super::scene::Scene;

/// An RGB colour.
pub type Rgb = [u8; 3];

/// Behind the surface.
pub const BACKGROUND: Rgb = [238, 240, 244];

/// How the pixels of a surface are coloured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Shading {
    /// Lambert with the per-pixel interpolated vertex normals.
    Smooth,
    /// Stripes of the angle between the interpolated normal and [`ZEBRA_DIRECTION`].
    Zebra,
    /// Lambert with each triangle's own normal.
    Flat,
    /// As `Smooth`, paler, under drawn edges.
    Pale,
}

/// The key light, in the camera's frame (up, left, towards the viewer).
const KEY_LIGHT: Vec3 = Vec3::new(-0.35, 0.55, 0.76);
/// Light that reaches every surface facing the viewer, so nothing is black.
const AMBIENT: f32 = 0.22;

/// The zebra's fixed direction, in the camera's frame: up and towards the viewer, at 45°.
/// Stripes are the level sets of the angle to it: where the normal turns continuously the
/// stripes are continuous, a jump of the normal (G¹ break) cuts them, and a jump of its rate of
/// turning (G² break) bends them.
pub const ZEBRA_DIRECTION: Vec3 = Vec3::new(
    0.0,
    std::f32::consts::FRAC_1_SQRT_2,
    std::f32::consts::FRAC_1_SQRT_2,
);
/// Stripes per half turn of the normal: each stripe spans 180° / this.
pub const ZEBRA_STRIPES: f32 = 20.0;

/// The zebra stripe (0 or 1) of a unit normal `n` in the camera's frame.
#[inline]
pub fn zebra_stripe(n: Vec3) -> u32 {
    let angle = n.dot(ZEBRA_DIRECTION).clamp(-1.0, 1.0).acos();
    (angle * ZEBRA_STRIPES / std::f32::consts::PI) as u32 % 2
}

/// Colours every pixel of `frame`, row-major RGB.
pub fn shade(scene: &Scene, camera: &Camera, frame: &Frame, shading: Shading) -> Vec<Rgb> {
    frame
        .triangle
        .par_iter()
        .enumerate()
        .map(|(at, &t)| {
            if t == EMPTY {
                return BACKGROUND;
            }
            let n = normal_at(scene, camera, frame, t, at, shading);
            colour(n, shading)
        })
        .collect()
}

/// The view-space unit normal drawn at pixel `at` on triangle `t`, facing the viewer.
fn normal_at(
    scene: &Scene,
    camera: &Camera,
    frame: &Frame,
    t: u32,
    at: usize,
    shading: Shading,
) -> Vec3 {
    let tri = scene.triangles[t as usize];
    let [pa, pb, pc] = tri.map(|i| scene.positions[i as usize]);
    let face = (pb - pa).cross(pc - pa).normalize_or_zero();
    let [na, nb, nc] = tri.map(|i| scene.normals[i as usize]);
    let smooth = shading != Shading::Flat && na.is_finite() && nb.is_finite() && nc.is_finite();
    let n = if smooth {
        let [a, b, c] = tri.map(|i| frame.screen[i as usize]);
        let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        let (x, y) = (at % frame.size, at / frame.size);
        let w = barycentric(a, b, c, x as f32 + 0.5, y as f32 + 0.5, 1.0 / area);
        (na * w[0] + nb * w[1] + nc * w[2]).normalize_or(face)
    } else {
        face
    };
    let v = camera.to_view(n);
    if v.z < 0.0 {
        -v
    } else {
        v
    }
}

fn colour(n: Vec3, shading: Shading) -> Rgb {
    match shading {
        Shading::Zebra => {
            if zebra_stripe(n) == 0 {
                [250, 250, 250]
            } else {
                [24, 24, 28]
            }
        }
        Shading::Smooth | Shading::Flat => shaded_colour(n),
        Shading::Pale => lit(n, [0.70, 0.70, 0.70], 0.45),
    }
}

/// The `shaded` and `flat` colour of a surface with unit normal `n` (camera frame).
pub fn shaded_colour(n: Vec3) -> Rgb {
    lit(n, [0.78, 0.80, 0.84], AMBIENT)
}

/// Lambert: `albedo` under the key light plus `ambient`.
fn lit(n: Vec3, albedo: [f32; 3], ambient: f32) -> Rgb {
    let light = ambient + (1.0 - ambient) * n.dot(KEY_LIGHT.normalize()).max(0.0);
    albedo.map(|a| (a * light * 255.0 + 0.5).clamp(0.0, 255.0) as u8)
}
