//! Shared helpers of the hostile-input tests: the real binary run under a memory limit (and, to
//! stand for a full disk, a file-size limit), the verdict every run must meet, and an
//! independent scan of written files for non-finite numbers.
#![allow(dead_code)]

use std::ffi::OsStr;
use std::os::unix::process::ExitStatusExt as _;
use std::path::Path;
use std::process::Command;

use serde_json::Value;

/// Address space a run may use. Far above what the small inputs of these tests need at the
/// options [`run`] passes, far below what a declared-but-absent gigabyte would take.
pub const MEMORY_LIMIT_KIB: u64 = 1536 * 1024;

/// Options every run gets: a small level and output cap keep each run short and make the
/// memory limit meaningful (the cap bounds the job to about 100 MiB).
pub const RUN_OPTIONS: [&str; 4] = ["--level", "2", "--max-triangles", "200000"];

/// How one run of the binary ended.
#[derive(Debug)]
pub struct Run {
    /// The exit status, when it exited.
    pub code: Option<i32>,
    /// The signal that ended it, when one did.
    pub signal: Option<i32>,
    /// What it printed on stderr.
    pub stderr: String,
}

/// Runs `g2tess args…` under `ulimit -v` (and `ulimit -f` blocks of 512 bytes when `fsize` is
/// given, with SIGXFSZ ignored so that an over-long write fails like a full disk).
pub fn run_limited<S: AsRef<OsStr>>(args: &[S], fsize_blocks: Option<u64>) -> Run {
    let mut script = format!("ulimit -v {MEMORY_LIMIT_KIB}; ");
    if let Some(f) = fsize_blocks {
        script.push_str(&format!("trap '' XFSZ; ulimit -f {f}; "));
    }
    script.push_str("exec \"$0\" \"$@\"");
    let out = Command::new("sh")
        .arg("-c")
        .arg(script)
        .arg(env!("CARGO_BIN_EXE_g2tess"))
        .args(args)
        .output()
        .expect("sh runs");
    Run {
        code: out.status.code(),
        signal: out.status.signal(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// Every run must end with status 0 or 1 and a message; never a signal or a panic. Returns a
/// description of what is wrong, if anything.
pub fn verdict(run: &Run) -> Option<String> {
    if let Some(s) = run.signal {
        return Some(format!("killed by signal {s}; stderr: {}", run.stderr));
    }
    if run.stderr.contains("panicked") || run.stderr.contains("RUST_BACKTRACE") {
        return Some(format!("panicked: {}", run.stderr));
    }
    match run.code {
        Some(0) if !run.stderr.is_empty() => None,
        Some(1) if run.stderr.contains("g2tess: error: ") => None,
        other => Some(format!(
            "exit status {other:?} without the expected message; stderr: {}",
            run.stderr
        )),
    }
}

/// Checks a written `.glb` or `.gltf` (+ `.bin` beside it): every float accessor's data and
/// every `min`/`max` is finite. Independent of the library's reader, which refuses non-finite
/// input and so could hide non-finite output.
pub fn scan_non_finite(path: &Path) -> Result<(), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let (json, bin): (Value, Vec<u8>) = if bytes.starts_with(b"glTF") {
        let chunks = g2tess::gltf_io::glb::split(&bytes).map_err(|e| e.to_string())?;
        (
            serde_json::from_slice(chunks.json).map_err(|e| e.to_string())?,
            chunks.bin.unwrap_or_default().to_vec(),
        )
    } else {
        let json: Value = serde_json::from_slice(&bytes).map_err(|e| e.to_string())?;
        let bin = match json.pointer("/buffers/0/uri").and_then(Value::as_str) {
            Some(u) => std::fs::read(path.with_file_name(u)).unwrap_or_default(),
            None => Vec::new(),
        };
        (json, bin)
    };
    let views = json["bufferViews"].as_array().cloned().unwrap_or_default();
    for (i, a) in json["accessors"]
        .as_array()
        .into_iter()
        .flatten()
        .enumerate()
    {
        for key in ["min", "max"] {
            if let Some(list) = a.get(key).and_then(Value::as_array) {
                if list.iter().any(|v| !v.as_f64().is_some_and(f64::is_finite)) {
                    return Err(format!("accessors[{i}].{key} is {:?}", a[key]));
                }
            }
        }
        if a["componentType"] != 5126 || a.get("sparse").is_some() {
            continue;
        }
        let Some(view) = a["bufferView"].as_u64().and_then(|v| views.get(v as usize)) else {
            continue;
        };
        if view["buffer"] != 0 || view.get("extensions").is_some() {
            continue;
        }
        let n = match a["type"].as_str() {
            Some("SCALAR") => 1,
            Some("VEC2") => 2,
            Some("VEC3") => 3,
            Some("VEC4") | Some("MAT2") => 4,
            Some("MAT3") => 9,
            _ => 16,
        };
        let stride = view["byteStride"].as_u64().unwrap_or(4 * n) as usize;
        let start = (view["byteOffset"].as_u64().unwrap_or(0)
            + a["byteOffset"].as_u64().unwrap_or(0)) as usize;
        for e in 0..a["count"].as_u64().unwrap_or(0) as usize {
            for c in 0..n as usize {
                let at = start + e * stride + 4 * c;
                let Some(b) = bin.get(at..at + 4) else {
                    return Err(format!("accessors[{i}] runs past the buffer"));
                };
                let x = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
                if !x.is_finite() {
                    return Err(format!("accessors[{i}] element {e} holds {x}"));
                }
            }
        }
    }
    Ok(())
}

/// A small deterministic generator, so that every failure reproduces.
pub struct Lcg(pub u64);

impl Lcg {
    /// A value in `0..n` (n > 0).
    pub fn below(&mut self, n: usize) -> usize {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 33) as usize) % n.max(1)
    }
}

