//! Every real asset in `../shared/fixtures-real/valid/` read, run through the identity
//! tessellation and written back as .gltf and as .glb: nothing lost, geometry bit-exact, and the
//! Khronos validator clean on every output whose input it finds clean.

use crate::corpus;

use std::path::{Path, PathBuf};

use g2tess::gltf_io::{self, Document, ReadOptions, Values, WriteOptions};
use g2tess::options::Options;
use serde_json::Value;

/// The input's JSON as written in the file.
fn raw_json(path: &Path) -> Value {
    let bytes = std::fs::read(path).unwrap();
    let json = if bytes.starts_with(b"glTF") {
        let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        bytes[20..20 + len].to_vec()
    } else {
        bytes
    };
    serde_json::from_slice(&json).unwrap()
}

/// The JSON with what the writer legitimately rewrites taken out: accessors, views and
/// buffers; accessor and view indices; images' storage; primitives' geometry references;
/// the compression and quantization extensions it decodes.
fn comparable(mut v: Value) -> Value {
    let root = v.as_object_mut().unwrap();
    for key in ["accessors", "bufferViews", "buffers"] {
        root.remove(key);
    }
    for key in ["extensionsUsed", "extensionsRequired"] {
        if let Some(list) = root.get_mut(key).and_then(Value::as_array_mut) {
            list.retain(|e| {
                !matches!(
                    e.as_str(),
                    Some(
                        "EXT_meshopt_compression"
                            | "KHR_meshopt_compression"
                            | "KHR_mesh_quantization"
                            | "KHR_draco_mesh_compression"
                    )
                )
            });
            if list.is_empty() {
                root.remove(key);
            }
        }
    }
    let each = |root: &mut serde_json::Map<String, Value>,
                key: &str,
                f: &mut dyn FnMut(&mut serde_json::Map<String, Value>)| {
        for item in root
            .get_mut(key)
            .and_then(Value::as_array_mut)
            .into_iter()
            .flatten()
        {
            f(item.as_object_mut().unwrap());
        }
    };
    each(root, "images", &mut |i| {
        for k in ["uri", "bufferView", "mimeType"] {
            i.remove(k);
        }
    });
    each(root, "skins", &mut |s| {
        s.remove("inverseBindMatrices");
    });
    each(root, "animations", &mut |a| {
        for s in a
            .get_mut("samplers")
            .and_then(Value::as_array_mut)
            .into_iter()
            .flatten()
        {
            s["input"] = Value::Null;
            s["output"] = Value::Null;
        }
    });
    each(root, "nodes", &mut |n| {
        if let Some(a) = n
            .get_mut("extensions")
            .and_then(|e| e.get_mut("EXT_mesh_gpu_instancing"))
        {
            a["attributes"] = Value::Null;
        }
    });
    each(root, "meshes", &mut |m| {
        for p in m
            .get_mut("primitives")
            .and_then(Value::as_array_mut)
            .into_iter()
            .flatten()
        {
            let p = p.as_object_mut().unwrap();
            let names: Vec<String> = p
                .get("attributes")
                .and_then(Value::as_object)
                .map(|o| o.keys().cloned().collect())
                .unwrap_or_default();
            // NORMAL and TANGENT may be added (generated where the input had none); that
            // every input attribute survives is checked by `assert_same_geometry`.
            let names: Vec<String> = names
                .into_iter()
                .filter(|n| n != "NORMAL" && n != "TANGENT")
                .collect();
            p.insert("attributes".into(), names.into());
            let targets = p
                .get("targets")
                .and_then(Value::as_array)
                .map_or(0, Vec::len);
            p.insert("targets".into(), targets.into());
            p.remove("indices");
            // Draco primitives are decoded and written uncompressed.
            if let Some(ext) = p.get_mut("extensions").and_then(Value::as_object_mut) {
                ext.remove("KHR_draco_mesh_compression");
                if ext.is_empty() {
                    p.remove("extensions");
                }
            }
            let mode = p.remove("mode").and_then(|m| m.as_u64()).unwrap_or(4);
            p.insert(
                "mode".into(),
                (if (4..=6).contains(&mode) { 4 } else { mode }).into(),
            );
        }
    });
    v
}

