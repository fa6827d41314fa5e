//! The renderer's pictures checked against the math: a sphere with exact normals draws
//! symmetric with the analytic zebra stripes, a known normal jump cuts the stripes at the
//! right column, and pictures are byte-identical across runs and thread counts.

use std::collections::HashMap;

use crate::support;
use g2tess::render::shade::{shaded_colour, zebra_stripe, BACKGROUND};
use g2tess::render::{sheet, Image, Mode, Scene, Settings, Subject, View};
use glam::{Mat4, Vec3};

const WHITE: [u8; 3] = [250, 250, 250];
const BLACK: [u8; 3] = [24, 24, 28];

/// The icosahedron subdivided `levels` times onto the unit sphere, normals = positions.
fn icosphere(levels: u32) -> Scene {
    let mesh = (0..levels).fold(support::icosahedron(), |m, _| support::subdivide(&m));
    let positions: Vec<Vec3> = mesh.positions.iter().map(|p| p.as_vec3()).collect();
    Scene {
        normals: positions.clone(),
        positions,
        triangles: mesh.triangles,
        instances: vec![(0, Mat4::IDENTITY)],
    }
}

fn draw(scene: &Scene, mode: Mode, size: u32) -> Image {
    let settings = Settings {
        modes: vec![mode],
        views: vec![View::Front],
        size,
    };
    sheet(&[Subject { scene, edges: None }], &settings)
}

/// Whether both stripe colours occur within one pixel of `(x, y)`.
fn at_stripe_edge(img: &Image, x: usize, y: usize) -> bool {
    let (mut white, mut black) = (false, false);
    for dy in -1i64..=1 {
        for dx in -1i64..=1 {
            let (px, py) = (x as i64 + dx, y as i64 + dy);
            if px < 0 || py < 0 || px >= img.width as i64 || py >= img.height as i64 {
                continue;
            }
            match img.at(px as usize, py as usize) {
                WHITE => white = true,
                BLACK => black = true,
                _ => {}
            }
        }
    }
    white && black
}

#[test]
fn a_sphere_draws_mirror_symmetric_and_lit_as_the_exact_sphere() {
    let sphere = icosphere(5);
    let size = 200u32;
    for mode in [Mode::Zebra, Mode::Shaded, Mode::Flat] {
        let img = draw(&sphere, mode, size);
        let (mut covered, mut differ) = (0usize, 0usize);
        for y in 0..img.height {
            for x in 0..img.width {
                let a = img.at(x, y);
                covered += usize::from(a != BACKGROUND);
                // The outline is symmetric about both axes in every mode; the zebra's
                // direction lies in the vertical plane, so its stripes mirror left to right.
                let mirrors = [img.at(img.width - 1 - x, y), img.at(x, img.height - 1 - y)];
                for (k, b) in mirrors.into_iter().enumerate() {
                    let mismatch = match mode {
                        Mode::Zebra if k == 0 => a != b,
                        _ => (a == BACKGROUND) != (b == BACKGROUND),
                    };
                    if mismatch {
                        differ += 1;
                        // Only pixels on a stripe edge may fall either way (their centres lie
                        // on a boundary up to rounding).
                        assert!(
                            mode == Mode::Zebra && at_stripe_edge(&img, x, y),
                            "{mode:?}: ({x}, {y}) differs from its mirror image {k}"
                        );
                    }
                }
            }
        }
        assert!(
            covered > 20_000,
            "{mode:?}: the sphere covers {covered} pixels"
        );
        assert!(
            differ * 200 < covered,
            "{mode:?}: {differ} of {covered} pixels differ from their mirror image"
        );
    }
}