/// A one-mesh glTF over `positions` (and `normals`, when given) and a triangle list, with its
/// buffer at `uri` (written by the caller) and correct bounds. Returns the JSON and the buffer.
pub fn mesh_gltf(
    positions: &[[f32; 3]],
    normals: Option<&[[f32; 3]]>,
    indices: &[u32],
    uri: &str,
) -> (Value, Vec<u8>) {
    let mut bin = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut attributes = serde_json::Map::new();
    let mut push_vec3 = |name: &str, data: &[[f32; 3]], bin: &mut Vec<u8>| {
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for p in data {
            for c in 0..3 {
                // Bounds of the finite values only, so that a test of non-finite data reaches
                // the data and not its bounds.
                if p[c].is_finite() {
                    lo[c] = lo[c].min(p[c]);
                    hi[c] = hi[c].max(p[c]);
                }
                bin.extend_from_slice(&p[c].to_le_bytes());
            }
        }
        let offset = bin.len() - 12 * data.len();
        views.push(serde_json::json!({"buffer": 0, "byteOffset": offset, "byteLength": 12 * data.len(), "target": 34962}));
        let mut acc = serde_json::json!({"bufferView": views.len() - 1, "componentType": 5126, "count": data.len(), "type": "VEC3"});
        if name == "POSITION" {
            acc["min"] = serde_json::json!(lo);
            acc["max"] = serde_json::json!(hi);
        }
        accessors.push(acc);
        attributes.insert(name.into(), serde_json::json!(accessors.len() - 1));
    };
    push_vec3("POSITION", positions, &mut bin);
    if let Some(n) = normals {
        push_vec3("NORMAL", n, &mut bin);
    }
    let offset = bin.len();
    for i in indices {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    views.push(serde_json::json!({"buffer": 0, "byteOffset": offset, "byteLength": 4 * indices.len(), "target": 34963}));
    accessors.push(serde_json::json!({"bufferView": views.len() - 1, "componentType": 5125, "count": indices.len(), "type": "SCALAR"}));
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": attributes, "indices": accessors.len() - 1}]}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"uri": uri, "byteLength": bin.len()}],
    });
    (json, bin)
}

/// Writes [`mesh_gltf`] of the mesh as `t.gltf` + `t.bin` into `dir`; returns the `.gltf` path.
pub fn write_mesh(
    dir: &Path,
    positions: &[[f32; 3]],
    normals: Option<&[[f32; 3]]>,
    indices: &[u32],
) -> std::path::PathBuf {
    let (json, bin) = mesh_gltf(positions, normals, indices, "t.bin");
    std::fs::write(dir.join("t.bin"), bin).unwrap();
    let input = dir.join("t.gltf");
    std::fs::write(&input, serde_json::to_vec(&json).unwrap()).unwrap();
    input
}

/// A closed tetrahedron (4 vertices, 4 triangles wound outward), the smallest closed mesh.
pub fn tetrahedron() -> (Vec<[f32; 3]>, Vec<u32>) {
    (
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        vec![0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3],
    )
}

/// Writes a tetrahedron asset `name` into `dir` whose buffer `uri` is `uri`; returns its path.
/// The buffer's bytes are written to `bin_at` (relative to `dir`) when given.
/// Every file under `dir`, relative to it: what a run left behind.
pub fn files_under(dir: &Path) -> std::collections::BTreeSet<std::path::PathBuf> {
    walkdir::WalkDir::new(dir)
        .into_iter()
        .filter_map(Result::ok)
        .filter(|e| !e.file_type().is_dir())
        .map(|e| e.path().strip_prefix(dir).unwrap().to_path_buf())
        .collect()
}

/// [`write_tetrahedron`] as `dir/t.gltf` + `dir/t.bin`, with `pad` bytes of extras that every
/// output carries: a small binary part beside a large JSON part, to fail a write in between.
pub fn tetrahedron_with_large_json(dir: &Path, pad: usize) -> std::path::PathBuf {
    let input = write_tetrahedron(dir, "t.gltf", "t.bin", Some(Path::new("t.bin")));
    let mut json: Value = serde_json::from_slice(&std::fs::read(&input).unwrap()).unwrap();
    json["extras"] = serde_json::json!({ "pad": "x".repeat(pad) });
    std::fs::write(&input, serde_json::to_vec(&json).unwrap()).unwrap();
    input
}

pub fn write_tetrahedron(
    dir: &Path,
    name: &str,
    uri: &str,
    bin_at: Option<&Path>,
) -> std::path::PathBuf {
    let (p, i) = tetrahedron();
    let (json, bin) = mesh_gltf(&p, None, &i, uri);
    if let Some(at) = bin_at {
        std::fs::write(dir.join(at), bin).unwrap();
    }
    let path = dir.join(name);
    std::fs::write(&path, serde_json::to_vec_pretty(&json).unwrap()).unwrap();
    path
}
