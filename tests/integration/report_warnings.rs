//! Every warning kind, produced by a small generated mesh and found typed in the JSON report
//! (`warning_details`, per file and per mesh) with its location, beside the unchanged sentence
//! (`warnings`, and the CLI's `-v` line); and the morph-target surfaces' warnings, which were
//! dropped before, reaching the report merged with the base surface's.

use std::path::{Path, PathBuf};

use glam::DVec3;
use serde_json::{json, Value};

use crate::corpus;
use crate::hostile::{self, tetrahedron};
use g2tess::mesh::TriMesh;
use g2tess::topology::Topology;

/// Runs the binary on `input` with `args` and `-v --report`, checks that it succeeded and that
/// every warning of the file appears once as a `-v` line, as a sentence in the report and as
/// an object whose `message` is that sentence; returns the file's `warning_details`.
fn details(input: &Path, args: &[&str]) -> Vec<Value> {
    let dir = input.parent().unwrap();
    let report = dir.join("report.json");
    let out = corpus::g2tess()
        .arg(input)
        .arg("-o")
        .arg(dir.join("out.glb"))
        .args(["--level", "2", "-v", "--report"])
        .arg(&report)
        .args(args)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let report: Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    let file = &report["files"][0];
    let sentences = file["warnings"].as_array().unwrap();
    let objects = file["warning_details"].as_array().unwrap().clone();
    assert_eq!(sentences.len(), objects.len(), "{file:#}");
    for (s, o) in sentences.iter().zip(&objects) {
        assert_eq!(&o["message"], s);
        let line = format!(
            "g2tess: warning: {}: {}",
            input.display(),
            s.as_str().unwrap()
        );
        assert!(stderr.contains(&line), "no {line:?} in {stderr}");
    }
    // Per mesh, the same objects.
    let per_mesh: Vec<Value> = file["meshes"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|m| m["warning_details"].as_array().unwrap().clone())
        .collect();
    assert_eq!(per_mesh, objects);
    objects
}

/// The one warning of `kind` among `all`.
fn one<'a>(all: &'a [Value], kind: &str) -> &'a Value {
    let found: Vec<&Value> = all.iter().filter(|w| w["kind"] == kind).collect();
    assert_eq!(found.len(), 1, "one {kind} in {all:#?}");
    found[0]
}

/// Writes the mesh as `t.gltf` + `t.bin` in `dir`.
fn write(dir: &Path, p: &[[f32; 3]], n: Option<&[[f32; 3]]>, i: &[u32]) -> PathBuf {
    hostile::write_mesh(dir, p, n, i)
}

/// The welded adjacency of the mesh, as the pipeline builds it.
fn topology(p: &[[f32; 3]], i: &[u32]) -> Topology {
    let mesh = TriMesh {
        positions: p.iter().map(|v| v.map(f64::from).into()).collect(),
        normals: vec![DVec3::Z; p.len()],
        triangles: i.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
    };
    Topology::build(&mesh)
}

/// The welded vertex of input vertex `v`.
fn welded(p: &[[f32; 3]], i: &[u32], v: usize) -> u32 {
    topology(p, i).welded_of_vertex[v].0
}

/// The welded edge between input vertices `a` and `b`.
fn edge_between(p: &[[f32; 3]], i: &[u32], a: u32, b: u32) -> usize {
    let topo = topology(p, i);
    let mut ends = [a, b].map(|v| topo.welded_of_vertex[v as usize]);
    ends.sort();
    let at = topo.edges().position(|e| e.verts == ends);
    at.expect("the edge")
}

#[test]
fn degenerate_sliver_duplicate_and_unused_are_located() {
    let dir = corpus::temp_dir();
    let (mut p, mut i) = tetrahedron();
    p.push([0.5, 0.0, 0.0]); // on the edge 0-1: triangle 4 has zero area
    i.extend([0, 1, 4]);
    i.extend([0, 2, 1]); // triangle 5: the corners of triangle 0
    p.push([9.0, 9.0, 9.0]); // vertex 5: used by no triangle
    let n = vec![[0.0, 0.0, 1.0]; p.len()];
    let all = details(&write(dir.path(), &p, Some(&n), &i), &[]);
    let w = one(&all, "degenerate_triangles");
    assert_eq!(
        (&w["mesh"], &w["count"], &w["triangles"]),
        (&json!(0), &json!(1), &json!([4]))
    );
    let w = one(&all, "duplicate_triangles");
    assert_eq!((&w["count"], &w["triangles"]), (&json!(1), &json!([5])));
    let w = one(&all, "unused_vertices");
    assert_eq!((&w["count"], &w["vertices"]), (&json!(1), &json!([5])));

    let dir = corpus::temp_dir();
    let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 1e-5, 0.0]];
    let all = details(&write(dir.path(), &p, None, &[0, 1, 2]), &[]);
    let w = one(&all, "sliver_triangles");
    assert_eq!((&w["count"], &w["triangles"]), (&json!(1), &json!([0])));
    // One open triangle: three boundary edges; no NORMAL: generated, with the angle used.
    assert_eq!(one(&all, "boundary_edges")["count"], 3);
    let w = one(&all, "normals_generated");
    assert_eq!(
        (&w["primitive"], &w["crease_angle"]),
        (&json!(0), &json!(60.0))
    );
}

