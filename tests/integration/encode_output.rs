//! Quantized (`--quantize`) and compressed (`--compress`) output, checked through our own reader
//! (which decodes meshopt compression) against the plain float output of the same input, within
//! the tolerances the bit depths imply; and through the Khronos validator, which cannot look
//! inside compressed views but checks everything around them.

use crate::corpus;

use std::path::{Path, PathBuf};

use g2tess::gltf_io::quantize::{
    DEFAULT_NORMAL_BITS, DEFAULT_POSITION_BITS, DEFAULT_TEXCOORD_BITS,
};
use g2tess::gltf_io::{self, Document, ReadOptions, Values};
use g2tess::options::Options;
use gltf_json::accessor::ComponentType;

/// The four encodings of one output.
#[derive(Debug, Clone, Copy)]
struct Encoding {
    quantize: bool,
    compress: bool,
}

const FLOAT: Encoding = Encoding {
    quantize: false,
    compress: false,
};
const QUANTIZED: Encoding = Encoding {
    quantize: true,
    compress: false,
};
const COMPRESSED: Encoding = Encoding {
    quantize: false,
    compress: true,
};
const BOTH: Encoding = Encoding {
    quantize: true,
    compress: true,
};

fn fixture(name: &str) -> Option<PathBuf> {
    let dir = corpus::fixtures_real()?.join("valid").join(name);
    corpus::gltf_files(&dir).into_iter().next()
}

/// Processes `input` at `level` with `e` into `dir`; returns the output's path.
fn process(input: &Path, dir: &Path, level: u32, e: Encoding, tag: &str) -> PathBuf {
    let mut options = Options::default();
    options.level = level;
    options.quantize = e.quantize;
    options.compress = e.compress;
    let stem = input.file_stem().unwrap().to_string_lossy();
    let out = dir.join(format!("{stem}.{tag}.glb"));
    g2tess::pipeline::process_file(input, &out, &options)
        .unwrap_or_else(|err| panic!("{}: {err}", input.display()));
    out
}

fn read(path: &Path) -> Document {
    gltf_io::read(path, &ReadOptions::default())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn floats<'a>(doc: &'a gltf_io::PrimitiveData, name: &str) -> Option<&'a [f32]> {
    match &doc.attribute(name)?.values {
        Values::Float(v) => Some(v),
        Values::Uint(_) => None,
    }
}

/// The accessor of attribute `name` of a primitive.
fn attribute_accessor(doc: &Document, mesh: usize, prim: usize, name: &str) -> usize {
    doc.root.meshes[mesh].primitives[prim]
        .attributes
        .iter()
        .find(|(k, _)| {
            serde_json::to_value(k)
                .ok()
                .and_then(|v| v.as_str().map(|s| s == name))
                .unwrap_or(false)
        })
        .map(|(_, v)| v.value())
        .expect("attribute present")
}

/// The stored component type of attribute `name` of a primitive.
fn component_type(doc: &Document, mesh: usize, prim: usize, name: &str) -> ComponentType {
    let a = attribute_accessor(doc, mesh, prim, name);
    doc.root.accessors[a].component_type.as_ref().unwrap().0
}

/// Positions of a primitive in its mesh's own space: integer positions through the
/// dequantizing node the writer puts above every quantized mesh; also the step size.
fn mesh_space_positions(doc: &Document, mesh: usize, prim: usize) -> (Vec<f64>, f64) {
    let data = doc.read_primitive(mesh, prim).unwrap();
    let p = floats(&data, "POSITION").unwrap();
    if component_type(doc, mesh, prim, "POSITION") == ComponentType::F32 {
        return (p.iter().map(|x| f64::from(*x)).collect(), 0.0);
    }
    let node = doc
        .root
        .nodes
        .iter()
        .find(|n| n.mesh.map(|m| m.value()) == Some(mesh))
        .expect("a node carries the quantized mesh");
    let t = node.translation.expect("dequantizing translation");
    let s = node.scale.expect("dequantizing scale");
    assert!(
        s[0] == s[1] && s[1] == s[2],
        "the dequantizing scale is uniform"
    );
    let out = p
        .chunks(3)
        .flat_map(|q| (0..3).map(move |k| f64::from(t[k]) + f64::from(s[k]) * f64::from(q[k])))
        .collect();
    (out, f64::from(s[0]))
}

