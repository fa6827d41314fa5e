//! Per-edge h resolution on small literal meshes: each source lands on the right edge, the
//! precedence order holds end to end, both naming forms work, and mistakes are located.

use crate::sharpness_support::{cube, hinge, hinge_two_prims, Case};
use g2tess::sharpness::{explain_rows, HSource};
use serde_json::json;

const O: [f64; 3] = [0.0, 0.0, 0.0];
const X: [f64; 3] = [1.0, 0.0, 0.0];
const APEX: [f64; 3] = [0.5, 1.0, 0.0];

// --- naming ---

#[test]
fn sidecar_entry_by_indices_sets_only_that_edge() {
    let r = Case::new(hinge(30.0))
        .sidecar("[mesh.\"Body\"]\nedges = [{ a = 1, b = 0, h = 0.01 }]\n")
        .run()
        .unwrap();
    assert_eq!(r.h(O, X), 0.01);
    assert_eq!(r.h(O, APEX), 0.08);
    assert_eq!(r.params.h.iter().filter(|&&h| h == 0.01).count(), 1);
}

#[test]
fn entry_by_positions_matches_in_either_order_within_tolerance() {
    // 1e-6 off: inside 1e-5 of the bounding-box diagonal (sqrt(5)).
    let r = Case::new(hinge(0.0))
        .mesh_extras(json!({"g2tess": {"edges": [
            {"from": [1.000001, 0, 0], "to": [0, 0, 0], "h": 0.02}]}}))
        .run()
        .unwrap();
    assert_eq!(r.h(O, X), 0.02);
    assert_eq!(r.params.h.iter().filter(|&&h| h == 0.02).count(), 1);
}

#[test]
fn position_beyond_tolerance_is_an_error() {
    let case = Case::new(hinge(0.0)).mesh_extras(json!({"g2tess": {"edges": [
        {"from": [1.0001, 0, 0], "to": [0, 0, 0], "h": 0.02}]}}));
    assert_eq!(
        case.error(),
        "robot.glb: meshes[0].extras.g2tess.edges[0]: no vertex of mesh \"Body\" within 2.236e-5 of [1.0001, 0, 0]"
    );
}

#[test]
fn two_vertices_within_tolerance_are_ambiguous() {
    let mut f = hinge(0.0);
    // A sliver: a fifth vertex 1e-7 from the origin, used by a third triangle.
    f.mesh.positions.push(glam::DVec3::new(1e-7, 0.0, 0.0));
    f.mesh.normals.push(glam::DVec3::Z);
    f.mesh.triangles.push([4, 2, 0]);
    f.prims = vec![(0, 5)];
    let case =
        Case::new(f).sidecar("[mesh.0]\nedges = [{ from = [0, 0, 0], to = [1, 0, 0], h = 0.1 }]\n");
    assert_eq!(
        case.error(),
        "robot.g2tess.toml:2: edges[0]: 2 vertices of mesh \"Body\" lie within 2.236e-5 of [0, 0, 0], the edge is ambiguous; use `a` and `b`"
    );
}

#[test]
fn edge_between_unconnected_vertices_does_not_exist() {
    let case = Case::new(hinge(0.0))
        .sidecar("[mesh.\"Body\"]\nh = 0.1\nedges = [\n  { a = 0, b = 1, h = 0.0 },\n  { a = 2, b = 3, h = 0.0 },\n]\n");
    assert_eq!(
        case.error(),
        "robot.g2tess.toml:5: edges[1]: edge (2, 3) does not exist in primitive 0 of mesh \"Body\""
    );
    let case = Case::new(hinge(0.0)).mesh_extras(json!({"g2tess": {"edges": [
        {"from": [0.5, 1, 0], "to": [0.5, -1, 0], "h": 0}]}}));
    assert_eq!(
        case.error(),
        "robot.glb: meshes[0].extras.g2tess.edges[0]: no edge between [0.5, 1, 0] and [0.5, -1, 0] in mesh \"Body\""
    );
}

