//! Bad input never panics, never dies of a signal and never exceeds a memory limit: the real
//! binary is run on mutated versions of the real assets (truncated at many points, bytes
//! flipped, counts and offsets changed, JSON fields deleted or given wrong types) and must answer
//! each with exit status 0 or 1 and a message. What it writes holds only finite numbers.
//!
//! `G2TESS_MUTATIONS=N` sets the cases per asset (default 24, which CI runs in well under two
//! minutes on two cores); failures name the asset, the case and the mutation.

use crate::corpus;
use crate::hostile;

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::hostile::Lcg;
use g2tess::gltf_io::glb;
use serde_json::{json, Value};

/// Assets up to this size (with their companion files) are mutated; the larger ones only cost
/// time, since every mutation kind reaches the same code on small files.
const MAX_ASSET_BYTES: u64 = 300_000;

/// One mutated asset, ready to write.
struct Case {
    label: String,
    bytes: Vec<u8>,
}

#[test]
fn mutated_assets_end_in_a_message_within_the_memory_limit() {
    let Some(corpus) = corpus::fixtures_real() else {
        return;
    };
    let per_asset: usize = std::env::var("G2TESS_MUTATIONS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(24);
    let assets: Vec<PathBuf> = corpus::gltf_files(&corpus.join("valid"))
        .into_iter()
        .filter(|p| folder_size(p) <= MAX_ASSET_BYTES)
        .collect();
    assert!(assets.len() >= 30, "only {} small assets", assets.len());
    let mut jobs = Vec::new();
    for (n, path) in assets.iter().enumerate() {
        let original = std::fs::read(path).unwrap();
        let mut rng = Lcg(n as u64 + 1);
        for k in 0..per_asset {
            jobs.push((path.clone(), mutate(&original, k, &mut rng)));
        }
    }
    let total = jobs.len();
    let failures = Mutex::new(Vec::new());
    let queue = Mutex::new(jobs);
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let Some((path, case)) = queue.lock().unwrap().pop() else {
                    return;
                };
                if let Some(f) = run_case(&path, &case) {
                    failures.lock().unwrap().push(f);
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    assert!(
        failures.is_empty(),
        "{} of {total} cases failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// Writes `case` beside copies of the asset's companion files, runs the binary, and returns
/// what went wrong, if anything.
fn run_case(asset: &Path, case: &Case) -> Option<String> {
    let dir = corpus::temp_dir();
    for f in std::fs::read_dir(asset.parent().unwrap())
        .unwrap()
        .flatten()
    {
        if f.path() != asset && f.path().is_file() {
            std::fs::copy(f.path(), dir.path().join(f.file_name())).unwrap();
        }
    }
    let input = dir.path().join(asset.file_name().unwrap());
    std::fs::write(&input, &case.bytes).unwrap();
    let output = dir.path().join("out.glb");
    let mut args = vec![input.into_os_string(), "-o".into(), output.clone().into()];
    args.extend(hostile::RUN_OPTIONS.iter().map(Into::into));
    let run = hostile::run_limited(&args, None);
    let name = format!("{} [{}]", asset.display(), case.label);
    if let Some(bad) = hostile::verdict(&run) {
        return Some(format!("{name}: {bad}"));
    }
    if run.code == Some(0) {
        if let Err(e) = hostile::scan_non_finite(&output) {
            return Some(format!("{name}: non-finite output: {e}"));
        }
    } else if output.exists() {
        return Some(format!("{name}: failed but wrote {}", output.display()));
    }
    None
}

/// Bytes of the asset and every file beside it.
fn folder_size(asset: &Path) -> u64 {
    std::fs::read_dir(asset.parent().unwrap())
        .unwrap()
        .flatten()
        .filter_map(|e| e.metadata().ok())
        .map(|m| m.len())
        .sum()
}

/// Mutation `k` of `original`: the kinds take turns so that every asset gets each of them.
fn mutate(original: &[u8], k: usize, rng: &mut Lcg) -> Case {
    let len = original.len();
    match k % 6 {
        0 => {
            // Truncation points spread over the whole file, then random ones.
            let at = if k < 6 * 4 {
                len * (k / 6 + 1) / 5
            } else {
                rng.below(len)
            };
            Case {
                label: format!("truncated at {at}"),
                bytes: original[..at].to_vec(),
            }
        }
        1 => {
            let mut bytes = original.to_vec();
            let at = rng.below(len);
            bytes[at] ^= 1 + rng.below(255) as u8;
            Case {
                label: format!("byte {at} flipped"),
                bytes,
            }
        }
        _ => json_mutation(original, k, rng),
    }
}

/// A change to the JSON (of a `.gltf`, or inside a `.glb`, re-assembled with correct chunk
/// lengths so that the change reaches the JSON checks and the data behind them).
fn json_mutation(original: &[u8], k: usize, rng: &mut Lcg) -> Case {
    let is_glb = original.starts_with(b"glTF");
    let (json_bytes, bin) = if is_glb {
        let c = glb::split(original).expect("a valid asset");
        (
            c.json.to_vec(),
            c.bin.map(<[u8]>::to_vec).unwrap_or_default(),
        )
    } else {
        (original.to_vec(), Vec::new())
    };
    let mut root: Value = serde_json::from_slice(&json_bytes).expect("valid JSON");
    let mut paths = Vec::new();
    collect_paths(&root, String::new(), &mut paths);
    let label = match k % 6 {
        2 => {
            // Counts, offsets, strides and references: the numbers that size allocations.
            const KEYS: [&str; 10] = [
                "count",
                "byteOffset",
                "byteLength",
                "byteStride",
                "bufferView",
                "buffer",
                "indices",
                "POSITION",
                "mode",
                "componentType",
            ];
            let numeric: Vec<&String> = paths
                .iter()
                .filter(|p| KEYS.iter().any(|k| p.ends_with(&format!("/{k}"))))
                .collect();
            let Some(p) = numeric.get(rng.below(numeric.len())).map(|p| p.to_string()) else {
                return Case {
                    label: "unchanged".into(),
                    bytes: original.to_vec(),
                };
            };
            let old = root.pointer(&p).and_then(Value::as_u64).unwrap_or(0);
            let new = [
                0,
                old + 1,
                old.saturating_sub(1),
                old * 3 + 7,
                1 << 31,
                u32::MAX as u64,
                1 << 40,
            ][rng.below(7)];
            *root.pointer_mut(&p).unwrap() = json!(new);
            format!("{p} {old} -> {new}")
        }
        3 => {
            let p = paths[rng.below(paths.len())].clone();
            delete(&mut root, &p);
            format!("{p} deleted")
        }
        4 => {
            let p = paths[rng.below(paths.len())].clone();
            let wrong = [
                json!("x"),
                json!([]),
                json!({}),
                json!(null),
                json!(-1),
                json!(1.5),
                json!(1e300),
                json!(true),
            ];
            let w = wrong[rng.below(wrong.len())].clone();
            *root.pointer_mut(&p).unwrap() = w.clone();
            format!("{p} = {w}")
        }
        _ => {
            // A number anywhere, off by one or scaled (indices, counts, components, values).
            let numbers: Vec<&String> = paths
                .iter()
                .filter(|p| root.pointer(p).is_some_and(Value::is_number))
                .collect();
            let Some(p) = numbers.get(rng.below(numbers.len())).map(|p| p.to_string()) else {
                return Case {
                    label: "unchanged".into(),
                    bytes: original.to_vec(),
                };
            };
            let old = root.pointer(&p).and_then(Value::as_f64).unwrap_or(0.0);
            let new = [old + 1.0, old - 1.0, old * 1000.0, -old, 0.0][rng.below(5)];
            *root.pointer_mut(&p).unwrap() = json!(new);
            format!("{p} {old} -> {new}")
        }
    };
    let text = serde_json::to_vec(&root).unwrap();
    let bytes = if is_glb {
        glb::assemble(&text, &bin)
    } else {
        text
    };
    Case { label, bytes }
}

/// Every JSON pointer below `v` (objects' fields and arrays' elements).
fn collect_paths(v: &Value, at: String, out: &mut Vec<String>) {
    match v {
        Value::Object(o) => {
            for (k, x) in o {
                let p = format!("{at}/{}", k.replace('~', "~0").replace('/', "~1"));
                out.push(p.clone());
                collect_paths(x, p, out);
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                let p = format!("{at}/{i}");
                out.push(p.clone());
                collect_paths(x, p, out);
            }
        }
        _ => {}
    }
}

fn delete(root: &mut Value, pointer: &str) {
    let (parent, last) = pointer.rsplit_once('/').unwrap();
    match root.pointer_mut(parent) {
        Some(Value::Object(o)) => {
            o.shift_remove(&last.replace("~1", "/").replace("~0", "~"));
        }
        Some(Value::Array(a)) => {
            if let Ok(i) = last.parse::<usize>() {
                a.remove(i);
            }
        }
        _ => {}
    }
}