#[test]
fn normals_facing_away_and_opposite_winding_are_located() {
    let dir = corpus::temp_dir();
    let (p, i) = tetrahedron();
    let inward: Vec<[f32; 3]> = p
        .iter()
        .map(|v| {
            let d = DVec3::splat(0.25) - DVec3::new(v[0].into(), v[1].into(), v[2].into());
            d.normalize().as_vec3().to_array()
        })
        .collect();
    let all = details(&write(dir.path(), &p, Some(&inward), &i), &[]);
    let w = one(&all, "normals_facing_away");
    assert_eq!(
        (&w["count"], &w["triangles"]),
        (&json!(4), &json!([0, 1, 2]))
    );

    let dir = corpus::temp_dir();
    let mut flipped = i.clone();
    flipped[9..12].copy_from_slice(&[1, 3, 2]); // triangle 3 wound the other way
    let all = details(&write(dir.path(), &p, None, &flipped), &[]);
    let mut expected = [(1, 3), (3, 2), (2, 1)].map(|(a, b)| edge_between(&p, &flipped, a, b));
    expected.sort_unstable();
    let w = one(&all, "opposite_winding_edges");
    assert_eq!((&w["count"], &w["edges"]), (&json!(3), &json!(expected)));
}

/// A book: three triangles on the edge 0-1.
const BOOK: ([[f32; 3]; 5], [u32; 9]) = (
    [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, 1.0, 0.0],
        [0.5, -0.5, 0.8],
        [0.5, -0.5, -0.8],
    ],
    [0, 1, 2, 1, 0, 3, 0, 1, 4],
);

#[test]
fn non_manifold_edges_and_bow_ties_are_located() {
    let dir = corpus::temp_dir();
    let (p, i) = BOOK;
    let all = details(&write(dir.path(), &p, None, &i), &[]);
    let w = one(&all, "non_manifold_edges");
    assert_eq!(
        (&w["count"], &w["edges"]),
        (&json!(1), &json!([edge_between(&p, &i, 0, 1)]))
    );

    let dir = corpus::temp_dir();
    // Two fans touching only at vertex 2.
    let p = [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
    ];
    let i = [2, 0, 1, 2, 3, 4];
    let n = [[0.0, 0.0, 1.0]; 5];
    let all = details(&write(dir.path(), &p, Some(&n), &i), &[]);
    let w = one(&all, "bow_tie_vertices");
    assert_eq!(
        (&w["count"], &w["vertices"]),
        (&json!(1), &json!([welded(&p, &i, 2)]))
    );
}

#[test]
fn many_pieces_are_counted() {
    let dir = corpus::temp_dir();
    let (mut p, mut i) = (Vec::new(), Vec::new());
    for k in 0..1001u32 {
        let x = k as f32 * 2.0;
        p.extend([[x, 0.0, 0.0], [x + 1.0, 0.0, 0.0], [x, 1.0, 0.0]]);
        i.extend([3 * k, 3 * k + 1, 3 * k + 2]);
    }
    let all = details(&write(dir.path(), &p, None, &i), &[]);
    assert_eq!(one(&all, "many_pieces")["pieces"], 1001);
}