#[test]
fn a_sphere_with_exact_normals_shows_the_analytic_zebra_stripes() {
    let sphere = icosphere(5);
    let size = 256u32;
    let img = draw(&sphere, Mode::Zebra, size);
    // The rendered normal under a pixel is the flat triangle's point P over it, normalized
    // (normals are the positions, interpolated linearly); the exact normal is the sphere's
    // point S over the same pixel. Both lie in one plane through the view axis, with polar
    // angles φ_P, φ_S and sin φ_P = sin φ_S / |P|, so they differ by about (1 − |P|) tan φ.
    // |P| is at least sqrt(1 − R²) for the largest circumradius R of a triangle.
    let r_max = sphere
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| sphere.positions[i as usize]);
            let (ab, bc, ca) = ((b - a).length(), (c - b).length(), (a - c).length());
            ab * bc * ca / (2.0 * (b - a).cross(c - a).length())
        })
        .fold(0.0f32, f32::max);
    let max_polar = 80f32.to_radians();
    let eps = 1.0 - (1.0 - r_max * r_max).sqrt();
    let delta = eps * max_polar.tan() + 1e-4;
    assert!(
        delta < 0.2f32.to_radians(),
        "tolerance {delta} rad is too loose to see a facet"
    );
    // The camera frames the unit sphere: pixels per unit from the margin of the framing.
    let scale = size as f32 * 0.45;
    let half = size as f32 / 2.0;
    let (mut checked, mut wrong) = (0, Vec::new());
    for y in 0..size as usize {
        for x in 0..size as usize {
            let (sx, sy) = (
                (x as f32 + 0.5 - half) / scale,
                (half - y as f32 - 0.5) / scale,
            );
            let q = (sx * sx + sy * sy).sqrt();
            if q >= max_polar.sin() {
                continue;
            }
            let n = Vec3::new(sx, sy, (1.0 - q * q).sqrt());
            let angle = n
                .dot(g2tess::render::shade::ZEBRA_DIRECTION)
                .clamp(-1.0, 1.0)
                .acos();
            let width = std::f32::consts::PI / g2tess::render::shade::ZEBRA_STRIPES;
            let off = (angle / width).fract().min(1.0 - (angle / width).fract()) * width;
            if off < delta {
                continue; // within the tolerance of a stripe boundary
            }
            checked += 1;
            let expected = if zebra_stripe(n) == 0 { WHITE } else { BLACK };
            if img.at(x, y) != expected {
                wrong.push((x, y));
            }
        }
    }
    assert!(checked > 25_000, "only {checked} pixels checked");
    // Lit: within two levels of the exact sphere's colour (the normal is off by at most
    // `delta`, which moves n·L by less than one level, plus rounding).
    let lit = draw(&sphere, Mode::Shaded, size);
    let mut lit_checked = 0;
    for y in 0..size as usize {
        for x in 0..size as usize {
            let (sx, sy) = (
                (x as f32 + 0.5 - half) / scale,
                (half - y as f32 - 0.5) / scale,
            );
            let q2 = sx * sx + sy * sy;
            if q2 >= max_polar.sin().powi(2) {
                continue;
            }
            let exact = shaded_colour(Vec3::new(sx, sy, (1.0 - q2).sqrt()));
            let got = lit.at(x, y);
            for k in 0..3 {
                assert!(
                    got[k].abs_diff(exact[k]) <= 2,
                    "({x}, {y}): {got:?}, exact sphere {exact:?}"
                );
            }
            lit_checked += 1;
        }
    }
    assert!(lit_checked > 25_000);
    assert!(
        wrong.is_empty(),
        "{} pixels off the analytic stripes, first {:?}",
        wrong.len(),
        &wrong[..wrong.len().min(5)]
    );
}

/// A square of side 2 in the plane z = 0 split at x = `split`: the left part's normals are
/// tilted up by `left` radians about the x axis, the right part's by `right`.
fn hinged_plane(split: f32, left: f32, right: f32) -> Scene {
    let tilt = |a: f32| Vec3::new(0.0, a.sin(), a.cos());
    let quad = |x0: f32, x1: f32, n: Vec3, base: u32| {
        (
            vec![
                Vec3::new(x0, -1.0, 0.0),
                Vec3::new(x1, -1.0, 0.0),
                Vec3::new(x1, 1.0, 0.0),
                Vec3::new(x0, 1.0, 0.0),
            ],
            vec![n; 4],
            vec![[base, base + 1, base + 2], [base, base + 2, base + 3]],
        )
    };
    let (p0, n0, t0) = quad(-1.0, split, tilt(left), 0);
    let (p1, n1, t1) = quad(split, 1.0, tilt(right), 4);
    Scene {
        positions: [p0, p1].concat(),
        normals: [n0, n1].concat(),
        triangles: [t0, t1].concat(),
        instances: vec![(0, Mat4::IDENTITY)],
    }
}

