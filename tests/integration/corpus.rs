//! Shared helpers of the integration tests: where the real-world corpus lives, the Khronos
//! validator, and temporary folders.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

/// The shared corpus of real assets, or `None` (and a note on stderr) when it is absent.
pub fn fixtures_real() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/fixtures-real");
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!("skipped: {} is absent", dir.display());
        None
    }
}

/// Every .gltf/.glb file under `dir`, sorted.
pub fn gltf_files(dir: &Path) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = walkdir::WalkDir::new(dir)
        .sort_by_file_name()
        .into_iter()
        .filter_map(Result::ok)
        .map(|e| e.into_path())
        .filter(|p| p.extension().is_some_and(|e| e == "gltf" || e == "glb"))
        .collect();
    out.sort();
    out
}

/// One validator verdict.
#[derive(Debug, Clone)]
pub struct Verdict {
    pub errors: u64,
    pub codes: Vec<String>,
}

/// Runs the Khronos validator (installed by `.ci/run` into `.ci/node_modules`) once over all
/// `paths`. Returns `None` when it is not installed, unless `G2TESS_REQUIRE_VALIDATOR=1`, in
/// which case a missing validator fails the test.
pub fn validate(paths: &[&Path]) -> Option<std::collections::BTreeMap<PathBuf, Verdict>> {
    let ci = Path::new(env!("CARGO_MANIFEST_DIR")).join(".ci");
    let installed = ci.join("node_modules/gltf-validator").is_dir();
    if !installed {
        if std::env::var("G2TESS_REQUIRE_VALIDATOR").as_deref() == Ok("1") {
            panic!("the glTF validator is required but not installed (run: npm ci --prefix .ci)");
        }
        eprintln!("skipped: the glTF validator is not installed (npm ci --prefix .ci)");
        return None;
    }
    let out = Command::new("node")
        .arg(ci.join("validate.mjs"))
        .args(paths)
        .output()
        .expect("node runs");
    assert!(
        out.status.success(),
        "validator failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut verdicts = std::collections::BTreeMap::new();
    for line in String::from_utf8(out.stdout).unwrap().lines() {
        let v: serde_json::Value = serde_json::from_str(line).unwrap();
        let codes = v["codes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_str().unwrap().to_string())
            .collect();
        verdicts.insert(
            PathBuf::from(v["file"].as_str().unwrap()),
            Verdict {
                errors: v["errors"].as_u64().unwrap(),
                codes,
            },
        );
    }
    Some(verdicts)
}

/// A fresh temporary folder.
pub fn temp_dir() -> tempfile::TempDir {
    tempfile::tempdir().expect("a temporary folder")
}

/// The g2tess binary.
pub fn g2tess() -> Command {
    Command::new(env!("CARGO_BIN_EXE_g2tess"))
}
