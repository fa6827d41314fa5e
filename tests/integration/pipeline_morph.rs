//! Morph targets on the smooth surface: each target is the surface of the displaced mesh, so at
//! the input's own vertices the output's deltas are the input's deltas; targets that leave most
//! of the dense mesh in place are stored sparse.

use crate::corpus;

use std::collections::HashMap;

use g2tess::gltf_io::{self, ReadOptions, Values};
use g2tess::options::Options;
use g2tess::pipeline::process_file;

fn floats(v: &Values) -> &[f32] {
    match v {
        Values::Float(f) => f,
        Values::Uint(_) => panic!("float data expected"),
    }
}

#[test]
fn target_deltas_match_the_input_at_its_vertices_and_are_stored_sparse() {
    let Some(corpus) = corpus::fixtures_real() else {
        return;
    };
    let input = corpus.join("valid/AnimatedMorphCube/AnimatedMorphCube.gltf");
    let dir = corpus::temp_dir();
    let output = dir.path().join("out.glb");
    let mut options = Options::default();
    options.level = 4;
    process_file(&input, &output, &options).unwrap();

    let before = gltf_io::read(&input, &ReadOptions::default()).unwrap();
    let after = gltf_io::read(&output, &ReadOptions::default()).unwrap();
    let a = before.read_primitive(0, 0).unwrap();
    let b = after.read_primitive(0, 0).unwrap();
    assert_eq!(a.targets.len(), b.targets.len());

    // Input deltas by input position (all split copies of a corner move alike here).
    let pos_a = floats(&a.attribute("POSITION").unwrap().values);
    let pos_b = floats(&b.attribute("POSITION").unwrap().values);
    for (t, (ta, tb)) in a.targets.iter().zip(&b.targets).enumerate() {
        let da = floats(&ta.iter().find(|x| x.name == "POSITION").unwrap().values);
        let db = floats(&tb.iter().find(|x| x.name == "POSITION").unwrap().values);
        let mut by_position: HashMap<[u32; 3], [f32; 3]> = HashMap::new();
        for (p, d) in pos_a.chunks_exact(3).zip(da.chunks_exact(3)) {
            by_position.insert([p[0], p[1], p[2]].map(f32::to_bits), [d[0], d[1], d[2]]);
        }
        let mut corners = 0;
        for (p, d) in pos_b.chunks_exact(3).zip(db.chunks_exact(3)) {
            if let Some(want) = by_position.get(&[p[0], p[1], p[2]].map(f32::to_bits)) {
                corners += 1;
                for k in 0..3 {
                    // (p + d) − p in f32: exact to one rounding of the displaced position.
                    let tol = 2.0 * f32::EPSILON * (p[k].abs() + want[k].abs()).max(1.0);
                    assert!(
                        (d[k] - want[k]).abs() <= tol,
                        "target {t}: {:?} vs {want:?}",
                        d
                    );
                }
            }
        }
        assert!(
            corners >= 8,
            "target {t}: only {corners} corner vertices found"
        );
    }

    // Stored sparse where that is smaller: every target accessor of this cube moves only part
    // of the dense mesh.
    let json: serde_json::Value = {
        let bytes = std::fs::read(&output).unwrap();
        let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        serde_json::from_slice(&bytes[20..20 + len]).unwrap()
    };
    let targets = json["meshes"][0]["primitives"][0]["targets"]
        .as_array()
        .unwrap();
    let mut sparse = 0;
    for target in targets {
        for index in target.as_object().unwrap().values() {
            let accessor = &json["accessors"][index.as_u64().unwrap() as usize];
            if accessor.get("sparse").is_some() || accessor.get("bufferView").is_none() {
                sparse += 1;
            }
        }
    }
    assert!(sparse > 0, "no target stored sparse: {targets:?}");
}
