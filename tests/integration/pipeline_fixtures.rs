//! The whole pipeline on the real assets of `../shared/fixtures-real/valid/`: every one smooths
//! at level 4 into output the Khronos validator passes (where it passed the input), with
//! animations, skins, morph targets, materials, variants and extras still present and still
//! referring to the right things; closed meshes stay closed.

use crate::corpus;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use g2tess::gltf_io::{self, Document, ReadOptions};
use g2tess::options::{Options, Scheme};
use g2tess::pipeline::process_file;
use serde_json::Value;

/// Draco geometry is decoded and written uncompressed.
fn is_draco(p: &Path) -> bool {
    p.to_string_lossy().contains("Draco")
}

fn options(level: u32) -> Options {
    let mut o = Options::default();
    o.level = level;
    o
}

/// The JSON of a written asset (either container).
fn json_of(path: &Path) -> Value {
    let bytes = std::fs::read(path).unwrap();
    if bytes.starts_with(b"glTF") {
        let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        serde_json::from_slice(&bytes[20..20 + len]).unwrap()
    } else {
        serde_json::from_slice(&bytes).unwrap()
    }
}

fn count(v: &Value, key: &str) -> usize {
    v.get(key).and_then(Value::as_array).map_or(0, Vec::len)
}

/// What a replaced primitive must keep: its material, its variant mappings and other
/// extensions, its extras, and its number of morph targets.
fn primitive_identity(p: &Value) -> Value {
    serde_json::json!({
        "material": p.get("material"),
        "extensions": p.get("extensions"),
        "extras": p.get("extras"),
        "targets": p.get("targets").and_then(Value::as_array).map(Vec::len),
    })
}

#[test]
fn every_valid_asset_smooths_at_level_4_and_keeps_everything() {
    let Some(corpus) = corpus::fixtures_real() else {
        return;
    };
    let out_dir = corpus::temp_dir();
    let mut pairs: Vec<(PathBuf, PathBuf)> = Vec::new();
    for (n, input) in corpus::gltf_files(&corpus.join("valid")).iter().enumerate() {
        let name = input.strip_prefix(&corpus).unwrap().display().to_string();
        let output = out_dir.path().join(format!("{n:03}.glb"));
        let result = process_file(input, &output, &options(4));
        let report = result.unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(report.triangles_out, report.triangles_in * 16, "{name}");
        if is_draco(input) {
            // Decoded and written uncompressed: its primitives lose the extension, so the
            // comparison of what is kept below does not apply; the validator still does.
            pairs.push((input.clone(), output));
            continue;
        }

        let (before, after) = (json_of(input), json_of(&output));
        for key in [
            "scenes",
            "nodes",
            "meshes",
            "materials",
            "animations",
            "skins",
            "images",
            "textures",
            "samplers",
            "cameras",
        ] {
            assert_eq!(count(&before, key), count(&after, key), "{name}: {key}");
        }
        for key in ["nodes", "animations", "skins", "materials", "scenes"] {
            // Everything outside meshes and their accessors is unchanged but for accessor
            // indices (animations and skins refer to accessors that may be renumbered).
            let strip = |v: &Value| -> Value {
                let mut v = v.get(key).cloned().unwrap_or(Value::Null);
                strip_accessor_refs(&mut v);
                v
            };
            assert_eq!(strip(&before), strip(&after), "{name}: {key}");
        }
        for (m, mesh) in before["meshes"]
            .as_array()
            .into_iter()
            .flatten()
            .enumerate()
        {
            assert_eq!(
                mesh.get("extras"),
                after["meshes"][m].get("extras"),
                "{name}"
            );
            assert_eq!(
                mesh.get("weights"),
                after["meshes"][m].get("weights"),
                "{name}"
            );
            for (p, prim) in mesh["primitives"].as_array().unwrap().iter().enumerate() {
                assert_eq!(
                    primitive_identity(prim),
                    primitive_identity(&after["meshes"][m]["primitives"][p]),
                    "{name}: meshes[{m}].primitives[{p}]"
                );
            }
        }
        for key in ["extensionsUsed", "extensionsRequired", "asset", "extras"] {
            if key == "asset" {
                continue; // the generator may be stamped
            }
            let keep = |v: &Value| -> Vec<String> {
                let mut list: Vec<String> = v
                    .get(key)
                    .and_then(Value::as_array)
                    .into_iter()
                    .flatten()
                    .filter_map(|e| e.as_str().map(str::to_string))
                    .filter(|e| !e.contains("meshopt") && e != "KHR_mesh_quantization")
                    .collect();
                list.sort();
                list
            };
            assert_eq!(keep(&before), keep(&after), "{name}: {key}");
        }
        pairs.push((input.clone(), output));
    }
    assert!(pairs.len() >= 55, "only {} assets processed", pairs.len());

    let inputs: Vec<&Path> = pairs.iter().map(|(i, _)| i.as_path()).collect();
    let outputs: Vec<&Path> = pairs.iter().map(|(_, o)| o.as_path()).collect();
    let (Some(before), Some(after)) = (corpus::validate(&inputs), corpus::validate(&outputs))
    else {
        return;
    };
    let canonical = |p: &Path| std::fs::canonicalize(p).unwrap();
    let verdict = |map: &std::collections::BTreeMap<PathBuf, corpus::Verdict>, p: &Path| {
        map.iter()
            .find(|(k, _)| canonical(k) == canonical(p))
            .map(|(_, v)| v.clone())
            .unwrap_or_else(|| panic!("{} was not validated", p.display()))
    };
    for (input, output) in &pairs {
        let (b, a) = (verdict(&before, input), verdict(&after, output));
        if b.errors == 0 {
            assert_eq!(
                a.errors,
                0,
                "{}: validator errors {:?}",
                input.display(),
                a.codes
            );
        }
    }
}