#[test]
fn vertex_index_out_of_range() {
    let case = Case::new(hinge(0.0))
        .prim_extras(0, json!({"g2tess": {"edges": [{"a": 0, "b": 7, "h": 0}]}}));
    assert_eq!(
        case.error(),
        "robot.glb: meshes[0].primitives[0].extras.g2tess.edges[0]: vertex 7 is out of range: primitive 0 of mesh \"Body\" has 4 vertices"
    );
}

#[test]
fn indices_are_local_to_their_primitive() {
    // In primitive 1, local vertices 0 and 1 are (1,0,0) and (0,0,0): the shared hinge edge.
    let r = Case::new(hinge_two_prims(0.0))
        .sidecar("[mesh.0]\nedges = [{ primitive = 1, a = 0, b = 1, h = 0.03 }]\n")
        .run()
        .unwrap();
    assert_eq!(r.h(O, X), 0.03);
}

#[test]
fn primitive_is_required_when_the_mesh_has_several() {
    let case =
        Case::new(hinge_two_prims(0.0)).sidecar("[mesh.0]\nedges = [{ a = 0, b = 1, h = 0.03 }]\n");
    assert_eq!(
        case.error(),
        "robot.g2tess.toml:2: edges[0]: `primitive` is required: mesh \"Body\" has 2 primitives"
    );
    let case = Case::new(hinge_two_prims(0.0))
        .sidecar("[mesh.0]\nedges = [{ primitive = 2, a = 0, b = 1, h = 0.03 }]\n");
    assert_eq!(
        case.error(),
        "robot.g2tess.toml:2: edges[0]: mesh \"Body\" has no triangle primitive 2 (triangle primitives: 0, 1)"
    );
}

// --- meshes in the sidecar ---

#[test]
fn unknown_mesh_name_lists_the_known_ones() {
    let case = Case::new(hinge(0.0)).sidecar("h = 0.1\n\n[mesh.\"Bdy\"]\nh = 0.2\n");
    assert_eq!(
        case.error(),
        "robot.g2tess.toml:3: no mesh named \"Bdy\" (meshes: \"Body\")"
    );
}

#[test]
fn unknown_mesh_index() {
    let case = Case::new(hinge(0.0)).sidecar("[mesh.3]\nh = 0.2\n");
    assert_eq!(
        case.error(),
        "robot.g2tess.toml:1: no mesh 3 (mesh count: 1)"
    );
}

#[test]
fn shared_mesh_name_must_be_addressed_by_index() {
    let mut case = Case::new(hinge(0.0)).sidecar("[mesh.\"Body\"]\nh = 0.2\n");
    case.mesh_names = vec![Some("Body"), None, Some("Body")];
    assert_eq!(
        case.error(),
        "robot.g2tess.toml:1: mesh name \"Body\" is shared by meshes 0, 2; name the section by index, e.g. [mesh.0]"
    );
}

#[test]
fn one_mesh_by_name_and_by_index_is_a_duplicate() {
    let case = Case::new(hinge(0.0)).sidecar("[mesh.\"Body\"]\nh = 0.2\n[mesh.0]\nh = 0.1\n");
    assert_eq!(
        case.error(),
        "robot.g2tess.toml:3: mesh \"Body\" already has a section at line 1"
    );
}

// --- duplicates ---

#[test]
fn same_edge_twice_with_different_h_is_an_error() {
    let case = Case::new(hinge(0.0)).sidecar(
        "[mesh.0]\nedges = [\n  { a = 0, b = 1, h = 0.05 },\n  { from = [1, 0, 0], to = [0, 0, 0], h = 0.1 },\n]\n",
    );
    assert_eq!(
        case.error(),
        "robot.g2tess.toml:4: edges[1]: edge [0, 0, 0]–[1, 0, 0] has two entries with different h: 0.1 here, 0.05 at robot.g2tess.toml:3: edges[0]"
    );
}

