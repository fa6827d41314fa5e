//! Per-edge h end to end: each source (extras and sidecar, edges named by indices and by
//! positions) lands on the edge it names, as a crease in the output; every mistake in a sidecar
//! fails its file with the location; normals of the output are continuous across smooth edges
//! and jump across creases.

use crate::corpus;
use crate::support;

use std::collections::HashMap;
use std::path::Path;

use crate::gltf_build::{gltf, octahedron, Prim};
use g2tess::gltf_io::{self, ReadOptions, Values};
use serde_json::json;

/// Output vertices that share a position but not a normal, grouped by position: where the
/// output is creased. Returns each such position with the largest angle between its normals.
fn creased_positions(path: &Path) -> Vec<([f32; 3], f64)> {
    let doc = gltf_io::read(path, &ReadOptions::default()).unwrap();
    let mut groups: HashMap<[u32; 3], Vec<[f32; 3]>> = HashMap::new();
    let mut at: HashMap<[u32; 3], [f32; 3]> = HashMap::new();
    for (m, p) in doc.triangle_primitives() {
        let data = doc.read_primitive(m, p).unwrap();
        let (Values::Float(pos), Values::Float(nrm)) = (
            &data.attribute("POSITION").unwrap().values,
            &data.attribute("NORMAL").unwrap().values,
        ) else {
            panic!("float positions and normals");
        };
        for (p, n) in pos.chunks_exact(3).zip(nrm.chunks_exact(3)) {
            let key = [p[0], p[1], p[2]].map(|x| if x == 0.0 { 0 } else { x.to_bits() });
            groups.entry(key).or_default().push([n[0], n[1], n[2]]);
            at.insert(key, [p[0], p[1], p[2]]);
        }
    }
    let mut out = Vec::new();
    for (key, normals) in groups {
        let mut worst: f64 = 0.0;
        for a in &normals {
            for b in &normals {
                // atan2 of |a × b| and a · b: acos of a dot product near 1 would turn f32
                // rounding of equal normals into a hundredth of a degree.
                let (a, b) = (
                    glam::DVec3::from(a.map(f64::from)),
                    glam::DVec3::from(b.map(f64::from)),
                );
                let angle = a.cross(b).length().atan2(a.dot(b)).to_degrees();
                worst = worst.max(angle);
            }
        }
        if normals.len() > 1 {
            out.push((at[&key], worst));
        }
    }
    out
}

/// The edge of `prim` (as a sorted pair of vertex indices) whose chord is nearest to `p`.
fn nearest_edge(prim: &Prim, p: [f32; 3]) -> (u32, u32) {
    let v = |i: u32| glam::Vec3::from(prim.positions[i as usize]);
    let p = glam::Vec3::from(p);
    let mut best = ((0, 0), f32::INFINITY);
    for t in prim.indices.chunks_exact(3) {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let (pa, pb) = (v(a), v(b));
            let s = ((p - pa).dot(pb - pa) / (pb - pa).length_squared()).clamp(0.0, 1.0);
            let d = (pa + s * (pb - pa) - p).length();
            if d < best.1 {
                best = ((a.min(b), a.max(b)), d);
            }
        }
    }
    best.0
}

fn run(dir: &Path, args: &[&str]) -> std::process::Output {
    corpus::g2tess()
        .current_dir(dir)
        .args(args)
        .output()
        .expect("g2tess runs")
}

