//! Builds small glTF assets from plain arrays, for tests that need a mesh with chosen
//! normals, seams and `extras` (the real corpus cannot be edited).
#![allow(dead_code)]

use base64::Engine as _;
use serde_json::{json, Value};

/// One triangle primitive's data.
#[derive(Debug, Clone, Default)]
pub struct Prim {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub uvs: Option<Vec<[f32; 2]>>,
    pub indices: Vec<u32>,
    pub extras: Option<Value>,
}

/// A one-mesh, one-node asset as `.gltf` text with an embedded buffer.
pub fn gltf(mesh_name: &str, mesh_extras: Option<Value>, prims: &[Prim]) -> String {
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut push = |bytes: Vec<u8>, accessor: Value, views: &mut Vec<Value>| -> usize {
        while bin.len() % 4 != 0 {
            bin.push(0);
        }
        views.push(json!({ "buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len() }));
        bin.extend(bytes);
        let mut a = accessor;
        a["bufferView"] = json!(views.len() - 1);
        accessors.push(a);
        accessors.len() - 1
    };
    let mut primitives = Vec::new();
    for p in prims {
        let (lo, hi) = bounds(&p.positions);
        let pos = push(
            p.positions
                .iter()
                .flatten()
                .flat_map(|x| x.to_le_bytes())
                .collect(),
            json!({ "componentType": 5126, "count": p.positions.len(), "type": "VEC3", "min": lo, "max": hi }),
            &mut views,
        );
        let mut attributes = json!({ "POSITION": pos });
        if !p.normals.is_empty() {
            attributes["NORMAL"] = json!(push(
                p.normals
                    .iter()
                    .flatten()
                    .flat_map(|x| x.to_le_bytes())
                    .collect(),
                json!({ "componentType": 5126, "count": p.normals.len(), "type": "VEC3" }),
                &mut views,
            ));
        }
        if let Some(uv) = &p.uvs {
            attributes["TEXCOORD_0"] = json!(push(
                uv.iter().flatten().flat_map(|x| x.to_le_bytes()).collect(),
                json!({ "componentType": 5126, "count": uv.len(), "type": "VEC2" }),
                &mut views,
            ));
        }
        let indices = push(
            p.indices.iter().flat_map(|i| i.to_le_bytes()).collect(),
            json!({ "componentType": 5125, "count": p.indices.len(), "type": "SCALAR" }),
            &mut views,
        );
        let mut prim = json!({ "attributes": attributes, "indices": indices });
        if let Some(e) = &p.extras {
            prim["extras"] = e.clone();
        }
        primitives.push(prim);
    }
    let mut mesh = json!({ "name": mesh_name, "primitives": primitives });
    if let Some(e) = mesh_extras {
        mesh["extras"] = e;
    }
    let data = base64::engine::general_purpose::STANDARD.encode(&bin);
    serde_json::to_string_pretty(&json!({
        "asset": { "version": "2.0" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0 }],
        "meshes": [mesh],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{ "byteLength": bin.len(), "uri": format!("data:application/octet-stream;base64,{data}") }],
    }))
    .unwrap()
}

fn bounds(p: &[[f32; 3]]) -> (Vec<f32>, Vec<f32>) {
    let mut lo = vec![f32::INFINITY; 3];
    let mut hi = vec![f32::NEG_INFINITY; 3];
    for v in p {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    (lo, hi)
}

/// A closed unit-ish octahedron with normals pointing out from the centre (smooth shading):
/// 6 vertices, 8 triangles, every edge with a 109.47° dihedral angle... too sharp for the
/// default crease angle, so tests set `crease_angle` as they need.
pub fn octahedron() -> Prim {
    let positions = vec![
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    let indices = vec![
        0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5,
    ];
    Prim {
        normals: positions.clone(),
        positions,
        uvs: None,
        indices,
        extras: None,
    }
}