/// The JSON path and values of the first difference between `a` and `b`.
fn first_difference(a: &Value, b: &Value, path: String) -> Option<String> {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            for k in x.keys().chain(y.keys()) {
                let (u, v) = (
                    x.get(k).unwrap_or(&Value::Null),
                    y.get(k).unwrap_or(&Value::Null),
                );
                if let Some(d) = first_difference(u, v, format!("{path}.{k}")) {
                    return Some(d);
                }
            }
            None
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => x
            .iter()
            .zip(y)
            .enumerate()
            .find_map(|(i, (u, v))| first_difference(u, v, format!("{path}[{i}]"))),
        _ if a == b => None,
        _ => Some(format!("{path}: {a} became {b}")),
    }
}

/// Every `extras` value with its JSON path.
fn extras(v: &Value, path: String, out: &mut Vec<(String, Value)>) {
    match v {
        Value::Object(o) => {
            for (k, x) in o {
                if k == "extras" {
                    out.push((path.clone(), x.clone()));
                }
                extras(x, format!("{path}.{k}"), out);
            }
        }
        Value::Array(a) => a
            .iter()
            .enumerate()
            .for_each(|(i, x)| extras(x, format!("{path}[{i}]"), out)),
        _ => {}
    }
}

fn floats(doc: &Document, m: usize, p: usize, name: &str) -> Option<Vec<f32>> {
    let data = doc.read_primitive(m, p).unwrap();
    match &data.attribute(name)?.values {
        Values::Float(v) => Some(v.clone()),
        Values::Uint(v) => Some(v.iter().map(|&x| x as f32).collect()),
    }
}

/// The primitive's triangles as sorted corner positions (bits), each rotated to start at its
/// smallest corner so the winding is kept.
fn position_triangles(doc: &Document, m: usize, p: usize) -> Vec<[[u32; 3]; 3]> {
    let data = doc.read_primitive(m, p).unwrap();
    let pos = floats(doc, m, p, "POSITION").unwrap();
    let mut tris: Vec<[[u32; 3]; 3]> = data
        .indices
        .chunks_exact(3)
        .map(|t| {
            let c = [t[0], t[1], t[2]].map(|i| {
                let i = i as usize * 3;
                [pos[i].to_bits(), pos[i + 1].to_bits(), pos[i + 2].to_bits()]
            });
            let r = (0..3).min_by_key(|&k| c[k]).unwrap();
            [c[r], c[(r + 1) % 3], c[(r + 2) % 3]]
        })
        .collect();
    tris.sort();
    tris
}

/// Output vertex k of the identity tessellation (without GPU reordering) is the k-th distinct
/// input vertex in order of first reference by the triangles.
fn first_reference_order(indices: &[u32]) -> Vec<usize> {
    let mut seen = std::collections::HashSet::new();
    indices
        .iter()
        .filter(|&&i| seen.insert(i))
        .map(|&i| i as usize)
        .collect()
}