#[test]
fn every_valid_asset_smooths_with_every_other_scheme() {
    let Some(corpus) = corpus::fixtures_real() else {
        return;
    };
    let out_dir = corpus::temp_dir();
    let mut pairs: Vec<(PathBuf, PathBuf)> = Vec::new();
    for scheme in [Scheme::Pn, Scheme::Hybrid, Scheme::Coons] {
        let mut opts = options(2);
        opts.scheme = scheme;
        for (n, input) in corpus::gltf_files(&corpus.join("valid")).iter().enumerate() {
            let output = out_dir.path().join(format!("{scheme}-{n:03}.glb"));
            let report = process_file(input, &output, &opts)
                .unwrap_or_else(|e| panic!("{scheme}: {}: {e}", input.display()));
            assert_eq!(report.triangles_out, report.triangles_in * 4);
            pairs.push((input.clone(), output));
        }
    }
    let inputs: Vec<&Path> = pairs.iter().map(|(i, _)| i.as_path()).collect();
    let outputs: Vec<&Path> = pairs.iter().map(|(_, o)| o.as_path()).collect();
    let (Some(before), Some(after)) = (corpus::validate(&inputs), corpus::validate(&outputs))
    else {
        return;
    };
    let by_name = |map: &std::collections::BTreeMap<PathBuf, corpus::Verdict>, p: &Path| {
        let p = std::fs::canonicalize(p).unwrap();
        map.iter()
            .find(|(k, _)| std::fs::canonicalize(k).unwrap() == p)
            .map(|(_, v)| v.clone())
            .unwrap()
    };
    for (input, output) in &pairs {
        if by_name(&before, input).errors == 0 {
            let v = by_name(&after, output);
            assert_eq!(v.errors, 0, "{}: {:?}", output.display(), v.codes);
        }
    }
}

/// Replaces every accessor reference inside nodes, animations and skins by null.
fn strip_accessor_refs(v: &mut Value) {
    match v {
        Value::Object(o) => {
            for (k, x) in o.iter_mut() {
                // Accessor indices: animation samplers, skins, and the per-instance
                // attributes of EXT_mesh_gpu_instancing on nodes.
                if matches!(
                    k.as_str(),
                    "input" | "output" | "inverseBindMatrices" | "attributes"
                ) {
                    *x = Value::Null;
                } else {
                    strip_accessor_refs(x);
                }
            }
        }
        Value::Array(a) => a.iter_mut().for_each(strip_accessor_refs),
        _ => {}
    }
}

