//! Every file in `../shared/fixtures-real/invalid/` is answered by the real binary with a clear
//! error, exit status 1, no panic, no signal and no output file, within a memory limit.

mod corpus;
mod hostile;

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