/// Largest angle in degrees between corresponding unit vectors (the first three of `n`).
fn max_angle(a: &[f32], b: &[f32], n: usize) -> f64 {
    a.chunks(n)
        .zip(b.chunks(n))
        .map(|(x, y)| {
            let dot: f64 = (0..3).map(|k| f64::from(x[k]) * f64::from(y[k])).sum();
            let len = |v: &[f32]| (0..3).map(|k| f64::from(v[k]).powi(2)).sum::<f64>().sqrt();
            (dot / (len(x) * len(y)))
                .clamp(-1.0, 1.0)
                .acos()
                .to_degrees()
        })
        .fold(0.0, f64::max)
}

/// Worst angle of a unit vector stored as normalized `bits`-bit components: every component
/// off by half a step.
fn plain_angle_bound(bits: u32) -> f64 {
    let half_step = 0.5 / f64::from((1u32 << (bits - 1)) - 1);
    (3f64.sqrt() * half_step).asin().to_degrees()
}

/// Worst angle of the octahedral encoding at `bits` bits, decoded back to `bits`-bit
/// components. Rounding moves the octahedral coordinates (u, v) by at most h = half a step on
/// each; on the octahedron |x| + |y| + |z| = 1 that moves the point by at most √6·h (the
/// surface point is (u, v, 1 − |u| − |v|)), and normalizing stretches it by at most 1/|p| = √3
/// (at a face centre); the decoder then rounds to `bits` bits like a plain encoding.
fn octahedral_angle_bound(bits: u32) -> f64 {
    let half_step = 0.5 / f64::from((1u32 << (bits - 1)) - 1);
    (18f64.sqrt() * half_step).asin().to_degrees() + plain_angle_bound(bits)
}

/// Triangles as corner triples rotated to start at their smallest index, in order (the triangle
/// codec may rotate a triangle's corners but keeps the winding and the triangle order).
fn rotated(indices: &[u32]) -> Vec<[u32; 3]> {
    indices
        .chunks(3)
        .map(|t| {
            let m = (0..3).min_by_key(|k| t[*k]).unwrap();
            [t[m], t[(m + 1) % 3], t[(m + 2) % 3]]
        })
        .collect()
}

/// Compares every triangle primitive of `enc` (read back) with the float output `float`:
/// positions within half a quantization step, normals and tangents within the bound of their
/// encoding, UVs within half a 12-bit step, everything else equal.
fn assert_close(float: &Document, enc: &Document, e: Encoding, what: &str) {
    assert_eq!(
        float.triangle_primitives(),
        enc.triangle_primitives(),
        "{what}"
    );
    for (m, p) in float.triangle_primitives() {
        let at = format!("{what}: meshes[{m}].primitives[{p}]");
        let f = float.read_primitive(m, p).unwrap();
        let q = enc.read_primitive(m, p).unwrap();
        assert_eq!(rotated(&f.indices), rotated(&q.indices), "{at}: triangles");
        let (fp, _) = mesh_space_positions(float, m, p);
        let (qp, step) = mesh_space_positions(enc, m, p);
        let pos_tol = 0.5 * step * 1.001;
        for (k, (a, b)) in fp.iter().zip(&qp).enumerate() {
            let tol = pos_tol + 1e-6 * a.abs().max(1.0);
            assert!(
                (a - b).abs() <= tol,
                "{at}: position component {k}: {a} vs {b} (tolerance {tol})"
            );
        }
        for a in &f.attributes {
            let b = q
                .attribute(&a.name)
                .unwrap_or_else(|| panic!("{at}: {} missing", a.name));
            let (Values::Float(x), Values::Float(y)) = (&a.values, &b.values) else {
                assert_eq!(a.values, b.values, "{at}: {}", a.name);
                continue;
            };
            match a.name.as_str() {
                "POSITION" => {}
                "NORMAL" | "TANGENT" if e.quantize => {
                    let bound = if e.compress {
                        octahedral_angle_bound(DEFAULT_NORMAL_BITS)
                    } else {
                        plain_angle_bound(DEFAULT_NORMAL_BITS)
                    };
                    let angle = max_angle(x, y, a.components);
                    assert!(
                        angle <= bound,
                        "{at}: {} off by {angle}° (bound {bound}°)",
                        a.name
                    );
                    if a.name == "TANGENT" {
                        for (s, t) in x.chunks(4).zip(y.chunks(4)) {
                            assert_eq!(s[3].signum(), t[3].signum(), "{at}: tangent handedness");
                        }
                    }
                }
                n if n.starts_with("TEXCOORD_") && e.quantize => {
                    let steps = f64::from((1u32 << DEFAULT_TEXCOORD_BITS) - 1);
                    let tol = 0.5 / steps + 1.0 / 65535.0;
                    for (s, t) in x.iter().zip(y) {
                        let d = (f64::from(*s) - f64::from(*t)).abs();
                        assert!(d <= tol, "{at}: {n}: {s} vs {t}");
                    }
                }
                _ => assert_eq!(x, y, "{at}: {}", a.name),
            }
        }
    }
}