/// Identity: the same triangles over the same positions and normals, bit for bit (a normal
/// further from unit length than the validator allows comes out normalized), and every other attribute carried unchanged.
fn assert_same_geometry(input: &Document, output: &Document, name: &str) {
    assert_eq!(
        input.triangle_primitives(),
        output.triangle_primitives(),
        "{name}: triangle primitives"
    );
    for (m, p) in input.triangle_primitives() {
        let at = format!("{name}: meshes[{m}].primitives[{p}]");
        let a = input.read_primitive(m, p).unwrap();
        let b = output.read_primitive(m, p).unwrap();
        if a.attribute("NORMAL").is_none() {
            // Generated normals split vertices at creases: only the triangles over the same
            // positions can be compared.
            assert!(b.attribute("NORMAL").is_some(), "{at}: normals generated");
            assert_eq!(
                position_triangles(input, m, p),
                position_triangles(output, m, p),
                "{at}: triangles"
            );
            continue;
        }
        let order = first_reference_order(&a.indices);
        let renumber: std::collections::HashMap<u32, u32> = order
            .iter()
            .enumerate()
            .map(|(k, &v)| (v as u32, k as u32))
            .collect();
        let expected: Vec<u32> = a.indices.iter().map(|i| renumber[i]).collect();
        assert_eq!(b.indices, expected, "{at}: triangles");
        for attr in &a.attributes {
            if attr.name == "TANGENT" {
                continue; // regenerated with MikkTSpace
            }
            let (x, y) = (
                floats(input, m, p, &attr.name).unwrap(),
                floats(output, m, p, &attr.name),
            );
            let y = y.unwrap_or_else(|| panic!("{at}: {} lost", attr.name));
            let c = attr.components;
            for (k, &v) in order.iter().enumerate() {
                let (want, got) = (&x[v * c..v * c + c], &y[k * c..k * c + c]);
                if attr.name == "NORMAL" {
                    // Kept bit for bit when unit to the validator's tolerance (the Teapot's
                    // are within 5e-5 of it), normalized beyond it.
                    let len = want
                        .iter()
                        .map(|&w| f64::from(w).powi(2))
                        .sum::<f64>()
                        .sqrt();
                    if (len - 1.0).abs() > 0.00769 {
                        let len = len as f32;
                        let normalized: Vec<f32> = want.iter().map(|w| w / len).collect();
                        let close = normalized
                            .iter()
                            .zip(got)
                            .all(|(w, g)| (w - g).abs() < 1e-6);
                        assert!(close, "{at}: NORMAL of vertex {v}: {want:?} -> {got:?}");
                        continue;
                    }
                }
                if attr.name.starts_with("WEIGHTS_") {
                    // Weights are renormalized to sum 1.
                    let close = want.iter().zip(got).all(|(w, g)| (w - g).abs() < 1e-5);
                    assert!(
                        close,
                        "{at}: {} of vertex {v}: {want:?} -> {got:?}",
                        attr.name
                    );
                    continue;
                }
                let same = want
                    .iter()
                    .zip(got)
                    .all(|(w, g)| w.to_bits() == g.to_bits());
                assert!(
                    same,
                    "{at}: {} of vertex {v}: {want:?} -> {got:?}",
                    attr.name
                );
            }
        }
        assert_eq!(a.targets.len(), b.targets.len(), "{at}: morph targets");
    }
}