#[test]
fn same_edge_twice_with_the_same_h_is_fine() {
    let r = Case::new(hinge(0.0))
        .sidecar("[mesh.0]\nedges = [\n  { a = 0, b = 1, h = 0.05 },\n  { from = [1, 0, 0], to = [0, 0, 0], h = 0.05 },\n]\n")
        .run()
        .unwrap();
    assert_eq!(r.h(O, X), 0.05);
}

#[test]
fn two_primitives_naming_their_shared_edge_differently_conflict() {
    let case = Case::new(hinge_two_prims(0.0))
        .prim_extras(
            0,
            json!({"g2tess": {"edges": [{"a": 0, "b": 1, "h": 0.05}]}}),
        )
        .prim_extras(
            1,
            json!({"g2tess": {"edges": [{"a": 0, "b": 1, "h": 0.1}]}}),
        );
    assert_eq!(
        case.error(),
        "robot.glb: meshes[0].primitives[1].extras.g2tess.edges[0]: edge [0, 0, 0]–[1, 0, 0] has two entries with different h: 0.1 here, 0.05 at robot.glb: meshes[0].primitives[0].extras.g2tess.edges[0]"
    );
}

// --- precedence ---

const CUBE_SIDECAR_ALL: &str = r#"
h = 0.07
[mesh."Body"]
h = 0.04
edges = [{ a = 0, b = 1, h = 0.01 }]
"#;

fn cube_extras() -> (serde_json::Value, serde_json::Value) {
    let mesh = json!({"g2tess": {"h": 0.06, "crease_angle": 60, "edges": [
        {"a": 0, "b": 1, "h": 0.03}, {"a": 0, "b": 2, "h": 0.03}, {"a": 0, "b": 4, "h": 0.03}]}});
    let prim = json!({"g2tess": {"h": 0.05, "edges": [
        {"a": 0, "b": 1, "h": 0.02}, {"a": 0, "b": 2, "h": 0.02}]}});
    (mesh, prim)
}

#[test]
fn edge_entries_beat_each_other_in_order_and_beat_the_crease_rule() {
    let (mesh, prim) = cube_extras();
    let r = Case::new(cube())
        .sidecar(CUBE_SIDECAR_ALL)
        .mesh_extras(mesh)
        .prim_extras(0, prim)
        .run()
        .unwrap();
    let (y, z) = ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
    assert_eq!(r.h(O, X), 0.01, "sidecar edge entry");
    assert_eq!(r.h(O, y), 0.02, "primitive extras edge entry");
    assert_eq!(r.h(O, z), 0.03, "mesh extras edge entry");
    // The 9 other cube edges meet at 90° > 60°: the rule beats every default h.
    let at_90 = r.h_at_dihedral(90.0);
    assert_eq!(at_90.len(), 12);
    assert_eq!(at_90.iter().filter(|&&h| h == 0.0).count(), 9);
    assert_eq!(r.h_at_dihedral(0.0), vec![0.04; 6], "sidecar mesh default");
}

/// Smoothing resolves only the effective widths: every one is what the full resolution gives,
/// under every source (edge entries at each level, the crease rule, each default), and the
/// requested widths are left unbuilt.
#[test]
fn effective_widths_alone_match_the_full_resolution() {
    let (mesh, prim) = cube_extras();
    let cases = [
        Case::new(cube())
            .sidecar(CUBE_SIDECAR_ALL)
            .mesh_extras(mesh)
            .prim_extras(0, prim),
        Case::new(cube()).mesh_extras(json!({"g2tess": {"h": 0.2, "crease_angle": 60}})),
        Case::new(cube()).sidecar("h = 0.07\n[mesh.0]\nh = 0.3\n"),
        Case::new(hinge(30.0)).sidecar("[mesh.\"Body\"]\nedges = [{ a = 1, b = 0, h = 0.01 }]\n"),
    ];
    for (i, mut case) in cases.into_iter().enumerate() {
        let full = case.run().unwrap().params;
        case.sources = false;
        case.effective_only = true;
        let only = case.run().unwrap().params;
        assert_eq!(only.effective, full.effective, "case {i}");
        assert!(full.effective.iter().any(|&h| h > 0.0), "case {i}");
        assert_eq!((only.h.len(), only.sources.len()), (0, 0), "case {i}");
        assert_eq!(only.warnings, full.warnings, "case {i}");
        // Where sources are kept, the requested widths are too.
        case.sources = true;
        assert_eq!(case.run().unwrap().params.h, full.h, "case {i}");
    }
}

