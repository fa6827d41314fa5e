//! The project's own small assets in `fixtures/`, generated here so that they are reviewable as
//! code. `G2TESS_UPDATE_FIXTURES=1 cargo test --test io_fixtures` rewrites them; otherwise the
//! test checks that the committed files are what this code produces.

use std::path::Path;

use base64::Engine as _;
use g2tess::gltf_io::{self, ReadOptions, WriteOptions};

/// A unit icosahedron: 12 vertices, 20 triangles, normals pointing out from the centre, so
/// that a smooth surface through it approximates a sphere.
fn icosahedron() -> (Vec<[f32; 3]>, Vec<u16>) {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let raw = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let len = (1.0 + t * t).sqrt();
    let positions = raw
        .iter()
        .map(|p: &[f32; 3]| [p[0] / len, p[1] / len, p[2] / len])
        .collect();
    let indices = vec![
        0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4, 11, 10, 2, 10, 7, 6, 7,
        1, 8, 3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9,
        8, 1,
    ];
    (positions, indices)
}

fn icosahedron_gltf() -> String {
    let (positions, indices) = icosahedron();
    let mut bin: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
    let pos_offset = bin.len();
    bin.extend(positions.iter().flatten().flat_map(|x| x.to_le_bytes()));
    let normal_offset = bin.len();
    bin.extend(positions.iter().flatten().flat_map(|x| x.to_le_bytes()));
    let (lo, hi) = (-0.8506508f32, 0.8506508f32);
    let data = base64::engine::general_purpose::STANDARD.encode(&bin);
    format!(
        r#"{{
  "asset": {{ "version": "2.0", "generator": "g2tess tests/io_fixtures.rs" }},
  "scene": 0,
  "scenes": [{{ "nodes": [0] }}],
  "nodes": [{{ "mesh": 0, "name": "Icosahedron" }}],
  "materials": [{{ "name": "Clay", "pbrMetallicRoughness": {{ "baseColorFactor": [0.8, 0.5, 0.3, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.6 }} }}],
  "meshes": [{{ "name": "Icosahedron", "primitives": [{{ "attributes": {{ "POSITION": 1, "NORMAL": 2 }}, "indices": 0, "material": 0 }}] }}],
  "accessors": [
    {{ "bufferView": 0, "componentType": 5123, "count": {ni}, "type": "SCALAR" }},
    {{ "bufferView": 1, "componentType": 5126, "count": 12, "type": "VEC3", "min": [{lo}, {lo}, {lo}], "max": [{hi}, {hi}, {hi}] }},
    {{ "bufferView": 2, "componentType": 5126, "count": 12, "type": "VEC3" }}
  ],
  "bufferViews": [
    {{ "buffer": 0, "byteOffset": 0, "byteLength": {pos_offset} }},
    {{ "buffer": 0, "byteOffset": {pos_offset}, "byteLength": 144 }},
    {{ "buffer": 0, "byteOffset": {normal_offset}, "byteLength": 144 }}
  ],
  "buffers": [{{ "byteLength": {len}, "uri": "data:application/octet-stream;base64,{data}" }}]
}}"#,
        ni = indices.len(),
        len = bin.len(),
    )
}

#[test]
fn bundled_icosahedron_is_up_to_date() {
    let doc =
        gltf_io::read_bytes(icosahedron_gltf().as_bytes(), None, &ReadOptions::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let fresh = dir.path().join("icosahedron.glb");
    gltf_io::write(&doc, &fresh, &WriteOptions::default()).unwrap();
    let committed = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/icosahedron.glb");
    if std::env::var("G2TESS_UPDATE_FIXTURES").as_deref() == Ok("1") {
        std::fs::copy(&fresh, &committed).unwrap();
    }
    assert_eq!(
        std::fs::read(&fresh).unwrap(),
        std::fs::read(&committed).unwrap_or_default(),
        "fixtures/icosahedron.glb is stale: rerun with G2TESS_UPDATE_FIXTURES=1"
    );
}
