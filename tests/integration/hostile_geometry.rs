//! Bad numbers and odd topology: each either is an error located by JSON path, or is processed
//! with a documented fallback and one warning in the report; the real binary writes only finite
//! numbers. One test per kind, each on a tiny literal mesh.

use crate::corpus;
use crate::hostile;
use crate::support;

use std::path::Path;

use crate::hostile::{run_limited, scan_non_finite, tetrahedron, verdict};
use g2tess::gltf_io::{self, ReadOptions};
use g2tess::options::Options;

/// Writes the mesh as `t.gltf` + `t.bin` in a fresh folder, processes it in the library (for the
/// report's warnings) and with the real binary (for the exit status and the output), and returns
/// the warnings, or the binary's error message.
fn process(
    positions: &[[f32; 3]],
    normals: Option<&[[f32; 3]]>,
    indices: &[u32],
) -> Result<Vec<String>, String> {
    let dir = corpus::temp_dir();
    let input = hostile::write_mesh(dir.path(), positions, normals, indices);

    let output = dir.path().join("out.glb");
    let run = run_limited(
        &[
            input.as_os_str(),
            "-o".as_ref(),
            output.as_os_str(),
            "--level".as_ref(),
            "4".as_ref(),
        ],
        None,
    );
    assert_eq!(verdict(&run), None, "{run:?}");
    if run.code == Some(1) {
        assert!(!output.exists());
        return Err(run.stderr);
    }
    scan_non_finite(&output).unwrap();

    let mut doc = gltf_io::read(&input, &ReadOptions::default()).unwrap();
    let report =
        g2tess::pipeline::process_document(&mut doc, Path::new(&input), &Options::default())
            .unwrap();
    Ok(report.warnings().map(ToString::to_string).collect())
}

fn warned(warnings: &[String], what: &str) {
    assert!(
        warnings.iter().any(|w| w.contains(what)),
        "no warning with {what:?} in {warnings:#?}"
    );
}

#[test]
fn zero_area_triangle_is_kept_flat_with_a_warning() {
    let (mut p, mut i) = tetrahedron();
    p.push([0.5, 0.0, 0.0]); // on the edge 0-1
    i.extend([0, 1, 4]);
    warned(
        &process(&p, None, &i).unwrap(),
        "1 zero-area triangles (first: 4)",
    );
}

#[test]
fn sliver_triangle_is_smoothed_with_a_warning() {
    let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 1e-5, 0.0]];
    warned(
        &process(&p, None, &[0, 1, 2]).unwrap(),
        "1 sliver triangles",
    );
}

#[test]
fn duplicate_triangle_is_kept_with_a_warning() {
    let (p, mut i) = tetrahedron();
    i.extend([0, 2, 1]);
    warned(
        &process(&p, None, &i).unwrap(),
        "1 duplicate triangles (first: 4)",
    );
}

#[test]
fn unused_vertex_is_dropped_with_a_warning() {
    let (mut p, i) = tetrahedron();
    p.push([5.0, 5.0, 5.0]);
    let n = vec![[0.0, 0.0, 1.0]; 5];
    warned(
        &process(&p, Some(&n), &i).unwrap(),
        "1 vertices used by no triangle (first: 4)",
    );
}

#[test]
fn normals_facing_away_orient_the_surface_with_a_warning() {
    let (p, i) = tetrahedron();
    let centre = [0.25f32; 3];
    let inward: Vec<[f32; 3]> = p
        .iter()
        .map(|v| {
            let d = [centre[0] - v[0], centre[1] - v[1], centre[2] - v[2]];
            let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            d.map(|x| x / l)
        })
        .collect();
    warned(
        &process(&p, Some(&inward), &i).unwrap(),
        "normals all face away from their winding",
    );
}

#[test]
fn zero_normal_is_repaired_with_a_warning() {
    let (p, i) = tetrahedron();
    let mut n = vec![[0.0, 0.0, 1.0]; 4];
    n[2] = [0.0; 3];
    warned(
        &process(&p, Some(&n), &i).unwrap(),
        "meshes[0].primitives[0].attributes.NORMAL (accessors[1]): 1 zero-length normals (first: vertex 2) replaced by the angle-weighted normal of their faces",
    );
}

#[test]
fn non_finite_normal_is_an_error_at_its_element() {
    let (p, i) = tetrahedron();
    let mut n = vec![[0.0, 0.0, 1.0]; 4];
    n[2] = [0.0, f32::NAN, 1.0];
    let e = process(&p, Some(&n), &i).unwrap_err();
    assert!(
        e.contains("accessors[1]: element 2 holds NaN (expected finite numbers)"),
        "{e}"
    );
}

#[test]
fn non_finite_position_is_an_error_at_its_element() {
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let (mut p, i) = tetrahedron();
        p[3][1] = bad;
        let e = process(&p, None, &i).unwrap_err();
        assert!(
            e.contains("accessors[0]: element 3 holds") && e.contains("(expected finite numbers)"),
            "{e}"
        );
    }
}

#[test]
fn out_of_range_index_is_an_error_at_its_position() {
    let (p, mut i) = tetrahedron();
    i[7] = 4;
    let e = process(&p, None, &i).unwrap_err();
    assert!(
        e.contains(
            "meshes[0].primitives[0].indices: index 4 at position 7 (expected a vertex below 4"
        ),
        "{e}"
    );
}

#[test]
fn primitive_restart_value_is_an_error_at_its_position() {
    let (p, mut i) = tetrahedron();
    i[5] = u32::MAX;
    let e = process(&p, None, &i).unwrap_err();
    assert!(
        e.contains("indices: index 4294967295 at position 5")
            && e.contains("not the restart value"),
        "{e}"
    );
}