#[test]
fn every_valid_asset_round_trips_without_loss() {
    let Some(corpus) = corpus::fixtures_real() else {
        return;
    };
    let out_dir = corpus::temp_dir();
    // The identity tessellation: this test is about what the I/O layer keeps.
    let mut opts = Options::default();
    opts.level = 1;
    opts.h = 0.0;
    let mut inputs_written: Vec<(PathBuf, Vec<PathBuf>)> = Vec::new();
    for (n, input) in corpus::gltf_files(&corpus.join("valid")).iter().enumerate() {
        let name = input.strip_prefix(&corpus).unwrap().display().to_string();
        let doc = gltf_io::read(input, &ReadOptions::default());
        let doc = doc.unwrap_or_else(|e| panic!("{name}: {e}"));
        let mut processed = doc.clone();
        g2tess::pipeline::process_document(&mut processed, input, &opts)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let mut outputs = Vec::new();
        for ext in ["gltf", "glb"] {
            // One folder per output, so .bin names never collide.
            let dir = out_dir.path().join(format!("{n:03}-{ext}"));
            std::fs::create_dir(&dir).unwrap();
            let out = dir.join(format!(
                "{}.{ext}",
                input.file_stem().unwrap().to_string_lossy()
            ));
            gltf_io::write(&processed, &out, &WriteOptions::default())
                .unwrap_or_else(|e| panic!("{name} -> {ext}: {e}"));
            let back = gltf_io::read(&out, &ReadOptions::default())
                .unwrap_or_else(|e| panic!("{name} -> {ext} read back: {e}"));
            assert_same_geometry(&doc, &back, &name);

            let (before, after) = (raw_json(input), raw_json(&out));
            let (mut eb, mut ea) = (Vec::new(), Vec::new());
            extras(&comparable(before.clone()), String::new(), &mut eb);
            extras(&comparable(after.clone()), String::new(), &mut ea);
            assert_eq!(eb, ea, "{name} -> {ext}: extras");
            for key in [
                "nodes",
                "meshes",
                "materials",
                "animations",
                "skins",
                "images",
                "textures",
                "cameras",
            ] {
                let count = |v: &Value| v.get(key).and_then(Value::as_array).map_or(0, Vec::len);
                assert_eq!(
                    count(&before),
                    count(&after),
                    "{name} -> {ext}: number of {key}"
                );
            }
            let diff = first_difference(&comparable(before), &comparable(after), String::new());
            assert_eq!(
                diff, None,
                "{name} -> {ext}: JSON outside the rewritten geometry"
            );
            outputs.push(out);
        }
        inputs_written.push((input.clone(), outputs));
    }
    assert!(
        inputs_written.len() >= 50,
        "only {} assets round-tripped",
        inputs_written.len()
    );

    let inputs: Vec<&Path> = inputs_written.iter().map(|(i, _)| i.as_path()).collect();
    let Some(before) = corpus::validate(&inputs) else {
        return;
    };
    let Some(after) = corpus::validate(&[out_dir.path()]) else {
        return;
    };
    let mut clean = 0;
    for (input, outputs) in &inputs_written {
        let verdict_in = &before[input];
        for out in outputs {
            let verdict_out = &after[out];
            if verdict_in.errors == 0 {
                assert_eq!(
                    verdict_out.errors,
                    0,
                    "{} -> {}: validator errors {:?}",
                    input.display(),
                    out.display(),
                    verdict_out.codes
                );
            }
            clean += usize::from(verdict_out.errors == 0);
        }
    }
    eprintln!(
        "{clean} of {} outputs validate without errors",
        inputs_written.len() * 2
    );
}

/// Every triangle of every triangle primitive as its three corner positions.
fn triangles(doc: &Document) -> Vec<Vec<[[f32; 3]; 3]>> {
    doc.triangle_primitives()
        .into_iter()
        .map(|(mesh, prim)| {
            let data = doc.read_primitive(mesh, prim).unwrap();
            let Values::Float(p) = &data.attribute("POSITION").unwrap().values else {
                panic!("float positions")
            };
            let at = |v: u32| {
                let v = v as usize * 3;
                [p[v], p[v + 1], p[v + 2]]
            };
            data.indices
                .chunks_exact(3)
                .map(|t| [at(t[0]), at(t[1]), at(t[2])])
                .collect()
        })
        .collect()
}