#[test]
fn a_normal_jump_cuts_the_stripes_at_its_pixel_column() {
    let (split, left, right) = (0.3f32, 20f32.to_radians(), -20f32.to_radians());
    let (n_left, n_right) = (
        Vec3::new(0.0, left.sin(), left.cos()),
        Vec3::new(0.0, right.sin(), right.cos()),
    );
    let (a, b) = (zebra_stripe(n_left), zebra_stripe(n_right));
    assert_ne!(
        a, b,
        "the two sides must fall in different stripes for the test to see the jump"
    );
    let colour = |s: u32| if s == 0 { WHITE } else { BLACK };
    let size = 160u32;
    let img = draw(&hinged_plane(split, left, right), Mode::Zebra, size);
    let (half, scale) = (size as f32 / 2.0, size as f32 * 0.45);
    let edge = half + split * scale; // the jump's screen column
    let (lo, hi) = (half - scale, half + scale); // the plane's extent on screen
    let mut seen = [0usize; 2];
    for y in 0..size as usize {
        for x in 0..size as usize {
            let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
            let inside = cx > lo + 0.01 && cx < hi - 0.01 && cy > lo + 0.01 && cy < hi - 0.01;
            let got = img.at(x, y);
            if !inside {
                continue;
            }
            if (cx - edge).abs() < 1e-3 {
                continue; // a pixel centre on the edge itself may take either side
            }
            let (side, expected) = if cx < edge {
                (0, colour(a))
            } else {
                (1, colour(b))
            };
            assert_eq!(
                got,
                expected,
                "pixel ({x}, {y}), {} of the jump at column {edge}",
                ["left", "right"][side]
            );
            seen[side] += 1;
        }
    }
    assert!(
        seen[0] > 1000 && seen[1] > 1000,
        "pixels checked per side: {seen:?}"
    );
    // A smooth field across the same edge draws no cut: both sides the same normal.
    let img = draw(&hinged_plane(split, left, left), Mode::Zebra, size);
    let row = size as usize / 2;
    let (l, r) = ((edge - 3.0) as usize, (edge + 3.0) as usize);
    assert_eq!(img.at(l, row), img.at(r, row));
}

#[test]
fn pictures_are_byte_identical_across_runs_and_thread_counts() {
    let sphere = icosphere(5);
    let settings = Settings {
        modes: vec![Mode::Shaded, Mode::Zebra, Mode::Flat],
        views: View::ALL.to_vec(),
        size: 96,
    };
    let once = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            sheet(
                &[
                    Subject {
                        scene: &sphere,
                        edges: None,
                    },
                    Subject {
                        scene: &sphere,
                        edges: None,
                    },
                ],
                &settings,
            )
            .to_png()
        })
    };
    let first = once(1);
    assert!(first.starts_with(b"\x89PNG\r\n\x1a\n"));
    for threads in [1, 2, 3, 8] {
        assert!(
            once(threads) == first,
            "{threads} threads drew a different picture"
        );
    }
}

use crate::gltf_build;

/// Decodes an 8-bit RGB PNG.
fn decode_png(bytes: &[u8]) -> Image {
    let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    Image {
        width: info.width as usize,
        height: info.height as usize,
        pixels: buf[..info.buffer_size()]
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect(),
    }
}

