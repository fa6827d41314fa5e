//! The z-buffer: which triangle is nearest at every pixel centre, and how near.
//!
//! Rasterizing only records the triangle and its depth; shading happens once per pixel
//! afterwards ([`super::shade`]), so one raster serves every mode. The picture is cut into
//! bands of rows that threads fill independently; each band takes its triangles in index order
//! and keeps the first of equally near ones, so the result does not depend on the thread count.

use rayon::prelude::*;

use super::camera::Camera;
use super::scene::Scene;

/// Rows per band: small enough for two threads to share out evenly, large enough that few
/// triangles straddle bands.
const BAND_ROWS: usize = 16;

/// No triangle covers the pixel.
pub const EMPTY: u32 = u32::MAX;

/// A rasterized picture.
#[derive(Debug, Clone)]
pub struct Frame {
    /// Side in pixels.
    pub size: usize,
    /// Every vertex projected: screen x, y, depth.
    pub screen: Vec<[f32; 3]>,
    /// Depth of the nearest surface per pixel, row-major (`f32::INFINITY` where empty).
    pub depth: Vec<f32>,
    /// The nearest triangle per pixel, or [`EMPTY`].
    pub triangle: Vec<u32>,
}

/// Rasterizes `scene` through `camera`.
pub fn rasterize(scene: &Scene, camera: &Camera) -> Frame {
    let size = camera.size as usize;
    let screen: Vec<[f32; 3]> = scene
        .positions
        .par_iter()
        .map(|p| camera.project(*p))
        .collect();
    let bands = size.div_ceil(BAND_ROWS);
    let binned = bin_by_band(&scene.triangles, &screen, size, bands);
    let mut depth = vec![f32::INFINITY; size * size];
    let mut triangle = vec![EMPTY; size * size];
    let chunk = BAND_ROWS * size;
    depth
        .par_chunks_mut(chunk.max(1))
        .zip(triangle.par_chunks_mut(chunk.max(1)))
        .enumerate()
        .for_each(|(band, (depth, tri))| {
            let rows = band * BAND_ROWS..((band + 1) * BAND_ROWS).min(size);
            binned.for_each(band, |t| {
                let [a, b, c] = scene.triangles[t as usize].map(|i| screen[i as usize]);
                cover(a, b, c, size, rows.clone(), |x, y, z| {
                    let at = (y - rows.start) * size + x;
                    if z < depth[at] {
                        depth[at] = z;
                        tri[at] = t;
                    }
                });
            });
        });
    Frame {
        size,
        screen,
        depth,
        triangle,
    }
}

/// Triangles per band, in index order within each band: listed (a counting sort, linear in
/// the triangles and the bands they touch) unless that list would exceed
/// [`LISTED_PER_TRIANGLE`] entries per triangle (long slivers across the picture), in which
/// case each band scans every triangle's rows instead, so memory stays linear in the triangles.
struct Bins {
    /// The bands of each triangle; `None` off screen or not finite.
    spans: Vec<Option<(u32, u32)>>,
    /// Where each band's list starts in `items`, and the lists (when listed).
    listed: Option<(Vec<usize>, Vec<u32>)>,
}

/// The most band entries per triangle that are listed.
const LISTED_PER_TRIANGLE: usize = 4;

impl Bins {
    /// Calls `f` with every triangle touching band `b`, in index order.
    fn for_each(&self, b: usize, mut f: impl FnMut(u32)) {
        match &self.listed {
            Some((start, items)) => items[start[b]..start[b + 1]].iter().for_each(|&t| f(t)),
            None => {
                let b = b as u32;
                for (t, span) in self.spans.iter().enumerate() {
                    if span.is_some_and(|(b0, b1)| b0 <= b && b <= b1) {
                        f(t as u32);
                    }
                }
            }
        }
    }
}

fn bin_by_band(triangles: &[[u32; 3]], screen: &[[f32; 3]], size: usize, bands: usize) -> Bins {
    let spans: Vec<Option<(u32, u32)>> = triangles
        .par_iter()
        .map(|t| {
            let ys = t.map(|i| screen[i as usize][1]);
            let (lo, hi) = (ys[0].min(ys[1]).min(ys[2]), ys[0].max(ys[1]).max(ys[2]));
            let rows = pixel_range(lo, hi, size)?;
            Some(((rows.0 / BAND_ROWS) as u32, (rows.1 / BAND_ROWS) as u32))
        })
        .collect();
    // Entries per band by a difference array: linear in triangles plus bands.
    let mut start = vec![0i64; bands + 2];
    for (b0, b1) in spans.iter().flatten() {
        start[*b0 as usize + 1] += 1;
        start[*b1 as usize + 2] -= 1;
    }
    for b in 1..start.len() {
        start[b] += start[b - 1];
    }
    let mut start: Vec<usize> = start[..=bands].iter().map(|&n| n as usize).collect();
    for b in 0..bands {
        start[b + 1] += start[b];
    }
    if start[bands] > LISTED_PER_TRIANGLE * triangles.len() + bands {
        return Bins {
            spans,
            listed: None,
        };
    }
    let mut fill = start.clone();
    let mut items = vec![0u32; start[bands]];
    for (t, span) in spans.iter().enumerate() {
        if let Some((b0, b1)) = span {
            for b in *b0..=*b1 {
                items[fill[b as usize]] = t as u32;
                fill[b as usize] += 1;
            }
        }
    }
    Bins {
        spans,
        listed: Some((start, items)),
    }
}