/// Per mesh: the number of edges used by exactly one triangle, after welding every primitive's
/// vertices by exact position (-0.0 = +0.0). Zero-length edges are not counted.
fn boundary_edges_per_mesh(doc: &Document) -> Vec<usize> {
    let mut out = vec![0; doc.root.meshes.len()];
    let mut by_mesh: HashMap<usize, Vec<(usize, usize)>> = HashMap::new();
    for (m, p) in doc.triangle_primitives() {
        by_mesh.entry(m).or_default().push((m, p));
    }
    for (m, prims) in by_mesh {
        let mut ids: HashMap<[u32; 3], u32> = HashMap::new();
        let mut uses: HashMap<(u32, u32), usize> = HashMap::new();
        for (m, p) in prims {
            let data = doc.read_primitive(m, p).unwrap();
            let gltf_io::Values::Float(pos) = &data.attribute("POSITION").unwrap().values else {
                panic!("positions are floats");
            };
            let welded: Vec<u32> = pos
                .chunks_exact(3)
                .map(|c| {
                    let key = [c[0], c[1], c[2]].map(|x| if x == 0.0 { 0 } else { x.to_bits() });
                    let next = ids.len() as u32;
                    *ids.entry(key).or_insert(next)
                })
                .collect();
            for t in data.indices.chunks_exact(3) {
                for k in 0..3 {
                    let (a, b) = (welded[t[k] as usize], welded[t[(k + 1) % 3] as usize]);
                    if a != b {
                        *uses.entry((a.min(b), a.max(b))).or_default() += 1;
                    }
                }
            }
        }
        out[m] = uses.values().filter(|&&u| u == 1).count();
    }
    out
}

#[test]
fn closed_assets_stay_closed_and_open_ones_gain_no_boundary() {
    let Some(corpus) = corpus::fixtures_real() else {
        return;
    };
    let out_dir = corpus::temp_dir();
    let level = 3;
    for asset in [
        "Duck/Duck.glb",
        "Fox/Fox.glb",
        "Suzanne/monkey.glb",
        "ShapeCollection/ShapeCollection.glb",
        "Box/Box.glb",
        "BoxTextured/BoxTextured.gltf",
        "Teapot/teapot.gltf",
        "DamagedHelmet/DamagedHelmet.glb",
    ] {
        let input = corpus.join("valid").join(asset);
        if !input.exists() {
            let found = corpus::gltf_files(input.parent().unwrap());
            panic!("{asset} is missing; the folder has {found:?}");
        }
        let output = out_dir.path().join("out.glb");
        process_file(&input, &output, &options(level)).unwrap_or_else(|e| panic!("{e}"));
        let before =
            boundary_edges_per_mesh(&gltf_io::read(&input, &ReadOptions::default()).unwrap());
        let after =
            boundary_edges_per_mesh(&gltf_io::read(&output, &ReadOptions::default()).unwrap());
        let expected: Vec<usize> = before.iter().map(|b| b * level as usize).collect();
        assert_eq!(
            after, expected,
            "{asset}: boundary edges per mesh (input {before:?})"
        );
    }
}

/// At level 1 the G² and PN schemes tessellate on the flat surface (their nets would never be
/// read); a report's figures need the scheme's own surface. The output must be the same bytes
/// either way: with morph targets, skins, split normals, several primitives and primitives
/// without normals (generated at the crease angle).
#[test]
fn level_one_writes_the_same_bytes_with_and_without_the_schemes_surface() {
    let Some(corpus) = corpus::fixtures_real() else {
        return;
    };
    let assets = [
        "valid/AnimatedMorphCube/AnimatedMorphCube.gltf",
        "valid/MorphPrimitivesTest/MorphPrimitivesTest.gltf",
        "valid/MultiPrimCustomAttribute/23_multi_prim_vertex_attribute.gltf",
        "valid/Fox/Fox.glb",
        "valid/CustomNormals/10_custom_normals.gltf",
        "valid/Suzanne/monkey.glb",
        "valid/DegenerateTriangle/index_buffer_degenerate_triangle.gltf",
    ];
    let dir = corpus::temp_dir();
    for asset in assets {
        let input = corpus.join(asset);
        for scheme in [Scheme::G2, Scheme::Pn] {
            let mut written = Vec::new();
            for report_figures in [false, true] {
                let mut o = options(1);
                o.scheme = scheme;
                o.report_figures = report_figures;
                let output = dir.path().join(format!("out-{report_figures}.glb"));
                process_file(&input, &output, &o).unwrap();
                written.push(std::fs::read(&output).unwrap());
            }
            assert!(written[0] == written[1], "{asset}, scheme {scheme}");
        }
    }
}