fn encodings_agree(name: &str) {
    let Some(input) = fixture(name) else { return };
    let dir = tempfile::tempdir().unwrap();
    let float = read(&process(&input, dir.path(), 2, FLOAT, "float"));
    for (e, tag) in [(COMPRESSED, "c"), (QUANTIZED, "q"), (BOTH, "qc")] {
        let enc = read(&process(&input, dir.path(), 2, e, tag));
        assert_close(&float, &enc, e, &format!("{name} {tag}"));
    }
}

#[test]
fn duck_decodes_within_quantization_tolerance() {
    encodings_agree("Duck");
}

#[test]
fn damaged_helmet_tangents_and_uvs_survive_quantization() {
    encodings_agree("DamagedHelmet");
}

#[test]
fn morph_target_deltas_share_the_position_grid() {
    encodings_agree("AnimatedMorphCube");
}

#[test]
fn shared_mesh_is_dequantized_under_every_node() {
    let Some(input) = fixture("SharedMesh") else {
        return;
    };
    encodings_agree("SharedMesh");
    let dir = tempfile::tempdir().unwrap();
    let float = read(&process(&input, dir.path(), 1, FLOAT, "float"));
    let enc = read(&process(&input, dir.path(), 1, QUANTIZED, "q"));
    let users = |d: &Document, m: usize| {
        d.root
            .nodes
            .iter()
            .filter(|n| n.mesh.map(|x| x.value()) == Some(m))
            .count()
    };
    for m in 0..float.root.meshes.len() {
        assert_eq!(
            users(&float, m),
            users(&enc, m),
            "mesh {m}: one dequantizing child per node"
        );
    }
}

#[test]
fn skinned_mesh_keeps_float_positions_and_quantizes_the_rest() {
    let Some(input) = fixture("Fox") else { return };
    encodings_agree("Fox");
    let dir = tempfile::tempdir().unwrap();
    let doc = read(&process(&input, dir.path(), 2, QUANTIZED, "q"));
    assert_eq!(component_type(&doc, 0, 0, "POSITION"), ComponentType::F32);
    assert_eq!(component_type(&doc, 0, 0, "NORMAL"), ComponentType::I8);
}

#[test]
fn quantized_positions_are_integers_with_integer_bounds() {
    let Some(input) = fixture("Duck") else { return };
    let dir = tempfile::tempdir().unwrap();
    let out = process(&input, dir.path(), 2, QUANTIZED, "q");
    let doc = read(&out);
    let json: serde_json::Value = serde_json::to_value(&doc.root).unwrap();
    for list in ["extensionsUsed", "extensionsRequired"] {
        let l = json[list].as_array().unwrap();
        assert!(
            l.iter().any(|e| e == "KHR_mesh_quantization"),
            "{list}: {l:?}"
        );
    }
    assert_eq!(component_type(&doc, 0, 0, "POSITION"), ComponentType::U16);
    let acc = &doc.root.accessors[attribute_accessor(&doc, 0, 0, "POSITION")];
    let top = f64::from((1u32 << DEFAULT_POSITION_BITS) - 1);
    for v in acc
        .min
        .iter()
        .chain(&acc.max)
        .flat_map(|m| m.as_array().unwrap())
    {
        let x = v.as_f64().unwrap();
        assert!(x.fract() == 0.0 && (0.0..=top).contains(&x), "bound {x}");
    }
    // The largest extent spans the whole grid.
    let max = acc.max.as_ref().unwrap().as_array().unwrap();
    assert!(max.iter().any(|x| x.as_f64() == Some(top)), "{max:?}");
}