/// A run that reads no width still binds and checks every edge entry: the same warnings, and
/// the same error for an entry naming no edge and for two values on one edge, at every level
/// of entries; it picks no width.
#[test]
fn checking_the_entries_alone_finds_what_the_full_resolution_finds() {
    let (mesh, prim) = cube_extras();
    let good = [
        Case::new(hinge(0.0)).sidecar("[mesh.0]\nedges = [{ a = 0, b = 2, h = 0.1 }]\n"),
        Case::new(cube())
            .sidecar(CUBE_SIDECAR_ALL)
            .mesh_extras(mesh)
            .prim_extras(0, prim),
    ];
    for (i, mut case) in good.into_iter().enumerate() {
        let full = case.run().unwrap().params;
        case.entries_only = true;
        let only = case.run().unwrap().params;
        assert_eq!(only.warnings, full.warnings, "case {i}");
        let widths = (only.h.len(), only.effective.len(), only.sources.len());
        assert_eq!(widths, (0, 0, 0), "case {i}");
    }
    assert!(!Case::new(hinge(0.0))
        .sidecar("[mesh.0]\nedges = [{ a = 0, b = 2, h = 0.1 }]\n")
        .run()
        .unwrap()
        .params
        .warnings
        .is_empty());
    let bad = [
        Case::new(hinge(0.0)).sidecar("[mesh.0]\nedges = [{ a = 0, b = 9, h = 0.1 }]\n"),
        Case::new(hinge(0.0))
            .sidecar("[mesh.0]\nedges = [{ a = 0, b = 1, h = 0.0 }, { a = 1, b = 0, h = 0.1 }]\n"),
        Case::new(hinge(0.0)).mesh_extras(json!({"g2tess": {"edges": [
            {"a": 0, "b": 1, "h": 0.0}, {"a": 1, "b": 0, "h": 0.1}]}})),
    ];
    for (i, mut case) in bad.into_iter().enumerate() {
        let full = case.error();
        case.entries_only = true;
        assert_eq!(case.error(), full, "case {i}");
    }
}

#[test]
fn each_default_level_beats_the_next() {
    // Remove the default levels one at a time, strongest first; the face diagonals (flat, so
    // never creases) show which one is left in charge.
    // (sidecar, primitive extras h, mesh extras h, expected h, expected source)
    let cases = [
        (
            "h = 0.07\n[mesh.0]\nh = 0.04\n",
            Some(0.05),
            Some(0.06),
            0.04,
            "sidecar mesh default",
        ),
        (
            "h = 0.07\n",
            Some(0.05),
            Some(0.06),
            0.05,
            "primitive extras default",
        ),
        ("h = 0.07\n", None, Some(0.06), 0.06, "mesh extras default"),
        ("h = 0.07\n", None, None, 0.07, "sidecar asset default"),
        ("", None, None, 0.08, "default h from the options"),
    ];
    for (sidecar, prim_h, mesh_h, want, source) in cases {
        let mut case = Case::new(cube()).sidecar(sidecar);
        if let Some(h) = prim_h {
            case = case.prim_extras(0, json!({"g2tess": {"h": h}}));
        }
        if let Some(h) = mesh_h {
            case = case.mesh_extras(json!({"g2tess": {"h": h}}));
        }
        let r = case.run().unwrap();
        assert_eq!(r.h_at_dihedral(0.0), vec![want; 6], "{source}");
        assert!(
            r.source([0.0; 3], [1.0, 1.0, 0.0]).starts_with(source),
            "{source}"
        );
    }
}

