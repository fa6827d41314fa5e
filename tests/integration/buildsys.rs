//! Shared helpers of the build-system tests: finding `bazel`, `ninja` and `make`, and the small
//! example asset tree they build.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// `tool` if it is on PATH; otherwise `None` (and a note on stderr), unless
/// `G2TESS_REQUIRE_BUILD_TOOLS=1` (set by `.ci/run`), in which case a missing tool fails the test.
pub fn tool(tool: &str) -> Option<PathBuf> {
    let found = std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|d| d.join(tool))
            .find(|p| p.is_file())
    });
    if found.is_none() {
        if std::env::var("G2TESS_REQUIRE_BUILD_TOOLS").as_deref() == Ok("1") {
            panic!("{tool} is required but not installed (.ci/run installs it with apt-get)");
        }
        eprintln!("skipped: {tool} is not installed");
    }
    found
}

/// The bundled icosahedron.
pub fn fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/icosahedron.glb")
}

/// Runs a command in `dir`, returning its output; panics with its stderr if it fails.
pub fn run_ok(cmd: &mut Command) -> Output {
    let out = cmd.output().expect("the command starts");
    assert!(
        out.status.success(),
        "{cmd:?} failed: {}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Fills `dir/assets` with the example assets: `rock.glb` (the icosahedron) and `crate.gltf`
/// with its `crate.bin` (the icosahedron at level 1, written as `.gltf`).
pub fn example_assets(dir: &Path) {
    let assets = dir.join("assets");
    std::fs::create_dir_all(&assets).unwrap();
    std::fs::copy(fixture(), assets.join("rock.glb")).unwrap();
    run_ok(
        super::corpus::g2tess()
            .arg(fixture())
            .args(["--level", "1", "-q", "-o"])
            .arg(assets.join("crate.gltf")),
    );
}

/// Copies the folder `from` into `to` (files and folders only).
pub fn copy_tree(from: &Path, to: &Path) {
    for entry in walkdir::WalkDir::new(from) {
        let entry = entry.unwrap();
        let dest = to.join(entry.path().strip_prefix(from).unwrap());
        if entry.file_type().is_dir() {
            std::fs::create_dir_all(&dest).unwrap();
        } else {
            std::fs::copy(entry.path(), &dest).unwrap();
        }
    }
}
