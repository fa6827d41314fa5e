//! Side-by-side pictures: the documents drawn with one camera per view, one row per mode, and
//! the whole encoded as PNG.

use rayon::prelude::*;

use super::camera::{Camera, View};
use super::edges::{self, MeshEdges};
use super::raster::rasterize;
use super::scene::Scene;
use super::shade::{shade, Rgb, Shading};

/// What a row of a picture shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Mode {
    /// Lambert with the mesh's own normals interpolated per pixel: shows normal quality.
    Shaded,
    /// Reflection-line stripes: a G¹ break is a jump in them, a G² break a kink.
    Zebra,
    /// Lambert with face normals: shows the tessellation.
    Flat,
    /// The edges of a subject with [`Subject::edges`] coloured by their resolved h over its
    /// pale shading; subjects without edges are shaded.
    H,
}

/// What to draw and how large.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// One row per mode, in this order.
    pub modes: Vec<Mode>,
    /// One group of columns per view, in this order.
    pub views: Vec<View>,
    /// Side of each square panel in pixels.
    pub size: u32,
}

/// One document to draw.
#[derive(Debug, Clone, Copy)]
pub struct Subject<'a> {
    /// Its triangles.
    pub scene: &'a Scene,
    /// Its welded edges and their h, for [`Mode::H`].
    pub edges: Option<&'a [MeshEdges]>,
}

/// An RGB picture.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Row-major pixels.
    pub pixels: Vec<Rgb>,
}

/// Between the panels of one view.
const GAP: usize = 4;
/// Between views.
const VIEW_GAP: usize = 12;
/// Between panels.
const PAPER: Rgb = [255, 255, 255];

impl Image {
    fn new(width: usize, height: usize) -> Image {
        Image {
            width,
            height,
            pixels: vec![PAPER; width * height],
        }
    }

    /// The pixel at column `x`, row `y`.
    pub fn at(&self, x: usize, y: usize) -> Rgb {
        self.pixels[y * self.width + x]
    }

    fn paste(&mut self, panel: &[Rgb], size: usize, x0: usize, y0: usize) {
        for (row, src) in panel.chunks_exact(size).enumerate() {
            let at = (y0 + row) * self.width + x0;
            self.pixels[at..at + size].copy_from_slice(src);
        }
    }

    /// The picture as a PNG file's bytes (8-bit RGB; the encoder's output depends only on
    /// the pixels).
    pub fn to_png(&self) -> Vec<u8> {
        let mut out = Vec::new();
        {
            let mut encoder = png::Encoder::new(&mut out, self.width as u32, self.height as u32);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            encoder.set_compression(png::Compression::Balanced);
            let mut writer = encoder
                .write_header()
                .expect("a header to memory cannot fail");
            writer
                .write_image_data(self.pixels.as_flattened())
                .expect("the pixel count matches the header");
        }
        out
    }
}

/// Most pixels in one picture (3 bytes each): enough for four views of two files in three
/// modes at 1 600 pixels.
pub const MAX_PIXELS: usize = 1 << 27;

/// Width and height of the picture of `subjects` documents under `settings`.
pub fn sheet_size(subjects: usize, settings: &Settings) -> (usize, usize) {
    let size = settings.size.max(1) as usize;
    let n = subjects.max(1);
    let group = n * size + (n - 1) * GAP;
    let views = settings.views.len().max(1);
    let rows = settings.modes.len().max(1);
    (
        views * group + (views - 1) * VIEW_GAP,
        rows * size + (rows - 1) * GAP,
    )
}

/// Draws `subjects` side by side: for each view, one column per subject (all framed on the
/// union of their bounds, so they line up), and one row per mode.
pub fn sheet(subjects: &[Subject], settings: &Settings) -> Image {
    let size = settings.size.max(1) as usize;
    let group = subjects.len().max(1) * (size + GAP) - GAP;
    let (width, height) = sheet_size(subjects.len(), settings);
    let mut image = Image::new(width, height);
    let points = || {
        let all: Vec<&[glam::Vec3]> = subjects
            .iter()
            .map(|s| s.scene.positions.as_slice())
            .collect();
        all.into_par_iter().flatten()
    };
    for (v, view) in settings.views.iter().enumerate() {
        let camera = Camera::framing(points, *view, size as u32);
        for (s, subject) in subjects.iter().enumerate() {
            let frame = rasterize(subject.scene, &camera);
            let x0 = v * (group + VIEW_GAP) + s * (size + GAP);
            for (r, mode) in settings.modes.iter().enumerate() {
                let shading = match (mode, subject.edges) {
                    (Mode::Shaded, _) | (Mode::H, None) => Shading::Smooth,
                    (Mode::Zebra, _) => Shading::Zebra,
                    (Mode::Flat, _) => Shading::Flat,
                    (Mode::H, Some(_)) => Shading::Pale,
                };
                let mut panel = shade(subject.scene, &camera, &frame, shading);
                if let (Mode::H, Some(meshes)) = (mode, subject.edges) {
                    edges::draw(&mut panel, &frame, subject.scene, &camera, meshes);
                }
                image.paste(&panel, size, x0, r * (size + GAP));
            }
        }
    }
    image
}