#[test]
fn crease_angle_next_to_a_default_h_keeps_creases_sharp() {
    let r = Case::new(cube())
        .mesh_extras(json!({"g2tess": {"h": 0.2, "crease_angle": 60}}))
        .run()
        .unwrap();
    assert_eq!(r.h_at_dihedral(90.0), vec![0.0; 12]);
    assert_eq!(r.h_at_dihedral(0.0), vec![0.2; 6]);
}

#[test]
fn most_specific_crease_angle_wins() {
    // The sidecar section's 100° beats the mesh extras' 60°: 90° edges are not creases.
    let r = Case::new(cube())
        .sidecar("crease_angle = 10\n[mesh.0]\ncrease_angle = 100\n")
        .mesh_extras(json!({"g2tess": {"crease_angle": 60}}))
        .run()
        .unwrap();
    assert_eq!(r.h_at_dihedral(90.0), vec![0.08; 12]);
    // The sidecar's top level beats the options.
    let mut case = Case::new(cube()).sidecar("crease_angle = 100\n");
    case.defaults.crease_angle = 45.0;
    assert_eq!(case.run().unwrap().h_at_dihedral(90.0), vec![0.08; 12]);
}

#[test]
fn crease_angle_from_the_options_applies_when_no_file_sets_one() {
    let mut case = Case::new(cube());
    case.defaults.crease_angle = 45.0;
    let r = case.run().unwrap();
    assert_eq!(r.h_at_dihedral(90.0), vec![0.0; 12]);
    assert!(
        r.source(O, X).ends_with("crease_angle 45° (options)"),
        "{}",
        r.source(O, X)
    );
}

#[test]
fn crease_rule_at_the_threshold() {
    let at = |crease: f64| {
        Case::new(hinge(60.0))
            .mesh_extras(json!({"g2tess": {"crease_angle": crease}}))
            .run()
            .unwrap()
            .h(O, X)
    };
    assert_eq!(at(60.0), 0.08, "exactly at the angle: not a crease");
    assert_eq!(at(59.99), 0.0, "just below: a crease");
}

#[test]
fn crease_rule_ignores_mixed_winding() {
    // The second triangle wound the other way still meets the first at 60°, not 120°.
    let mut f = hinge(60.0);
    f.mesh.triangles[1] = [0, 1, 3];
    let r = Case::new(f)
        .mesh_extras(json!({"g2tess": {"crease_angle": 90}}))
        .run()
        .unwrap();
    assert_eq!(r.h(O, X), 0.08);
}

#[test]
fn hard_edges_are_sharp_only_when_kept() {
    let mut case = Case::new(hinge_two_prims(20.0)).mesh_extras(json!({"g2tess": {"h": 0.2}}));
    assert_eq!(case.run().unwrap().h(O, X), 0.2);
    case.defaults.keep_hard_edges = true;
    let r = case.run().unwrap();
    assert_eq!(r.h(O, X), 0.0);
    assert_eq!(r.params.sources[r.edge(O, X).0 as usize], HSource::HardEdge);
}

/// Which source set each edge's h (32 bytes per edge) is resolved only for `--explain-h`:
/// without it the list is empty and the widths are the same.
#[test]
fn sources_are_kept_only_when_asked_for() {
    let mut case = Case::new(hinge_two_prims(20.0))
        .mesh_extras(json!({"g2tess": {"h": 0.2}}))
        .sidecar("[mesh.0]\nedges = [{ from = [0, 0, 0], to = [1, 0, 0], h = 0.1 }]\n");
    let with = case.run().unwrap();
    assert_eq!(with.params.sources.len(), with.topo.edge_count());
    case.sources = false;
    let without = case.run().unwrap();
    assert!(without.params.sources.is_empty());
    assert_eq!(without.params.h, with.params.h);
    assert_eq!(without.params.effective, with.params.effective);
    assert_eq!(without.params.warnings, with.params.warnings);
}