#[test]
fn node_transforms_place_every_instance() {
    let text = gltf_build::gltf("octahedron", None, &[gltf_build::octahedron()]);
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    json["nodes"] = serde_json::json!([
        { "mesh": 0, "translation": [-2.0, 0.0, 0.0] },
        { "children": [2], "translation": [2.0, 0.0, 0.0] },
        { "mesh": 0, "scale": [0.5, 0.5, 0.5] },
        { "mesh": 0, "translation": [0.0, 50.0, 0.0] }
    ]);
    json["scenes"] = serde_json::json!([{ "nodes": [0, 1] }, { "nodes": [3] }]);
    let bytes = serde_json::to_vec(&json).unwrap();
    let doc = g2tess::gltf_io::read_bytes(&bytes, None, &Default::default()).unwrap();
    let scene = Scene::from_document(&doc).unwrap();
    assert_eq!(scene.instances.len(), 2, "node 3 is in another scene");
    let size = 200u32;
    let img = draw(&scene, Mode::Shaded, size);
    // Framed on x in [-3, 2.5], y in [-1, 1]: the wider extent, 5.5, fills 90% of the width.
    let scale = size as f32 * 0.9 / 5.5;
    let column = |x: f32| ((x - (-3.0 + 2.5) / 2.0) * scale + size as f32 / 2.0) as usize;
    let row = size as usize / 2;
    let covered = |x: f32| img.at(column(x), row) != BACKGROUND;
    assert!(
        covered(-2.0) && covered(-1.1),
        "the instance at x = -2 is missing"
    );
    assert!(
        !covered(0.0) && !covered(1.3),
        "something is drawn between the instances"
    );
    assert!(
        covered(2.0) && covered(2.4),
        "the scaled child instance at x = 2 is missing"
    );
}

