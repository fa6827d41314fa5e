//! The two h formats (extras JSON, sidecar TOML): what they accept, and the exact message for
//! each mistake, located by JSON path or TOML line.

use std::path::Path;

use crate::sharpness_support::{hinge, Case, SIDECAR};
use g2tess::sharpness::{sidecar_path_for, Sidecar};
use serde_json::json;

fn sidecar_error(text: &str) -> String {
    Sidecar::parse(Path::new(SIDECAR), text)
        .expect_err("expected an error")
        .to_string()
}

// --- sidecar ---

#[test]
fn sidecar_full_example_parses_and_exposes_level() {
    let text = r#"
h = 0.2
crease_angle = 60
level = 8

[mesh."Body"]
h = 0.15
edges = [
  { primitive = 0, a = 0, b = 1, h = 0.0 },
  { from = [0.0, 0.0, 0.0], to = [0.5, 1.0, 0.0], h = 0.05 },
]
"#;
    let sidecar = Sidecar::parse(Path::new(SIDECAR), text).unwrap();
    assert_eq!(sidecar.level(), Some(8));
}

#[test]
fn sidecar_path_sits_beside_the_asset() {
    assert_eq!(
        sidecar_path_for(Path::new("assets/robot.glb")),
        Path::new("assets/robot.g2tess.toml")
    );
}

#[test]
fn sidecar_syntax_error_names_its_line() {
    let message = sidecar_error("h = 0.2\ncrease_angle = = 3\n");
    assert!(message.starts_with("robot.g2tess.toml:2: "), "{message}");
}

#[test]
fn sidecar_unknown_top_level_key_is_named() {
    assert_eq!(
        sidecar_error("h = 0.1\ncrease_angel = 60\n"),
        "robot.g2tess.toml:2: unknown field `crease_angel`, expected one of `h`, `crease_angle`, `level`, `tolerance`, `relative_tolerance`, `triangle_budget`, `max_segments`, `mesh`"
    );
}

#[test]
fn sidecar_unknown_edge_key_is_named() {
    let message = sidecar_error("[mesh.0]\nedges = [\n  { a = 0, b = 1, hh = 0.1 },\n]\n");
    assert!(
        message.starts_with("robot.g2tess.toml:3: unknown field `hh`"),
        "{message}"
    );
}

#[test]
fn sidecar_h_out_of_range_names_line_and_key() {
    assert_eq!(
        sidecar_error("[mesh.\"Body\"]\nedges = [\n  { a = 0, b = 1, h = 0.0 },\n  { a = 1, b = 2, h = 1.7 },\n]\n"),
        "robot.g2tess.toml:4: edges[1].h: h must be in [0, 0.3536], got 1.7"
    );
    assert_eq!(
        sidecar_error("\nh = -0.1\n"),
        "robot.g2tess.toml:2: h: h must be in [0, 0.3536], got -0.1"
    );
}

#[test]
fn sidecar_h_at_the_maximum_is_accepted() {
    Sidecar::parse(Path::new(SIDECAR), "h = 0.35355339059327373\n").unwrap();
}

#[test]
fn sidecar_crease_angle_out_of_range() {
    assert_eq!(
        sidecar_error("[mesh.0]\ncrease_angle = 200\n"),
        "robot.g2tess.toml:2: crease_angle: crease_angle must be in [0, 180] degrees, got 200"
    );
}

#[test]
fn sidecar_level_has_the_range_of_the_flag() {
    assert_eq!(
        sidecar_error("level = 0\n"),
        "robot.g2tess.toml:1: level: level must be in [1, 64], got 0"
    );
    // Past the documented 64, and past what one output vertex can record (255).
    for level in [65_i64, 256, 1 << 40] {
        assert_eq!(
            sidecar_error(&format!("level = {level}\n")),
            format!("robot.g2tess.toml:1: level: level must be in [1, 64], got {level}")
        );
    }
    assert!(sidecar_error("level = 2.5\n").starts_with("robot.g2tess.toml:1: invalid type"));
}

#[test]
fn sidecar_wrong_type_names_line() {
    let message = sidecar_error("h = 0.1\n[mesh.0]\nh = \"0.2\"\n");
    assert!(
        message.starts_with("robot.g2tess.toml:3: invalid type: string \"0.2\""),
        "{message}"
    );
}