#[test]
fn shared_edge_takes_the_sharper_primitive_default() {
    let r = Case::new(hinge_two_prims(0.0))
        .prim_extras(0, json!({"g2tess": {"h": 0.2}}))
        .prim_extras(1, json!({"g2tess": {"h": 0.1}}))
        .run()
        .unwrap();
    assert_eq!(r.h(O, X), 0.1);
    assert_eq!(r.h(O, APEX), 0.2, "primitive 0 alone");
    assert!(r
        .source(O, X)
        .contains("meshes[0].primitives[1].extras.g2tess.h"));
}

#[test]
fn primitive_without_its_own_default_contributes_the_mesh_default() {
    let r = Case::new(hinge_two_prims(0.0))
        .mesh_extras(json!({"g2tess": {"h": 0.05}}))
        .prim_extras(0, json!({"g2tess": {"h": 0.2}}))
        .run()
        .unwrap();
    assert_eq!(r.h(O, X), 0.05);
    assert!(r.source(O, X).starts_with("mesh extras default"));
}

#[test]
fn shared_edge_takes_the_smaller_crease_angle() {
    let r = Case::new(hinge_two_prims(50.0))
        .prim_extras(0, json!({"g2tess": {"crease_angle": 90}}))
        .prim_extras(1, json!({"g2tess": {"crease_angle": 40}}))
        .run()
        .unwrap();
    assert_eq!(r.h(O, X), 0.0);
    assert!(r
        .source(O, X)
        .contains("meshes[0].primitives[1].extras.g2tess.crease_angle"));
}

// --- warnings and explain ---

#[test]
fn blending_a_boundary_edge_is_a_warning() {
    let r = Case::new(hinge(0.0))
        .sidecar("[mesh.0]\nedges = [{ a = 0, b = 2, h = 0.1 }]\n")
        .run()
        .unwrap();
    let warnings: Vec<String> = r.params.warnings.iter().map(ToString::to_string).collect();
    assert_eq!(
        warnings,
        ["robot.g2tess.toml:2: edges[0]: h = 0.1 has no effect on a boundary edge, which always uses h = 0"]
    );
}

#[test]
fn explain_rows_name_the_source_of_each_edge() {
    let r = Case::new(hinge(90.0))
        .sidecar("h = 0.07\n[mesh.0]\nedges = [\n  { a = 0, b = 2, h = 0.0 },\n]\n")
        .mesh_extras(json!({"g2tess": {"crease_angle": 60}}))
        .run()
        .unwrap();
    let rows = explain_rows(&r.params, &r.topo);
    assert_eq!(rows.len(), 5);
    let row = |p: [f64; 3], q: [f64; 3]| {
        let id = r.edge(p, q);
        rows.iter().find(|row| row.edge == id).unwrap().to_string()
    };
    assert_eq!(
        row(O, APEX),
        "edge 1  [0, 0, 0] – [0.5, 1, 0]  h = 0.0000  sidecar edge entry (robot.g2tess.toml:4: edges[0])  [boundary: not blended]"
    );
    assert!(
        row(O, X).ends_with(
            "h = 0.0000  crease: faces meet at 90.00° > crease_angle 60° (robot.glb: meshes[0].extras.g2tess.crease_angle)"
        ),
        "{}",
        row(O, X)
    );
    assert!(row(X, APEX).ends_with(
        "h = 0.0700  sidecar asset default (robot.g2tess.toml:1: h)  [boundary: not blended]"
    ));
}