#[test]
fn repaired_and_rescaled_normals_name_primitive_accessor_and_vertex() {
    let dir = corpus::temp_dir();
    let (p, i) = tetrahedron();
    let mut n = vec![[0.0, 0.0, 1.0]; 4];
    n[1] = [0.0, 0.0, 0.5];
    n[2] = [0.0; 3];
    let all = details(&write(dir.path(), &p, Some(&n), &i), &[]);
    let w = one(&all, "normals_repaired");
    assert_eq!(
        [
            &w["mesh"],
            &w["primitive"],
            &w["accessor"],
            &w["count"],
            &w["vertex"]
        ],
        [&json!(0), &json!(0), &json!(1), &json!(1), &json!(2)]
    );
    assert_eq!(
        w["message"],
        "meshes[0].primitives[0].attributes.NORMAL (accessors[1]): 1 zero-length normals (first: vertex 2) replaced by the angle-weighted normal of their faces"
    );
    let w = one(&all, "normals_rescaled");
    assert_eq!(
        [&w["accessor"], &w["count"], &w["vertex"], &w["length"]],
        [&json!(1), &json!(1), &json!(1), &json!(0.5)]
    );
}

#[test]
fn an_entry_on_a_boundary_edge_names_the_sidecar_line_and_the_edge() {
    let dir = corpus::temp_dir();
    let p = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, 1.0, 0.0],
        [0.5, -1.0, 0.0],
    ];
    let i = [0, 1, 2, 1, 0, 3];
    let input = write(dir.path(), &p, None, &i);
    let sidecar = dir.path().join("t.g2tess.toml");
    std::fs::write(&sidecar, "[mesh.0]\nedges = [{ a = 0, b = 2, h = 0.1 }]\n").unwrap();
    let all = details(&input, &[]);
    let w = one(&all, "unblended_edge_entry");
    assert_eq!(
        [&w["mesh"], &w["edge"], &w["edge_kind"], &w["h"]],
        [
            &json!(0),
            &json!(edge_between(&p, &i, 0, 2)),
            &json!("boundary"),
            &json!(0.1)
        ]
    );
    assert_eq!(
        w["at"],
        json!({"file": sidecar.display().to_string(), "line": 2, "path": "edges[0]"})
    );
}

/// No surface the pipeline builds says "h > 0 asked for on … edge(s); they use h = 0" (the
/// warning kind `blend_ignored` was removed): the widths it is built from are already 0 on
/// boundary, non-manifold and degenerate edges, and an entry naming one is reported where it
/// is resolved. A book (non-manifold edge), a zero-area triangle and open edges, every edge
/// asked for h > 0, under every scheme.
#[test]
fn edges_the_surface_cannot_blend_are_reported_once_by_their_entry() {
    let dir = corpus::temp_dir();
    // The book, and a zero-area triangle on one of its open edges.
    let p = [BOOK.0.as_slice(), &[[2.0, 0.0, 0.0]]].concat();
    let i = [BOOK.1.as_slice(), &[1, 5, 5]].concat();
    let input = write(dir.path(), &p, None, &i);
    let sidecar = dir.path().join("t.g2tess.toml");
    std::fs::write(
        &sidecar,
        "h = 0.3\n[mesh.0]\nedges = [{ a = 0, b = 2, h = 0.1 }]\n",
    )
    .unwrap();
    for scheme in ["g2", "pn", "hybrid", "coons"] {
        let all = details(&input, &["--scheme", scheme]);
        let kinds: Vec<&str> = all.iter().map(|w| w["kind"].as_str().unwrap()).collect();
        assert!(kinds.contains(&"non_manifold_edges"), "{scheme}: {kinds:?}");
        assert!(
            kinds.contains(&"degenerate_triangles"),
            "{scheme}: {kinds:?}"
        );
        assert_eq!(one(&all, "unblended_edge_entry")["edge_kind"], "boundary");
        for w in &all {
            let message = w["message"].as_str().unwrap();
            assert!(!message.contains("they use h = 0"), "{scheme}: {message}");
        }
    }
}