#[test]
fn h_from_each_source_lands_on_the_edge_it_names() {
    let dir = corpus::temp_dir();
    let mut prim = octahedron();
    // Primitive extras: by indices. Mesh extras: by positions (either order).
    prim.extras = Some(json!({ "g2tess": { "edges": [ { "a": 0, "b": 2, "h": 0.0 } ] } }));
    let mesh_extras = json!({ "g2tess": { "crease_angle": 180, "edges": [
        { "from": [0.0, 0.0, 1.0], "to": [-1.0, 0.0, 0.0], "h": 0.0 } ] } });
    std::fs::write(
        dir.path().join("octa.gltf"),
        gltf("Gem", Some(mesh_extras), std::slice::from_ref(&prim)),
    )
    .unwrap();
    // Sidecar: one edge by indices, one by positions.
    std::fs::write(
        dir.path().join("octa.g2tess.toml"),
        "h = 0.2\n[mesh.\"Gem\"]\nedges = [\n  { primitive = 0, a = 3, b = 5, h = 0.0 },\n  { from = [0.0, 1.0, 0.0], to = [0.0, 0.0, -1.0], h = 0.0 },\n]\n",
    )
    .unwrap();
    let out = run(dir.path(), &["octa.gltf", "-o", "out.glb", "--level", "4"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    let creased = creased_positions(&dir.path().join("out.glb"));
    let mut edges: Vec<(u32, u32)> = creased
        .iter()
        .filter(|(_, angle)| *angle > 1.0)
        .map(|(p, _)| nearest_edge(&prim, *p))
        .collect();
    edges.sort();
    edges.dedup();
    assert_eq!(edges, vec![(0, 2), (1, 4), (2, 5), (3, 5)]);
    // Away from the creases the output is smooth: no other split vertex disagrees.
    for (p, angle) in &creased {
        let e = nearest_edge(&prim, *p);
        if ![(0, 2), (1, 4), (2, 5), (3, 5)].contains(&e) {
            assert!(
                *angle < 1e-3,
                "split vertex at {p:?} on smooth edge {e:?}: {angle}°"
            );
        }
    }
}

/// Two meshes of one name: `--explain-h NAME` is refused like a sidecar section of that name
/// (it picked the first), and the index still works.
#[test]
fn explain_h_refuses_a_name_two_meshes_share() {
    let dir = corpus::temp_dir();
    let text = gltf("Gem", None, &[octahedron()]);
    let mut doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    let mesh = doc["meshes"][0].clone();
    doc["meshes"].as_array_mut().unwrap().push(mesh);
    doc["nodes"]
        .as_array_mut()
        .unwrap()
        .push(json!({ "mesh": 1 }));
    let nodes = doc["nodes"].as_array().unwrap().len();
    doc["scenes"][0]["nodes"] = json!((0..nodes).collect::<Vec<_>>());
    std::fs::write(dir.path().join("two.gltf"), doc.to_string()).unwrap();
    let out = run(dir.path(), &["two.gltf", "--explain-h", "Gem"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--explain-h Gem: mesh name \"Gem\" is shared by meshes 0, 1; name the mesh by index, e.g. --explain-h 0"),
        "{err}"
    );
    let out = run(dir.path(), &["two.gltf", "--explain-h", "1"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn explain_h_names_the_source_of_every_edge() {
    let dir = corpus::temp_dir();
    let mut prim = octahedron();
    prim.extras = Some(json!({ "g2tess": { "edges": [ { "a": 0, "b": 2, "h": 0.0 } ] } }));
    std::fs::write(
        dir.path().join("octa.gltf"),
        gltf("Gem", None, std::slice::from_ref(&prim)),
    )
    .unwrap();
    std::fs::write(
        dir.path().join("octa.g2tess.toml"),
        "crease_angle = 180.0\n[mesh.0]\nh = 0.1\nedges = [ { a = 3, b = 5, h = 0.05 } ]\n",
    )
    .unwrap();
    let out = run(dir.path(), &["octa.gltf", "--explain-h", "Gem"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        text.lines().filter(|l| l.contains("h = ")).count(),
        12,
        "{text}"
    );
    let line = |needle: &str| {
        text.lines()
            .find(|l| l.contains(needle))
            .unwrap_or_else(|| panic!("no row with {needle}:\n{text}"))
            .to_string()
    };
    assert!(line("h = 0.0500").contains("octa.g2tess.toml:4"), "{text}");
    assert!(
        line("h = 0.0000").contains("meshes[0].primitives[0].extras"),
        "{text}"
    );
    assert_eq!(
        text.lines().filter(|l| l.contains("h = 0.1000")).count(),
        10,
        "{text}"
    );
    assert!(
        !dir.path().join("octa.smooth.gltf").exists(),
        "--explain-h writes nothing"
    );
}

#[test]
fn every_sidecar_mistake_fails_its_file_with_the_line() {
    let cases: [(&str, &str, &[&str]); 6] = [
        (
            "h = 1.7\n",
            "h out of range",
            &["octa.g2tess.toml:1", "h must be in [0, 0.3536], got 1.7"],
        ),
        (
            "[mesh.\"Gem\"]\nedges = [ { a = 0, b = 1, h = 0.0 } ]\n",
            "edge that does not exist",
            &["octa.g2tess.toml:2", "does not exist"],
        ),
        (
            "[mesh.\"Body\"]\nh = 0.1\n",
            "unknown mesh",
            &["octa.g2tess.toml:1", "no mesh named \"Body\""],
        ),
        (
            "[mesh.0]\nedges = [\n { a = 0, b = 2, h = 0.0 },\n { a = 2, b = 0, h = 0.1 },\n]\n",
            "two values for one edge",
            &["octa.g2tess.toml:4", "different h"],
        ),
        ("h = = 0.2\n", "syntax error", &["octa.g2tess.toml:1"]),
        (
            "crease = 30\n",
            "unknown key",
            &["octa.g2tess.toml:1", "crease"],
        ),
    ];
    for (sidecar, what, expected) in cases {
        let check = |out: &std::process::Output, dir: &tempfile::TempDir| {
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(1), "{what}: {stderr}");
            let line = stderr
                .lines()
                .find(|l| l.starts_with("g2tess: error:"))
                .unwrap_or_else(|| panic!("{what}: no error line in {stderr}"));
            for e in expected {
                assert!(line.contains(e), "{what}: {line:?} lacks {e:?}");
            }
            assert!(
                !dir.path().join("out/octa.gltf").exists(),
                "{what}: output written"
            );
            assert!(
                dir.path().join("out/good.gltf").exists(),
                "{what}: good file not processed"
            );
        };
        let dir = corpus::temp_dir();
        std::fs::write(
            dir.path().join("octa.gltf"),
            gltf("Gem", None, &[octahedron()]),
        )
        .unwrap();
        std::fs::write(dir.path().join("octa.g2tess.toml"), sidecar).unwrap();
        // A good asset beside it is still processed: one bad file never stops the others.
        std::fs::write(
            dir.path().join("good.gltf"),
            gltf("Gem", None, &[octahedron()]),
        )
        .unwrap();
        std::fs::create_dir(dir.path().join("out")).unwrap();
        let out = run(dir.path(), &["octa.gltf", "good.gltf", "-o", "out"]);
        check(&out, &dir);
        // A uniform level 1 reads no edge's h, and checks the entries all the same.
        std::fs::remove_dir_all(dir.path().join("out")).unwrap();
        std::fs::create_dir(dir.path().join("out")).unwrap();
        let out = run(
            dir.path(),
            &["octa.gltf", "good.gltf", "-o", "out", "--level", "1"],
        );
        check(&out, &dir);
    }
}

/// Every corner of `mesh` gets its own vertex; normals tilted per face so every edge is a hard
/// edge in the input.
fn split_normal_prim() -> Prim {
    let mesh = support::split_normals(&support::bumpy_sphere(), 0.3);
    Prim {
        positions: mesh
            .positions
            .iter()
            .map(|p| p.as_vec3().to_array())
            .collect(),
        normals: mesh
            .normals
            .iter()
            .map(|n| n.as_vec3().to_array())
            .collect(),
        uvs: None,
        indices: mesh.triangles.iter().flatten().copied().collect(),
        extras: None,
    }
}

#[test]
fn output_normals_are_continuous_across_smooth_edges_and_jump_at_creases() {
    let dir = corpus::temp_dir();
    std::fs::write(
        dir.path().join("soup.gltf"),
        gltf("Soup", None, &[split_normal_prim()]),
    )
    .unwrap();
    let common = ["soup.gltf", "--level", "6", "--crease-angle", "180"];
    let smooth = run(
        dir.path(),
        &[&common[..], &["-o", "smooth.glb", "--h", "0.2"]].concat(),
    );
    assert!(
        smooth.status.success(),
        "{}",
        String::from_utf8_lossy(&smooth.stderr)
    );
    let sharp = run(
        dir.path(),
        &[&common[..], &["-o", "sharp.glb", "--h", "0"]].concat(),
    );
    assert!(
        sharp.status.success(),
        "{}",
        String::from_utf8_lossy(&sharp.stderr)
    );

    // Every input edge is a seam, so every edge sample is split: the two copies carry the two
    // sides' normals. Away from the corners (which are G1 cone points with split input
    // normals), G2 makes them agree to f32 rounding; plain PN does not.
    let interior = |v: &Vec<([f32; 3], f64)>| -> Vec<f64> {
        v.iter()
            .filter(|(p, _)| {
                let prim = split_normal_prim();
                !prim
                    .positions
                    .iter()
                    .any(|q| (0..3).all(|k| (q[k] - p[k]).abs() < 1e-6))
            })
            .map(|(_, a)| *a)
            .collect()
    };
    let smooth_jumps = interior(&creased_positions(&dir.path().join("smooth.glb")));
    let sharp_jumps = interior(&creased_positions(&dir.path().join("sharp.glb")));
    assert!(!smooth_jumps.is_empty() && !sharp_jumps.is_empty());
    let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
    // f32 normals are exact to about 6e-8 rad (3.4e-6°) per component.
    assert!(
        max(&smooth_jumps) < 1e-4,
        "smooth edges jump {}°",
        max(&smooth_jumps)
    );
    assert!(
        max(&sharp_jumps) > 1.0,
        "creases jump only {}°",
        max(&sharp_jumps)
    );
}

#[test]
fn report_figures_are_computed_only_when_asked_and_never_change_the_output() {
    let dir = corpus::temp_dir();
    let input = dir.path().join("soup.gltf");
    std::fs::write(&input, gltf("Soup", None, &[split_normal_prim()])).unwrap();
    let mut options = g2tess::options::Options::default();
    options.level = 3;
    options.h = 0.2;
    options.crease_angle = 180.0;
    let (quiet_out, measured_out) = (dir.path().join("a.glb"), dir.path().join("b.glb"));
    let quiet = g2tess::pipeline::process_file(&input, &quiet_out, &options).unwrap();
    options.report_figures = true;
    let measured = g2tess::pipeline::process_file(&input, &measured_out, &options).unwrap();

    let (q, m) = (&quiet.meshes[0].edges, &measured.meshes[0].edges);
    let counts = |e: &g2tess::pipeline::EdgeFigures| (e.smooth_edges, e.crease_edges, e.open_edges);
    assert_eq!(counts(q), counts(m));
    assert!(q.smooth_edges > 0 && q.crease_edges == 0, "{q:?}");
    assert_eq!((q.max_normal_jump_deg, q.max_gap), (None, None));
    assert_eq!(quiet.meshes[0].primitives[0].cache, None);
    // Every vertex is used, so at least one transform per vertex: ATVR ≥ 1, ACMR ≤ 3.
    let cache = measured.meshes[0].primitives[0].cache.expect("measured");
    assert!(
        cache.atvr >= 1.0 && cache.acmr > 0.0 && cache.acmr <= 3.0,
        "{cache:?}"
    );
    // G2 across smooth edges: the two sides agree to rounding (1e-13° measured in the surface
    // tests), however the input normals were split.
    let jump = m.max_normal_jump_deg.expect("measured");
    let gap = m.max_gap.expect("measured");
    assert!(jump < 1e-9, "normal jump {jump}°");
    assert!(gap < 1e-12, "gap {gap}");
    assert_eq!(
        std::fs::read(&quiet_out).unwrap(),
        std::fs::read(&measured_out).unwrap()
    );
}