/// The pixels whose centres (`k + 0.5`) lie in `lo..=hi`, clamped to the picture, as an
/// inclusive range; `None` when there are none.
#[inline]
fn pixel_range(lo: f32, hi: f32, size: usize) -> Option<(usize, usize)> {
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    let first = (lo - 0.5).ceil().max(0.0);
    let last = (hi - 0.5).floor().min(size as f32 - 1.0);
    (first <= last).then_some((first as usize, last as usize))
}

/// Calls `write(x, y, depth)` for every pixel centre in rows `rows` inside triangle `abc`
/// (edges included; either winding; degenerate triangles cover nothing).
#[inline]
pub fn cover(
    a: [f32; 3],
    b: [f32; 3],
    c: [f32; 3],
    size: usize,
    rows: std::ops::Range<usize>,
    mut write: impl FnMut(usize, usize, f32),
) {
    let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if area == 0.0 || !area.is_finite() {
        return;
    }
    let Some((x0, x1)) = pixel_range(a[0].min(b[0]).min(c[0]), a[0].max(b[0]).max(c[0]), size)
    else {
        return;
    };
    let Some((y0, y1)) = pixel_range(a[1].min(b[1]).min(c[1]), a[1].max(b[1]).max(c[1]), size)
    else {
        return;
    };
    let (y0, y1) = (y0.max(rows.start), y1.min(rows.end.saturating_sub(1)));
    let inv = 1.0 / area;
    for y in y0..=y1 {
        let py = y as f32 + 0.5;
        // Only the row's span inside the triangle is visited (a long sliver costs its rows
        // and pixels, not its bounding box); the exact test below still decides each pixel.
        let span = match x1 - x0 {
            // A few pixels wide: testing them is cheaper than finding the span.
            0..=3 => Some((x0, x1)),
            _ => row_span(a, b, c, py, inv, x0, x1),
        };
        let Some((first, last)) = span else {
            continue;
        };
        for x in first..=last {
            let px = x as f32 + 0.5;
            let [wa, wb, wc] = barycentric(a, b, c, px, py, inv);
            if wa >= 0.0 && wb >= 0.0 && wc >= 0.0 {
                write(x, y, wa * a[2] + wb * b[2] + wc * c[2]);
            }
        }
    }
}

/// The pixels of row `py` that may lie inside `abc`, within `x0..=x1`: each barycentric
/// coordinate is linear along the row, so the inside is an interval; it is widened by
/// [`SPAN_SLACK`] pixels so that rounding never drops a pixel the exact test accepts.
#[inline]
fn row_span(
    a: [f32; 3],
    b: [f32; 3],
    c: [f32; 3],
    py: f32,
    inv: f32,
    x0: usize,
    x1: usize,
) -> Option<(usize, usize)> {
    // w = k + s·px for each coordinate (see `barycentric`).
    let (sa, ka) = (
        (b[1] - c[1]) * inv,
        (b[0] * (c[1] - py) - (b[1] - py) * c[0]) * inv,
    );
    let (sb, kb) = (
        (c[1] - a[1]) * inv,
        (c[0] * (a[1] - py) - (c[1] - py) * a[0]) * inv,
    );
    let (sc, kc) = (-(sa + sb), 1.0 - ka - kb);
    let (mut lo, mut hi) = (x0 as f32, x1 as f32 + 1.0);
    for (s, k) in [(sa, ka), (sb, kb), (sc, kc)] {
        let root = -k / s;
        if s > 0.0 && root.is_finite() {
            lo = lo.max(root);
        } else if s < 0.0 && root.is_finite() {
            hi = hi.min(root);
        }
    }
    let first = ((lo - 0.5).ceil() - SPAN_SLACK).max(x0 as f32);
    let last = ((hi - 0.5).floor() + SPAN_SLACK).min(x1 as f32);
    (first <= last).then_some((first as usize, last as usize))
}

/// Pixels added on each side of a row's computed span.
const SPAN_SLACK: f32 = 2.0;