/// A Draco asset decodes to the geometry of its uncompressed twin: per primitive, the same
/// number of triangles, and each decoded triangle has a twin triangle whose corners (in any
/// rotation, with any vertex numbering) lie within one quantization step. The step is the
/// primitive's extent over 2^11 (the coarsest position quantization glTF Draco encoders use by
/// default is 11 bits, whose error is half a step); a misread stream is off by far more.
#[test]
fn draco_primitives_decode_to_their_uncompressed_twin() {
    let Some(corpus) = corpus::fixtures_real() else {
        return;
    };
    let pairs = [
        ("BoxDraco/BoxDraco.gltf", "Box/Box.gltf"),
        (
            "2CylinderEngineDraco/2CylinderEngine.gltf",
            "2CylinderEngine/2CylinderEngine.glb",
        ),
    ];
    for (draco, plain) in pairs {
        let read = |p: &str| {
            gltf_io::read(&corpus.join("valid").join(p), &ReadOptions::default()).unwrap()
        };
        let (decoded, twin) = (triangles(&read(draco)), triangles(&read(plain)));
        assert_eq!(decoded.len(), twin.len(), "{draco}: primitives");
        for (k, (a, b)) in decoded.iter().zip(&twin).enumerate() {
            let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
            for p in b.iter().flatten() {
                for c in 0..3 {
                    lo[c] = lo[c].min(p[c]);
                    hi[c] = hi[c].max(p[c]);
                }
            }
            let extent = (0..3).map(|c| hi[c] - lo[c]).fold(0.0, f32::max);
            let tol = extent / 2048.0;
            // Twins are found through a grid of centroids with cells of 4 steps.
            let cell = |t: &[[f32; 3]; 3]| {
                let c =
                    |i: usize| ((t[0][i] + t[1][i] + t[2][i]) / (3.0 * 4.0 * tol)).floor() as i64;
                [c(0), c(1), c(2)]
            };
            let mut grid: std::collections::HashMap<[i64; 3], Vec<usize>> = Default::default();
            for (i, t) in b.iter().enumerate() {
                grid.entry(cell(t)).or_default().push(i);
            }
            let near = |p: &[f32; 3], q: &[f32; 3]| (0..3).all(|c| (p[c] - q[c]).abs() <= tol);
            let same = |t: &[[f32; 3]; 3], u: &[[f32; 3]; 3]| {
                (0..3).any(|r| (0..3).all(|i| near(&t[i], &u[(i + r) % 3])))
            };
            for t in a {
                let [x, y, z] = cell(t);
                let found = (-1..=1).any(|dx| {
                    (-1..=1).any(|dy| {
                        (-1..=1).any(|dz| {
                            grid.get(&[x + dx, y + dy, z + dz])
                                .is_some_and(|list| list.iter().any(|&i| same(t, &b[i])))
                        })
                    })
                });
                assert!(
                    found,
                    "{draco}: primitive {k}: no twin for {t:?} within {tol}"
                );
            }
        }
    }
}

/// A damaged Draco stream is refused with an error naming the primitive's extension, never a
/// panic, whatever the damage: 300 seeded variants of BoxDraco's stream with 1 to 3 bytes
/// replaced or the stream cut short.
#[test]
fn damaged_draco_streams_are_errors_naming_the_primitive() {
    let Some(corpus) = corpus::fixtures_real() else {
        return;
    };
    let dir = corpus.join("valid/BoxDraco");
    let json = std::fs::read(dir.join("BoxDraco.gltf")).unwrap();
    let stream = std::fs::read(dir.join("0.bin")).unwrap();
    let tmp = corpus::temp_dir();
    std::fs::write(tmp.path().join("BoxDraco.gltf"), &json).unwrap();
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = |n: usize| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed % n as u64) as usize
    };
    let (mut refused, mut gave_up) = (0, 0);
    for round in 0..300 {
        let mut bytes = stream.clone();
        for _ in 0..1 + next(3) {
            let at = next(bytes.len());
            bytes[at] = next(256) as u8;
        }
        if round % 10 == 0 {
            let cut = next(bytes.len());
            bytes[cut..].fill(0);
        }
        std::fs::write(tmp.path().join("0.bin"), &bytes).unwrap();
        let doc =
            gltf_io::read(&tmp.path().join("BoxDraco.gltf"), &ReadOptions::default()).unwrap();
        let read = std::panic::catch_unwind(|| doc.read_primitive(0, 0));
        match read.unwrap_or_else(|_| panic!("round {round}: the reader panicked")) {
            Ok(_) => {}
            Err(e) => {
                let e = e.to_string();
                assert!(
                    e.starts_with("meshes[0].primitives[0].extensions.KHR_draco_mesh_compression"),
                    "round {round}: {e}"
                );
                refused += 1;
                gave_up += usize::from(e.contains("the decoder gave up on it"));
            }
        }
    }
    // Most damage is detected (a byte inside a value can decode to another valid value), and
    // some of it makes the decoder itself fail (a panic inside it, caught and reported).
    assert!(refused > 100, "only {refused} of 300 refused");
    assert!(
        gave_up > 0,
        "no damage reached a decoder failure: {refused} refused"
    );
}
