//! Exit statuses and the safety rules of the command line: 0 all done, 1 some input failed (the
//! others still processed), 2 usage or configuration error; outputs written atomically; inputs
//! never overwritten unless `--overwrite-input` is given.

use crate::corpus;

use std::path::{Path, PathBuf};

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/icosahedron.glb")
}

#[test]
fn help_exits_0_and_shows_defaults() {
    let run = corpus::g2tess().arg("--help").output().unwrap();
    assert_eq!(run.status.code(), Some(0));
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(
        text.contains("[default: 4]") && text.contains("Exit status"),
        "{text}"
    );
}

#[test]
fn missing_input_is_a_usage_error() {
    assert_eq!(corpus::g2tess().output().unwrap().status.code(), Some(2));
}

#[test]
fn out_of_range_level_is_a_usage_error() {
    let run = corpus::g2tess()
        .arg(example())
        .args(["--level", "0"])
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.starts_with("g2tess: error: command line: level: is 0 (expected 1 to 64)"),
        "{stderr}"
    );
}

#[test]
fn unknown_config_key_names_file_and_line() {
    let dir = corpus::temp_dir();
    let config = dir.path().join("bad.toml");
    std::fs::write(&config, "level = 2\nhh = 0.1\n").unwrap();
    let run = corpus::g2tess()
        .arg(example())
        .arg("--config")
        .arg(&config)
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains(&format!("{}:2: ", config.display())),
        "{stderr}"
    );
}

#[test]
fn one_bad_input_fails_the_run_but_not_the_others() {
    let dir = corpus::temp_dir();
    let bad = dir.path().join("bad.gltf");
    std::fs::write(&bad, "{").unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    let run = corpus::g2tess()
        .arg(&bad)
        .arg(example())
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(1));
    assert!(out.join("icosahedron.glb").exists());
    assert!(!out.join("bad.gltf").exists());
}

#[test]
fn identity_run_exits_0_and_writes_gltf_with_bin() {
    let dir = corpus::temp_dir();
    let out = dir.path().join("ico.gltf");
    let run = corpus::g2tess()
        .arg(example())
        .args(["--level", "1", "--h", "0", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(
        run.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(out.exists() && dir.path().join("ico.bin").exists());
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 2, "no temporary files left: {names:?}");
}

#[test]
fn input_is_not_overwritten_without_overwrite_input() {
    let dir = corpus::temp_dir();
    let input = dir.path().join("in.glb");
    std::fs::copy(example(), &input).unwrap();
    let before = std::fs::read(&input).unwrap();
    let run = corpus::g2tess()
        .arg(&input)
        .arg("-o")
        .arg(&input)
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&run.stderr).contains("--overwrite-input"));
    assert_eq!(std::fs::read(&input).unwrap(), before);
    let run = corpus::g2tess()
        .arg(&input)
        .arg("-o")
        .arg(&input)
        .arg("--overwrite-input")
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(0));
}

#[test]
fn output_is_deterministic() {
    let dir = corpus::temp_dir();
    let (a, b) = (dir.path().join("a.glb"), dir.path().join("b.glb"));
    for out in [&a, &b] {
        assert!(corpus::g2tess()
            .arg(example())
            .arg("-o")
            .arg(out)
            .status()
            .unwrap()
            .success());
    }
    assert_eq!(std::fs::read(a).unwrap(), std::fs::read(b).unwrap());
}

#[test]
fn an_output_name_without_an_asset_extension_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.txt");
    let run = corpus::g2tess()
        .arg(example())
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{err}");
    assert!(
        err.contains("-o names neither a .glb nor a .gltf file"),
        "{err}"
    );
    assert!(!out.exists());
}

#[test]
fn a_missing_sidecar_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    let run = corpus::g2tess()
        .arg(example())
        .arg("-o")
        .arg(dir.path().join("o.glb"))
        .arg("--sidecar")
        .arg(dir.path().join("none.g2tess.toml"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{err}");
    assert!(err.contains("--sidecar: no such file"), "{err}");
}

#[test]
fn a_folder_config_range_error_names_its_line_and_each_asset() {
    let dir = tempfile::tempdir().unwrap();
    let tree = dir.path().join("tree");
    std::fs::create_dir_all(tree.join("sub")).unwrap();
    std::fs::copy(example(), tree.join("a.glb")).unwrap();
    std::fs::copy(example(), tree.join("sub/b.glb")).unwrap();
    let config = tree.join("g2tess.toml");
    std::fs::write(&config, "# settings\n\nlevel = 99\n").unwrap();
    let run = corpus::g2tess()
        .arg(&tree)
        .arg("-o")
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{err}");
    for asset in ["a.glb", "sub/b.glb"] {
        let line = format!(
            "g2tess: error: {}: not processed: {}:3: level: is 99",
            tree.join(asset).display(),
            config.display()
        );
        assert_eq!(err.matches(&line).count(), 1, "{line}\n{err}");
    }
}