/// Two triangles on the edge 0-1 over the four points `p` with normals `n`, with morph targets
/// given as four position deltas then four normal deltas.
fn hinge_with_targets(
    dir: &Path,
    p: &[[f32; 3]; 4],
    n: &[[f32; 3]; 4],
    targets: &[[[f32; 3]; 8]],
) -> PathBuf {
    let (mut json, mut bin) = hostile::mesh_gltf(p, Some(n), &[0, 1, 2, 1, 0, 3], "t.bin");
    let mut list = Vec::new();
    for t in targets {
        let mut target = serde_json::Map::new();
        for (name, deltas) in [("POSITION", &t[..4]), ("NORMAL", &t[4..])] {
            let offset = bin.len();
            for d in deltas {
                for c in d {
                    bin.extend_from_slice(&c.to_le_bytes());
                }
            }
            let views = json["bufferViews"].as_array_mut().unwrap();
            views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": 48}));
            let view = views.len() - 1;
            let mut acc =
                json!({"bufferView": view, "componentType": 5126, "count": 4, "type": "VEC3"});
            if name == "POSITION" {
                let lo: Vec<f32> = (0..3)
                    .map(|c| deltas.iter().map(|d| d[c]).fold(f32::INFINITY, f32::min))
                    .collect();
                let hi: Vec<f32> = (0..3)
                    .map(|c| {
                        deltas
                            .iter()
                            .map(|d| d[c])
                            .fold(f32::NEG_INFINITY, f32::max)
                    })
                    .collect();
                acc["min"] = json!(lo);
                acc["max"] = json!(hi);
            }
            let accessors = json["accessors"].as_array_mut().unwrap();
            accessors.push(acc);
            target.insert(name.into(), json!(accessors.len() - 1));
        }
        list.push(Value::Object(target));
    }
    json["meshes"][0]["primitives"][0]["targets"] = Value::Array(list);
    json["buffers"][0]["byteLength"] = json!(bin.len());
    std::fs::write(dir.join("t.bin"), bin).unwrap();
    let input = dir.join("t.gltf");
    std::fs::write(&input, serde_json::to_vec(&json).unwrap()).unwrap();
    input
}

/// The hybrid scheme finds no projection plane for an edge whose triangles fold onto each
/// other. The base hinge is flat; targets 0 and 2 fold it into a knife edge (vertex 3 over
/// vertex 2, normals along ±y), target 1 leaves it flat. The base surface says nothing; the
/// targets' surfaces each say the same thing, which the report gives once, naming both (before,
/// every morph target's surface warnings were discarded).
#[test]
fn a_morph_target_that_folds_an_edge_is_reported_once_naming_its_targets() {
    let dir = corpus::temp_dir();
    let knife = [
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0],
        [0.0, 2.0, 0.05],
        [0.0, -1.0, -1.0],
        [0.0, -1.0, -1.0],
        [0.0, 1.0, -1.0],
        [0.0, 1.0, -1.0],
    ];
    let flat = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, 1.0, 0.0],
        [0.5, -1.0, 0.0],
    ];
    let up = [[0.0, 0.0, 1.0]; 4];
    let input = hinge_with_targets(dir.path(), &flat, &up, &[knife, [[0.0; 3]; 8], knife]);
    let args = ["--scheme", "hybrid", "--crease-angle", "180"];
    let all = details(&input, &args);
    let w = one(&all, "no_projection_plane");
    assert_eq!(
        [&w["mesh"], &w["targets"], &w["count"], &w["edge"]],
        [&json!(0), &json!([0, 2]), &json!(1), &json!(0)]
    );
    assert_eq!(
        w["message"],
        "mesh 0, morph targets 0, 2: no projection plane for 1 folded edge(s) (first: edge 0); they are creases"
    );
}

/// The same fold in the base and in a target: the base's warning alone, no copy for the target.
#[test]
fn a_target_warning_the_base_already_gives_is_not_repeated() {
    let dir = corpus::temp_dir();
    let knife = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, 1.0, 0.0],
        [0.5, 1.0, 0.05],
    ];
    let n = [
        [0.0, -1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    // One target that moves nothing: its surface is the base's, with the same warning.
    let input = hinge_with_targets(dir.path(), &knife, &n, &[[[0.0; 3]; 8]]);
    let all = details(&input, &["--scheme", "hybrid", "--crease-angle", "180"]);
    let w = one(&all, "no_projection_plane");
    assert_eq!(w["targets"], json!([]));
}

/// `--merge-reports` keeps each record whole: the typed warnings come through a merge as
/// written.
#[test]
fn merged_reports_keep_the_typed_warnings() {
    let dir = corpus::temp_dir();
    let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 1e-5, 0.0]];
    let input = write(dir.path(), &p, None, &[0, 1, 2]);
    let written = details(&input, &[]);
    let merged = dir.path().join("merged.json");
    let out = corpus::g2tess()
        .arg("--merge-reports")
        .arg(&merged)
        .arg(dir.path().join("report.json"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let merged: Value = serde_json::from_slice(&std::fs::read(&merged).unwrap()).unwrap();
    assert_eq!(
        merged["files"][0]["warning_details"].as_array().unwrap(),
        &written
    );
    assert_eq!(merged["format"], 1);
}
