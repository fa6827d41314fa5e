//! Every file in `../shared/fixtures-real/invalid/` is answered by the real binary with a clear
//! error, exit status 1, no panic, no signal and no output file, within a memory limit.

use crate::corpus;
use crate::hostile;

/// Invalid files the tool repairs instead of refusing, each with a warning: zero-length and
/// non-unit normals (the direction is all the surface needs; a zero one is rebuilt from the
/// faces around its vertex).
const REPAIRED: [&str; 1] = ["real-box-zero-normals.glb"];

#[test]
fn every_invalid_asset_is_refused_cleanly() {
    let Some(corpus) = corpus::fixtures_real() else {
        return;
    };
    let out_dir = corpus::temp_dir();
    let files = corpus::gltf_files(&corpus.join("invalid"));
    assert!(
        files.len() >= 55,
        "only {} invalid files found",
        files.len()
    );
    for input in &files {
        let name = input.file_name().unwrap().to_string_lossy().to_string();
        if REPAIRED.contains(&name.as_str()) {
            continue;
        }
        let output = out_dir.path().join(format!("{name}.out.glb"));
        let run = hostile::run_limited(
            &[input.as_os_str(), "-o".as_ref(), output.as_os_str()],
            None,
        );
        let stderr = &run.stderr;
        assert_eq!(run.code, Some(1), "{name}: exit status; {run:?}");
        let prefix = format!("g2tess: error: {}: ", input.display());
        assert!(
            stderr.starts_with(&prefix),
            "{name}: message {stderr:?} does not start with {prefix:?}"
        );
        assert!(!stderr.contains("panicked"), "{name}: panicked: {stderr}");
        let what = stderr.trim_end();
        assert!(
            !what.ends_with('.'),
            "{name}: message ends with a period: {what}"
        );
        assert!(!output.exists(), "{name}: wrote an output");
    }
    let left: Vec<_> = std::fs::read_dir(out_dir.path()).unwrap().collect();
    assert!(left.is_empty(), "temporary files left behind: {left:?}");
}

/// The Box with zero-length and non-unit normals comes out processed, with one warning per kind
/// naming the mesh, primitive and accessor, and an output the validator accepts.
#[test]
fn zero_and_non_unit_normals_are_repaired_with_warnings() {
    let Some(corpus) = corpus::fixtures_real() else {
        return;
    };
    let out_dir = corpus::temp_dir();
    let input = corpus.join("invalid").join(REPAIRED[0]);
    let output = out_dir.path().join("box.glb");
    let run = hostile::run_limited(
        &[
            input.as_os_str(),
            "-o".as_ref(),
            output.as_os_str(),
            "-v".as_ref(),
        ],
        None,
    );
    assert_eq!(run.code, Some(0), "{run:?}");
    for what in [
        "meshes[0].primitives[0].attributes.NORMAL (accessors[1]): 4 zero-length normals (first: vertex 0) replaced by the angle-weighted normal of their faces",
        "meshes[0].primitives[0].attributes.NORMAL (accessors[1]): 4 normals not of unit length (first: vertex 4, length 0.1) normalized",
    ] {
        assert!(run.stderr.contains(what), "no {what:?} in {}", run.stderr);
    }
    if let Some(verdicts) = corpus::validate(&[output.as_path()]) {
        let v = &verdicts[&output];
        assert_eq!(v.errors, 0, "{v:?}");
    }
}