#[test]
fn compressed_output_requires_the_extension_and_uses_vertex_codec_0() {
    let Some(input) = fixture("Duck") else { return };
    let dir = tempfile::tempdir().unwrap();
    let out = process(&input, dir.path(), 2, BOTH, "qc");
    let bytes = std::fs::read(&out).unwrap();
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let bin = &bytes[20 + json_len + 8..];
    for list in ["extensionsUsed", "extensionsRequired"] {
        let l = json[list].as_array().unwrap();
        assert!(
            l.iter().any(|e| e == "EXT_meshopt_compression"),
            "{list}: {l:?}"
        );
    }
    let fallback = &json["buffers"][1];
    assert_eq!(
        fallback["extensions"]["EXT_meshopt_compression"]["fallback"],
        true
    );
    assert!(fallback.get("uri").is_none());
    let mut modes = Vec::new();
    for v in json["bufferViews"].as_array().unwrap() {
        let Some(ext) = v.pointer("/extensions/EXT_meshopt_compression") else {
            continue;
        };
        assert_eq!(v["buffer"], 1);
        let (stride, count) = (
            ext["byteStride"].as_u64().unwrap(),
            ext["count"].as_u64().unwrap(),
        );
        assert_eq!(v["byteLength"].as_u64(), Some(stride * count));
        if let Some(s) = v.get("byteStride") {
            assert_eq!(s.as_u64(), Some(stride));
        }
        let start = ext["byteOffset"].as_u64().unwrap() as usize;
        let mode = ext["mode"].as_str().unwrap();
        if mode == "ATTRIBUTES" {
            assert_eq!(bin[start], 0xa0, "vertex codec version 0");
        }
        modes.push((
            mode.to_string(),
            ext["filter"].as_str().unwrap_or("NONE").to_string(),
        ));
    }
    assert!(
        modes.contains(&("TRIANGLES".into(), "NONE".into())),
        "{modes:?}"
    );
    assert!(
        modes.contains(&("ATTRIBUTES".into(), "OCTAHEDRAL".into())),
        "{modes:?}"
    );
}

#[test]
fn compress_fallback_writes_the_uncompressed_data_beside_the_output() {
    let Some(input) = fixture("BoxTextured") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let mut options = Options::default();
    options.level = 2;
    options.compress = true;
    options.compress_fallback = true;
    let out = dir.path().join("box.gltf");
    g2tess::pipeline::process_file(&input, &out, &options).unwrap();
    let fallback = gltf_io::fallback_path(&out);
    assert!(fallback.is_file());
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    assert_eq!(json["buffers"][1]["uri"], "box.fallback.bin");
    assert!(json.get("extensionsRequired").is_none_or(|l| !l
        .as_array()
        .unwrap()
        .iter()
        .any(|e| e == "EXT_meshopt_compression")));
    // A loader without the extension reads the fallback: the same data as the decoder's.
    let mut plain = json.clone();
    for v in plain["bufferViews"].as_array_mut().unwrap() {
        v.as_object_mut().unwrap().remove("extensions");
    }
    plain["buffers"][1]
        .as_object_mut()
        .unwrap()
        .remove("extensions");
    plain.as_object_mut().unwrap().remove("extensionsUsed");
    std::fs::write(
        dir.path().join("plain.gltf"),
        serde_json::to_vec(&plain).unwrap(),
    )
    .unwrap();
    let decoded = read(&out);
    let fell_back = read(&dir.path().join("plain.gltf"));
    for (m, p) in decoded.triangle_primitives() {
        assert_eq!(
            decoded.read_primitive(m, p).unwrap(),
            fell_back.read_primitive(m, p).unwrap()
        );
    }
}

#[test]
fn encoded_output_is_byte_identical_run_to_run() {
    let Some(input) = fixture("DamagedHelmet") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let a = process(&input, dir.path(), 2, BOTH, "a");
    let b = process(&input, dir.path(), 2, BOTH, "b");
    assert!(std::fs::read(a).unwrap() == std::fs::read(b).unwrap());
}

/// Every valid real fixture that processes, quantized (and quantized and compressed), passes the
/// validator with no errors where the input had none.
#[test]
fn quantized_fixtures_pass_the_validator() {
    let Some(root) = corpus::fixtures_real() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let inputs = corpus::gltf_files(&root.join("valid"));
    let mut outputs = Vec::new();
    for (i, input) in inputs.iter().enumerate() {
        let mut options = Options::default();
        options.level = 2;
        if g2tess::pipeline::process_file(input, &dir.path().join(format!("{i}.f.glb")), &options)
            .is_err()
        {
            continue; // not this test's concern (e.g. Draco input)
        }
        for (e, tag) in [(QUANTIZED, "q"), (BOTH, "qc")] {
            outputs.push((
                input.clone(),
                process(input, dir.path(), 2, e, &format!("{i}.{tag}")),
            ));
        }
    }
    let paths: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
    assert!(outputs.len() > 20, "only {} outputs", outputs.len());
    let Some(before) = corpus::validate(&paths) else {
        return;
    };
    let out_paths: Vec<&Path> = outputs.iter().map(|(_, o)| o.as_path()).collect();
    let Some(after) = corpus::validate(&out_paths) else {
        return;
    };
    let mut failures = Vec::new();
    for (input, output) in &outputs {
        if before[input].errors == 0 && after[output].errors > 0 {
            failures.push(format!("{}: {:?}", input.display(), after[output].codes));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