#[test]
fn sidecar_edge_needs_exactly_one_form() {
    assert_eq!(
        sidecar_error("[mesh.0]\nedges = [{ a = 0, b = 1, from = [0, 0, 0], to = [1, 0, 0], h = 0.1 }]\n"),
        "robot.g2tess.toml:2: edges[0]: an edge is named either by `a` and `b` or by `from` and `to`, not both"
    );
    assert_eq!(
        sidecar_error("[mesh.0]\nedges = [{ h = 0.1 }]\n"),
        "robot.g2tess.toml:2: edges[0]: an edge is named either by `a` and `b` or by `from` and `to`, found neither"
    );
    assert_eq!(
        sidecar_error("[mesh.0]\nedges = [{ a = 0, h = 0.1 }]\n"),
        "robot.g2tess.toml:2: edges[0]: missing key `b`"
    );
    assert_eq!(
        sidecar_error("[mesh.0]\nedges = [{ primitive = 0, from = [0, 0, 0], to = [1, 0, 0], h = 0.1 }]\n"),
        "robot.g2tess.toml:2: edges[0]: `primitive` only applies to `a` and `b`; `from` and `to` are matched over the whole mesh"
    );
}

#[test]
fn sidecar_negative_vertex_index_is_rejected() {
    assert_eq!(
        sidecar_error("[mesh.0]\nedges = [\n{ a = -1, b = 1, h = 0.1 }]\n"),
        "robot.g2tess.toml:3: edges[0].a: expected a non-negative integer, got -1"
    );
}

#[test]
fn explicit_sidecar_must_exist_but_the_one_beside_is_optional() {
    let dir = tempfile::tempdir().unwrap();
    let asset = dir.path().join("robot.glb");
    assert!(Sidecar::discover(&asset, None).unwrap().is_none());
    std::fs::write(dir.path().join("robot.g2tess.toml"), "level = 3\n").unwrap();
    let found = Sidecar::discover(&asset, None).unwrap().unwrap();
    assert_eq!(found.level(), Some(3));
    let missing = dir.path().join("other.toml");
    let message = Sidecar::discover(&asset, Some(&missing))
        .unwrap_err()
        .to_string();
    assert!(
        message.starts_with(&format!("{}: cannot read: ", missing.display())),
        "{message}"
    );
}

// --- extras ---

#[test]
fn extras_h_out_of_range_names_json_path() {
    let case = Case::new(hinge(0.0)).mesh_extras(json!({"g2tess": {"edges": [
        {"a": 0, "b": 1, "h": 0.1},
        {"from": [0, 0, 0], "to": [1, 0, 0], "h": 1.7},
    ]}}));
    assert_eq!(
        case.error(),
        "robot.glb: meshes[0].extras.g2tess.edges[1].h: h must be in [0, 0.3536], got 1.7"
    );
}

#[test]
fn extras_unknown_key_is_named() {
    let case = Case::new(hinge(0.0)).mesh_extras(json!({"g2tess": {"crease": 60}}));
    assert_eq!(
        case.error(),
        "robot.glb: meshes[0].extras.g2tess.crease: unknown key `crease`, expected one of `h`, `crease_angle`, `edges`"
    );
}

#[test]
fn extras_wrong_type_shows_what_was_written() {
    let case = Case::new(hinge(0.0)).prim_extras(0, json!({"g2tess": {"h": "0.2"}}));
    assert_eq!(
        case.error(),
        "robot.glb: meshes[0].primitives[0].extras.g2tess.h: expected a number, got the string \"0.2\""
    );
    let case = Case::new(hinge(0.0))
        .mesh_extras(json!({"g2tess": {"edges": [{"from": [0, 0], "to": [1, 0, 0], "h": 0}]}}));
    assert_eq!(
        case.error(),
        "robot.glb: meshes[0].extras.g2tess.edges[0].from: expected a position [x, y, z], got an array of 2 elements"
    );
}

#[test]
fn extras_primitive_is_implied_on_a_primitive() {
    let case = Case::new(hinge(0.0)).prim_extras(
        0,
        json!({"g2tess": {"edges": [{"primitive": 0, "a": 0, "b": 1, "h": 0}]}}),
    );
    assert_eq!(
        case.error(),
        "robot.glb: meshes[0].primitives[0].extras.g2tess.edges[0].primitive: `primitive` is implied in a primitive's extras, remove it"
    );
}

#[test]
fn extras_crease_angle_out_of_range() {
    let case = Case::new(hinge(0.0)).mesh_extras(json!({"g2tess": {"crease_angle": -5}}));
    assert_eq!(
        case.error(),
        "robot.glb: meshes[0].extras.g2tess.crease_angle: crease_angle must be in [0, 180] degrees, got -5"
    );
}

#[test]
fn extras_of_other_tools_are_left_alone() {
    Case::new(hinge(0.0))
        .mesh_extras(json!({"blender": {"h": 9}}))
        .prim_extras(0, json!("a string"))
        .run()
        .unwrap();
}

#[test]
fn options_out_of_range_are_reported_too() {
    let mut case = Case::new(hinge(0.0));
    case.defaults.h = 0.5;
    assert_eq!(case.error(), "options: h must be in [0, 0.3536], got 0.5");
}

#[test]
fn shipped_example_sidecar_parses() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("config/sidecar.example.toml");
    let sidecar = Sidecar::load(&path).unwrap();
    assert_eq!(sidecar.level(), Some(8));
}