#[test]
fn non_manifold_edge_is_left_sharp_with_a_warning() {
    let p = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, 1.0, 0.0],
        [0.5, -1.0, 0.0],
        [0.5, 0.0, 1.0],
    ];
    let w = process(&p, None, &[0, 1, 2, 1, 0, 3, 0, 1, 4]).unwrap();
    warned(&w, "1 non-manifold edges");
}

/// Two triangles that touch only at vertex 0 (`[0, 1, 2]` and `[0, 3, 4]`).
const BOW_TIE: [[f32; 3]; 5] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [-1.0, 0.0, 0.0],
    [-1.0, -1.0, 0.0],
];

#[test]
fn bow_tie_vertex_is_kept_with_a_warning() {
    let p = BOW_TIE;
    warned(
        &process(&p, None, &[0, 1, 2, 0, 3, 4]).unwrap(),
        "1 bow-tie vertices",
    );
}

#[test]
fn inconsistent_winding_is_smoothed_with_a_warning() {
    let (p, mut i) = tetrahedron();
    i.swap(1, 2); // flip the first triangle
    warned(
        &process(&p, None, &i).unwrap(),
        "3 edges between triangles of opposite winding",
    );
}

#[test]
fn open_boundary_is_reported_once_and_not_as_an_ignored_h() {
    let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let w = process(&p, None, &[0, 1, 2]).unwrap();
    warned(&w, "3 open boundary edges");
    // The default h covers boundary edges without naming them: nothing to warn about.
    assert!(!w.iter().any(|w| w.contains("asked for")), "{w:#?}");
}

/// A book of 2 000 distinct triangles on one edge: one non-manifold edge, no bow-tie (all pages
/// meet along the spine), and no duplicates.
#[test]
fn book_of_pages_on_one_edge_is_one_non_manifold_edge() {
    let mut p = vec![[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
    let mut i = Vec::new();
    for k in 0..2000u32 {
        let a = k as f32 * std::f32::consts::TAU / 2000.0;
        p.push([a.cos(), a.sin(), 0.5]);
        i.extend([0, 1, k + 2]);
    }
    let w = process(&p, None, &i).unwrap();
    warned(
        &w,
        "1 non-manifold edges (three or more triangles) (first: ",
    );
    assert!(
        !w.iter()
            .any(|w| w.contains("bow-tie") || w.contains("duplicate")),
        "{w:#?}"
    );
}

/// 2 000 copies of one triangle plus a second fan touching it at one vertex only: 1 999
/// duplicates and one bow-tie vertex (the copies form one fan, the other triangle another).
#[test]
fn copies_of_a_triangle_and_a_second_fan_give_exact_counts() {
    let p = BOW_TIE;
    let mut i = [0, 1, 2].repeat(2000);
    i.extend([0, 3, 4]);
    let w = process(&p, None, &i).unwrap();
    warned(&w, "1999 duplicate triangles (first: 1, 2, 3)");
    warned(
        &w,
        "1 bow-tie vertices (triangle fans that touch only at the vertex) (first: 0)",
    );
}

#[test]
fn thousands_of_tiny_pieces_are_each_smoothed_with_a_warning() {
    let mut p = Vec::new();
    let mut i = Vec::new();
    for k in 0..3000u32 {
        let (x, y) = ((k % 60) as f32 * 0.01, (k / 60) as f32 * 0.01);
        p.extend([[x, y, 0.0], [x + 0.001, y, 0.0], [x, y + 0.001, 0.0]]);
        i.extend([3 * k, 3 * k + 1, 3 * k + 2]);
    }
    warned(&process(&p, None, &i).unwrap(), "3000 disconnected pieces");
}

/// An 80-triangle sphere of radius 3.38e38 with tilted normals: the hybrid and Coons control
/// points leave the f32 range (they wrote Infinity, which the validator rejects). Every scheme
/// either writes only finite numbers or fails the file naming the primitive and attribute.
#[test]
fn a_surface_beyond_the_float_range_is_refused_never_written() {
    let mesh = support::subdivide(&support::icosahedron());
    let p: Vec<[f32; 3]> = mesh
        .positions
        .iter()
        .map(|q| (*q * 3.38e38).as_vec3().to_array())
        .collect();
    let n: Vec<[f32; 3]> = mesh
        .positions
        .iter()
        .map(|q| {
            let tilt = glam::DVec3::new(q.x + 0.4 * q.y, q.y - 0.4 * q.x, q.z + 0.3);
            tilt.normalize().as_vec3().to_array()
        })
        .collect();
    let i: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let dir = corpus::temp_dir();
    let input = hostile::write_mesh(dir.path(), &p, Some(&n), &i);
    let mut refused = Vec::new();
    for scheme in ["g2", "pn", "hybrid", "coons"] {
        let output = dir.path().join(format!("{scheme}.glb"));
        let run = run_limited(
            &[
                input.as_os_str(),
                "-o".as_ref(),
                output.as_os_str(),
                "--scheme".as_ref(),
                scheme.as_ref(),
            ],
            None,
        );
        assert_eq!(verdict(&run), None, "{scheme}: {run:?}");
        if run.code == Some(1) {
            assert!(
                run.stderr.contains(&format!(
                    "meshes[0].primitives[0].attributes.POSITION: the {scheme} surface reaches inf"
                )),
                "{scheme}: {}",
                run.stderr
            );
            assert!(!output.exists(), "{scheme}: wrote an output");
            refused.push(scheme);
        } else {
            scan_non_finite(&output).unwrap_or_else(|e| panic!("{scheme}: {e}"));
        }
    }
    // The case is only a test while some scheme still overflows here.
    assert!(
        !refused.is_empty(),
        "no scheme overflowed: raise the radius"
    );
}