#[test]
fn quantized_and_compressed_outputs_draw_like_plain_ones() {
    let dir = tempfile::tempdir().unwrap();
    let input = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/icosahedron.glb");
    let bin = env!("CARGO_BIN_EXE_g2tess");
    let run = |args: &[&std::ffi::OsStr]| {
        let out = std::process::Command::new(bin).args(args).output().unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let (plain, packed) = (dir.path().join("plain.glb"), dir.path().join("packed.glb"));
    run(&[
        input.as_os_str(),
        "-o".as_ref(),
        plain.as_os_str(),
        "-q".as_ref(),
    ]);
    run(&[
        input.as_os_str(),
        "-o".as_ref(),
        packed.as_os_str(),
        "-q".as_ref(),
        "--quantize".as_ref(),
        "--compress".as_ref(),
    ]);
    let mut pictures = Vec::new();
    for file in [&plain, &packed] {
        let png = file.with_extension("png");
        run(&[
            "--render".as_ref(),
            file.as_os_str(),
            "-o".as_ref(),
            png.as_os_str(),
            "--render-modes".as_ref(),
            "shaded".as_ref(),
            "--render-views".as_ref(),
            "iso".as_ref(),
            "--render-size".as_ref(),
            "128".as_ref(),
        ]);
        pictures.push(decode_png(&std::fs::read(&png).unwrap()));
    }
    let (a, b) = (&pictures[0], &pictures[1]);
    assert_eq!((a.width, a.height), (128, 128));
    assert_eq!((a.width, a.height), (b.width, b.height));
    let covered = a.pixels.iter().filter(|p| **p != BACKGROUND).count();
    assert!(covered > 5000, "the plain output covers {covered} pixels");
    // 14-bit positions move the outline by well under a pixel, 8-bit normals turn the shading
    // by about half a degree: a few levels, and a few outline pixels.
    let (mut outline, mut far) = (0, 0);
    for (p, q) in a.pixels.iter().zip(&b.pixels) {
        if (*p == BACKGROUND) != (*q == BACKGROUND) {
            outline += 1;
        } else if (0..3).any(|k| p[k].abs_diff(q[k]) > 6) {
            far += 1;
        }
    }
    assert!(outline * 100 < covered, "{outline} outline pixels differ");
    assert!(
        far * 100 < covered,
        "{far} pixels differ by more than 6 levels"
    );
}

/// Pixels of each colour in `img`.
fn colour_counts(img: &Image) -> HashMap<[u8; 3], usize> {
    let mut counts = HashMap::new();
    for p in &img.pixels {
        *counts.entry(*p).or_insert(0) += 1;
    }
    counts
}

/// The `h` picture of a one-mesh asset under `options`, front view.
fn h_picture(gltf: &str, options: &g2tess::options::Options) -> Image {
    let doc = g2tess::gltf_io::read_bytes(gltf.as_bytes(), None, &Default::default()).unwrap();
    let scene = Scene::from_document(&doc).unwrap();
    let asset = std::path::Path::new("memory.gltf");
    let edges: Vec<g2tess::render::MeshEdges> =
        g2tess::pipeline::resolved_edges(&doc, asset, options)
            .unwrap()
            .iter()
            .map(|r| g2tess::render::MeshEdges::from_topology(r.mesh, &r.topo, &r.h))
            .collect();
    let settings = Settings {
        modes: vec![Mode::H],
        views: vec![View::Iso],
        size: 160,
    };
    sheet(
        &[Subject {
            scene: &scene,
            edges: Some(&edges),
        }],
        &settings,
    )
}

#[test]
fn the_h_picture_colours_creases_blended_and_open_edges_apart() {
    use g2tess::render::EdgeClass;
    let octahedron = gltf_build::gltf("octahedron", None, &[gltf_build::octahedron()]);
    let crease = EdgeClass::Crease.colour();
    let blended = EdgeClass::Blended(0.212).colour();
    let open = EdgeClass::Open.colour();
    // Neighbouring normals of the octahedron meet at 70.5°: creases under a 60° crease angle,
    // blended under 90°.
    let mut options = g2tess::options::Options::default();
    options.crease_angle = 60.0;
    let sharp = colour_counts(&h_picture(&octahedron, &options));
    options.crease_angle = 90.0;
    let smooth = colour_counts(&h_picture(&octahedron, &options));
    let count = |c: &HashMap<[u8; 3], usize>, k| c.get(&k).copied().unwrap_or(0);
    assert!(
        count(&sharp, crease) > 100 && count(&sharp, blended) == 0,
        "60°: {sharp:?}"
    );
    assert!(
        count(&smooth, blended) > 100 && count(&smooth, crease) == 0,
        "90°: {smooth:?}"
    );
    assert_eq!(
        count(&sharp, open) + count(&smooth, open),
        0,
        "a closed mesh has no open edge"
    );
    // Half of it (the four triangles with z >= 0) is open along its equator.
    let mut half = gltf_build::octahedron();
    half.indices.truncate(12);
    let open_mesh = colour_counts(&h_picture(
        &gltf_build::gltf("half", None, &[half]),
        &options,
    ));
    assert!(count(&open_mesh, open) > 50, "{open_mesh:?}");
}

#[test]
fn previews_are_written_per_asset_only_when_asked() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = dir.path().join("in");
    std::fs::create_dir_all(inputs.join("props")).unwrap();
    let fixture = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/icosahedron.glb");
    std::fs::copy(&fixture, inputs.join("props/ico.glb")).unwrap();
    std::fs::copy(&fixture, inputs.join("ico.glb")).unwrap();
    let bin = env!("CARGO_BIN_EXE_g2tess");
    let out = dir.path().join("out");
    let plain = std::process::Command::new(bin)
        .arg(&inputs)
        .arg("-o")
        .arg(&out)
        .arg("-q")
        .status()
        .unwrap();
    assert!(plain.success());
    let pngs = walk_pngs(dir.path());
    assert!(pngs.is_empty(), "a run without previews drew {pngs:?}");
    let previews = dir.path().join("previews");
    let run = std::process::Command::new(bin)
        .arg(&inputs)
        .arg("-o")
        .arg(&out)
        .arg("--previews")
        .arg(&previews)
        .args(["--render-size", "40", "--render-modes", "shaded,h", "-q"])
        .status()
        .unwrap();
    assert!(run.success());
    let settings = Settings {
        modes: vec![Mode::Shaded, Mode::H],
        views: View::ALL.to_vec(),
        size: 40,
    };
    let (width, height) = g2tess::render::sheet_size(2, &settings);
    for name in ["ico.glb.png", "props/ico.glb.png"] {
        let img = decode_png(&std::fs::read(previews.join(name)).unwrap());
        assert_eq!((img.width, img.height), (width, height), "{name}");
    }
    assert_eq!(walk_pngs(&previews).len(), 2);
}

fn walk_pngs(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            found.extend(walk_pngs(&path));
        } else if path.extension().is_some_and(|e| e == "png") {
            found.push(path);
        }
    }
    found
}