/// Barycentric coordinates of screen point `(px, py)` in `abc`, given `inv` = 1 / the signed
/// doubled area; all three are non-negative inside, whatever the winding.
#[inline]
pub fn barycentric(a: [f32; 3], b: [f32; 3], c: [f32; 3], px: f32, py: f32, inv: f32) -> [f32; 3] {
    let wa = ((b[0] - px) * (c[1] - py) - (b[1] - py) * (c[0] - px)) * inv;
    let wb = ((c[0] - px) * (a[1] - py) - (c[1] - py) * (a[0] - px)) * inv;
    [wa, wb, 1.0 - wa - wb]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every pixel centre of a `size`² picture inside `abc` by the exact test alone.
    fn brute_force(a: [f32; 3], b: [f32; 3], c: [f32; 3], size: usize) -> Vec<(usize, usize)> {
        let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        let mut out = Vec::new();
        if area == 0.0 {
            return out;
        }
        for y in 0..size {
            for x in 0..size {
                let w = barycentric(a, b, c, x as f32 + 0.5, y as f32 + 0.5, 1.0 / area);
                if w.iter().all(|&v| v >= 0.0) {
                    out.push((x, y));
                }
            }
        }
        out
    }

    #[test]
    fn row_spans_cover_exactly_the_pixels_of_the_exact_test() {
        let size = 48;
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32 * 64.0 - 8.0
        };
        for k in 0..3000 {
            let mut v = [[0.0f32; 3]; 3];
            for p in &mut v {
                *p = [next(), next(), 0.0];
            }
            if k % 3 == 0 {
                // A sliver: the third corner close to the first edge.
                v[2] = [
                    v[0][0] + (v[1][0] - v[0][0]) * 0.5,
                    v[0][1] + (v[1][1] - v[0][1]) * 0.5 + 0.01,
                    0.0,
                ];
            }
            let mut got = Vec::new();
            cover(v[0], v[1], v[2], size, 0..size, |x, y, _| got.push((x, y)));
            got.sort_unstable_by_key(|&(x, y)| (y, x));
            assert_eq!(got, brute_force(v[0], v[1], v[2], size), "triangle {v:?}");
        }
    }

    /// The frame of `scene` drawn in one pass over whole pictures, triangle by triangle.
    fn one_pass(scene: &Scene, camera: &Camera) -> (Vec<f32>, Vec<u32>) {
        let size = camera.size as usize;
        let screen: Vec<[f32; 3]> = scene.positions.iter().map(|p| camera.project(*p)).collect();
        let (mut depth, mut tri) = (vec![f32::INFINITY; size * size], vec![EMPTY; size * size]);
        for (t, corners) in scene.triangles.iter().enumerate() {
            let [a, b, c] = corners.map(|i| screen[i as usize]);
            cover(a, b, c, size, 0..size, |x, y, z| {
                if z < depth[y * size + x] {
                    depth[y * size + x] = z;
                    tri[y * size + x] = t as u32;
                }
            });
        }
        (depth, tri)
    }

    #[test]
    fn bands_listed_or_scanned_draw_what_one_pass_draws() {
        use glam::{Mat4, Vec3};
        // Slivers from the top of the picture to the bottom, tilted in depth, crossing each
        // other: each touches every band, so the bands scan instead of listing.
        let mut scene = Scene::default();
        for k in 0..40u32 {
            let x = k as f32 / 40.0 * 2.0 - 1.0;
            let z = (k % 7) as f32 * 0.1;
            scene.positions.extend([
                Vec3::new(x, -1.0, z),
                Vec3::new(x + 0.3, 1.0, -z),
                Vec3::new(x + 0.05, -1.0, 0.5 - z),
            ]);
            scene.triangles.push([3 * k, 3 * k + 1, 3 * k + 2]);
        }
        scene.normals = vec![Vec3::Z; scene.positions.len()];
        scene.instances = vec![(0, Mat4::IDENTITY)];
        let camera = Camera::framing(
            || vec![scene.positions.as_slice()].into_par_iter().flatten(),
            super::super::View::Front,
            96,
        );
        let frame = rasterize(&scene, &camera);
        let screen: Vec<[f32; 3]> = scene.positions.iter().map(|p| camera.project(*p)).collect();
        let bands = 96usize.div_ceil(BAND_ROWS);
        assert!(bin_by_band(&scene.triangles, &screen, 96, bands)
            .listed
            .is_none());
        let (depth, tri) = one_pass(&scene, &camera);
        assert!(tri.iter().filter(|&&t| t != EMPTY).count() > 1000);
        assert_eq!(frame.triangle, tri);
        assert_eq!(frame.depth, depth);
        // Small triangles only: listed, and the same again.
        let mut small = scene.clone();
        small.triangles.clear();
        for k in 0..40u32 {
            let p = scene.positions[3 * k as usize];
            small.positions.push(p + Vec3::new(0.02, 0.3, 0.0));
            small
                .triangles
                .push([3 * k, 3 * k + 2, small.positions.len() as u32 - 1]);
        }
        small.normals = vec![Vec3::Z; small.positions.len()];
        let screen: Vec<[f32; 3]> = small.positions.iter().map(|p| camera.project(*p)).collect();
        assert!(bin_by_band(&small.triangles, &screen, 96, bands)
            .listed
            .is_some());
        let frame = rasterize(&small, &camera);
        assert!(frame.triangle.iter().filter(|&&t| t != EMPTY).count() > 200);
        assert_eq!((frame.depth, frame.triangle), one_pass(&small, &camera));
    }
}
