//! The binary over folders: mirrored outputs, folder configs and sidecars, a broken file among
//! good ones, the JSON report, skipping on a second run, `--check`, globs, `--fail-fast`, and
//! byte-equal outputs at any `-j`.

use crate::corpus;

use std::path::{Path, PathBuf};
use std::process::Output;

use serde_json::Value;

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/icosahedron.glb")
}

/// A tree with nested folders, folder configs, a sidecar, a `.gltf` with its `.bin` and a
/// broken file:
///
/// ```text
/// tree/g2tess.toml           level = 2
/// tree/a.glb                 → level 2 (folder config)
/// tree/chars/g2tess.toml     level = 1 (nearer, wins)
/// tree/chars/c.glb           → level 1
/// tree/props/b.gltf + .bin   → level 3 (its sidecar)
/// tree/props/b.g2tess.toml   level = 3
/// tree/props/broken.glb      not glTF
/// ```
fn tree(dir: &Path) -> PathBuf {
    let tree = dir.join("tree");
    for sub in ["chars", "props"] {
        std::fs::create_dir_all(tree.join(sub)).unwrap();
    }
    std::fs::write(tree.join("g2tess.toml"), "level = 2\n").unwrap();
    std::fs::copy(example(), tree.join("a.glb")).unwrap();
    std::fs::write(tree.join("chars/g2tess.toml"), "level = 1\n").unwrap();
    std::fs::copy(example(), tree.join("chars/c.glb")).unwrap();
    let made = g2tess(&[
        example().as_os_str(),
        "--level".as_ref(),
        "1".as_ref(),
        "-o".as_ref(),
        tree.join("props/b.gltf").as_os_str(),
    ]);
    assert_eq!(made.status.code(), Some(0), "{}", stderr(&made));
    std::fs::write(tree.join("props/b.g2tess.toml"), "level = 3\n").unwrap();
    std::fs::write(tree.join("props/broken.glb"), b"glTF not really").unwrap();
    tree
}

fn g2tess(args: &[&std::ffi::OsStr]) -> Output {
    corpus::g2tess().args(args).output().unwrap()
}

/// Runs g2tess on `tree` into `out` with a report; returns the run and the report.
fn run(tree: &Path, out: &Path, extra: &[&str]) -> (Output, Value) {
    let report = out.with_extension("report.json");
    let run = corpus::g2tess()
        .arg(tree)
        .arg("-o")
        .arg(out)
        .arg("--report")
        .arg(&report)
        .args(extra)
        .output()
        .unwrap();
    let json = std::fs::read(&report)
        .map(|b| serde_json::from_slice(&b).unwrap())
        .unwrap_or(Value::Null);
    (run, json)
}

fn stderr(run: &Output) -> String {
    String::from_utf8_lossy(&run.stderr).into_owned()
}

/// The report's record of the input whose path ends with `name`.
fn record<'a>(report: &'a Value, name: &str) -> &'a Value {
    report["files"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["input"].as_str().unwrap().ends_with(name))
        .unwrap_or_else(|| panic!("no record for {name} in {report:#}"))
}

fn statuses(report: &Value) -> Vec<(String, String)> {
    report["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            let input = r["input"].as_str().unwrap();
            let name = Path::new(input).file_name().unwrap().to_string_lossy();
            (name.into_owned(), r["status"].as_str().unwrap().to_string())
        })
        .collect()
}

fn pairs(list: &[(&str, &str)]) -> Vec<(String, String)> {
    list.iter()
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .collect()
}

/// Every file below `dir` (relative path → bytes), the manifest left out.
fn files(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut all: Vec<_> = walkdir::WalkDir::new(dir)
        .sort_by_file_name()
        .into_iter()
        .map(|e| e.unwrap())
        .filter(|e| e.file_type().is_file() && e.file_name() != ".g2tess-manifest.json")
        .map(|e| {
            let rel = e.path().strip_prefix(dir).unwrap().to_path_buf();
            (rel, std::fs::read(e.path()).unwrap())
        })
        .collect();
    all.sort();
    all
}

#[test]
fn a_tree_with_a_broken_file_mirrors_the_rest_and_exits_1() {
    let dir = corpus::temp_dir();
    let tree = tree(dir.path());
    let out = dir.path().join("out");
    let (run, report) = run(&tree, &out, &["-j", "2"]);
    let err = stderr(&run);
    assert_eq!(run.status.code(), Some(1), "{err}");
    let broken = tree.join("props/broken.glb");
    assert!(
        err.contains(&format!("g2tess: error: {}: ", broken.display())),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    for f in ["a.glb", "chars/c.glb", "props/b.gltf", "props/b.bin"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    assert!(!out.join("props/broken.glb").exists());
    let left: Vec<_> = files(&out)
        .into_iter()
        .filter(|(p, _)| p.to_string_lossy().contains(".g2tess-"))
        .map(|(p, _)| p)
        .collect();
    assert!(left.is_empty(), "temporary files left: {left:?}");

    // Sorted walk order, one record per asset.
    assert_eq!(
        statuses(&report),
        pairs(&[
            ("a.glb", "done"),
            ("c.glb", "done"),
            ("b.gltf", "done"),
            ("broken.glb", "failed")
        ])
    );
    // Nearest folder config wins; a sidecar beats both.
    assert_eq!(record(&report, "a.glb")["level"], 2);
    assert_eq!(record(&report, "c.glb")["level"], 1);
    assert_eq!(record(&report, "b.gltf")["level"], 3);
    assert_eq!(record(&report, "a.glb")["triangles_in"], 20);
    assert_eq!(record(&report, "a.glb")["triangles_out"], 20 * 4);
    assert_eq!(record(&report, "b.gltf")["triangles_out"], 20 * 9);
}

#[test]
fn the_report_has_the_documented_fields() {
    let dir = corpus::temp_dir();
    let tree = tree(dir.path());
    let out = dir.path().join("out");
    let (_, report) = run(&tree, &out, &[]);
    assert_eq!(report["format"], 1);
    assert_eq!(report["mode"], "write");
    assert_eq!(report["exit_status"], 1);
    let s = &report["summary"];
    assert_eq!(
        (s["done"].as_u64(), s["failed"].as_u64()),
        (Some(3), Some(1))
    );
    assert_eq!(s["triangles_in"], 60);
    assert!(s["bytes_out"].as_u64().unwrap() > 0 && s["seconds"].as_f64().is_some());

    let a = record(&report, "a.glb");
    assert_eq!(a["output"], out.join("a.glb").display().to_string());
    assert!(a["error"].is_null());
    for key in [
        "primitives",
        "vertices_out",
        "bytes_in",
        "bytes_out",
        "seconds",
    ] {
        assert!(a[key].is_number(), "{key} in {a:#}");
    }
    assert!(a["times"]["total"].is_number() && a["warnings"].is_array());
    let edges = &a["meshes"][0]["edges"];
    for key in [
        "smooth_edges",
        "crease_edges",
        "open_edges",
        "max_normal_jump_deg",
        "max_gap",
    ] {
        assert!(edges[key].is_number(), "{key} in {edges:#}");
    }

    let broken = record(&report, "broken.glb");
    let error = broken["error"].as_str().unwrap();
    assert!(error.starts_with(&tree.join("props/broken.glb").display().to_string()));
    assert!(broken["triangles_out"].is_null());
}

#[test]
fn a_second_run_skips_what_is_up_to_date_and_redoes_what_changed() {
    let dir = corpus::temp_dir();
    let tree = tree(dir.path());
    let out = dir.path().join("out");
    let (first, _) = run(&tree, &out, &[]);
    assert_eq!(first.status.code(), Some(1));
    let before = files(&out);

    let (second, report) = run(&tree, &out, &[]);
    assert_eq!(second.status.code(), Some(1), "the broken file still fails");
    assert_eq!(
        statuses(&report),
        pairs(&[
            ("a.glb", "skipped"),
            ("c.glb", "skipped"),
            ("b.gltf", "skipped"),
            ("broken.glb", "failed")
        ])
    );
    assert_eq!(files(&out), before);

    // A changed sidecar redoes its asset; a changed folder config the assets below it.
    std::fs::write(tree.join("props/b.g2tess.toml"), "level = 2\n").unwrap();
    std::fs::write(tree.join("chars/g2tess.toml"), "level = 3\n").unwrap();
    std::fs::remove_file(tree.join("props/broken.glb")).unwrap();
    let (third, report) = run(&tree, &out, &[]);
    assert_eq!(third.status.code(), Some(0), "{}", stderr(&third));
    assert_eq!(
        statuses(&report),
        pairs(&[("a.glb", "skipped"), ("c.glb", "done"), ("b.gltf", "done")])
    );
    assert_eq!(record(&report, "c.glb")["triangles_out"], 20 * 9);

    // A flag that changes the settings redoes everything; so does --force.
    let (_, report) = run(&tree, &out, &["--h", "0.1"]);
    assert!(statuses(&report).iter().all(|(_, s)| s == "done"));
    let (_, report) = run(&tree, &out, &["--h", "0.1"]);
    assert!(statuses(&report).iter().all(|(_, s)| s == "skipped"));
    let (_, report) = run(&tree, &out, &["--h", "0.1", "--force"]);
    assert!(statuses(&report).iter().all(|(_, s)| s == "done"));

    // An output replaced by hand is made again.
    std::fs::write(out.join("a.glb"), b"edited").unwrap();
    let (_, report) = run(&tree, &out, &["--h", "0.1"]);
    assert_eq!(record(&report, "a.glb")["status"], "done");
}

#[test]
fn check_passes_on_current_outputs_and_fails_on_stale_or_missing_ones() {
    let dir = corpus::temp_dir();
    let tree = tree(dir.path());
    std::fs::remove_file(tree.join("props/broken.glb")).unwrap();
    let out = dir.path().join("out");

    // Nothing written yet: every output is missing, and --check writes nothing.
    let (run1, report) = run(&tree, &out, &["--check"]);
    assert_eq!(run1.status.code(), Some(1));
    assert_eq!(report["mode"], "check");
    assert!(statuses(&report).iter().all(|(_, s)| s == "changed"));
    assert!(
        stderr(&run1).contains("missing (expected what"),
        "{}",
        stderr(&run1)
    );
    assert!(!out.exists(), "--check wrote something");

    let (made, _) = run(&tree, &out, &[]);
    assert_eq!(made.status.code(), Some(0));
    let (ok, report) = run(&tree, &out, &["--check"]);
    assert_eq!(ok.status.code(), Some(0), "{}", stderr(&ok));
    assert!(statuses(&report).iter().all(|(_, s)| s == "unchanged"));

    // A .bin edited by hand is caught, and named.
    let bin = out.join("props/b.bin");
    let mut bytes = std::fs::read(&bin).unwrap();
    bytes[0] ^= 1;
    std::fs::write(&bin, &bytes).unwrap();
    let (stale, report) = run(&tree, &out, &["--check"]);
    assert_eq!(stale.status.code(), Some(1));
    assert_eq!(record(&report, "b.gltf")["status"], "changed");
    assert_eq!(record(&report, "a.glb")["status"], "unchanged");
    assert!(
        stderr(&stale).contains(&format!("g2tess: error: {}: out of date", bin.display())),
        "{}",
        stderr(&stale)
    );
    assert_eq!(
        std::fs::read(&bin).unwrap(),
        bytes,
        "--check rewrote a file"
    );
}

#[test]
fn check_compares_a_compressed_outputs_fallback_buffer_and_never_writes_it() {
    let dir = corpus::temp_dir();
    let tree = dir.path().join("tree");
    std::fs::create_dir_all(&tree).unwrap();
    std::fs::copy(example(), tree.join("a.glb")).unwrap();
    let out = dir.path().join("out");
    let flags = ["--level", "2", "--compress", "--compress-fallback"];
    let (made, _) = run(&tree, &out, &flags);
    assert_eq!(made.status.code(), Some(0), "{}", stderr(&made));
    let fallback = out.join("a.fallback.bin");
    assert!(fallback.is_file(), "no fallback buffer written");
    let (ok, _) = run(&tree, &out, &[&flags[..], &["--check"]].concat());
    assert_eq!(ok.status.code(), Some(0), "{}", stderr(&ok));

    std::fs::remove_file(&fallback).unwrap();
    let (missing, report) = run(&tree, &out, &[&flags[..], &["--check"]].concat());
    assert_eq!(missing.status.code(), Some(1));
    assert_eq!(record(&report, "a.glb")["status"], "changed");
    assert!(
        stderr(&missing).contains(&format!("{}: missing", fallback.display())),
        "{}",
        stderr(&missing)
    );
    assert!(!fallback.exists(), "--check wrote the fallback buffer");
}

#[test]
fn outputs_are_byte_equal_at_any_thread_count() {
    let dir = corpus::temp_dir();
    let tree = tree(dir.path());
    let mut inputs = vec![tree];
    if let Some(real) = corpus::fixtures_real() {
        inputs.push(real.join("valid"));
    }
    let mut results = Vec::new();
    for j in ["1", "2"] {
        let out = dir.path().join(format!("out-j{j}"));
        let run = corpus::g2tess()
            .args(&inputs)
            .arg("-o")
            .arg(&out)
            .args(["--level", "2", "-q", "-j", j])
            .output()
            .unwrap();
        assert_eq!(run.status.code(), Some(1), "{}", stderr(&run));
        results.push(files(&out));
    }
    assert!(results[0].len() >= 4);
    assert_eq!(results[0].len(), results[1].len());
    for (a, b) in results[0].iter().zip(&results[1]) {
        assert!(a == b, "{} differs between -j 1 and -j 2", a.0.display());
    }
}

#[test]
fn include_and_exclude_filter_the_walk() {
    let dir = corpus::temp_dir();
    let tree = tree(dir.path());
    let (_, report) = run(&tree, &dir.path().join("o1"), &["--exclude", "props"]);
    assert_eq!(
        statuses(&report),
        pairs(&[("a.glb", "done"), ("c.glb", "done")])
    );
    let (_, report) = run(&tree, &dir.path().join("o2"), &["--include", "*.gltf"]);
    assert_eq!(statuses(&report), pairs(&[("b.gltf", "done")]));
    let (_, report) = run(
        &tree,
        &dir.path().join("o3"),
        &["--include", "props/**", "--exclude", "broken.*"],
    );
    assert_eq!(statuses(&report), pairs(&[("b.gltf", "done")]));
}

#[test]
fn fail_fast_starts_nothing_after_the_first_failure() {
    let dir = corpus::temp_dir();
    let tree = tree(dir.path());
    std::fs::write(tree.join("0-broken.glb"), b"nope").unwrap();
    let (run, report) = run(&tree, &dir.path().join("out"), &["--fail-fast", "-j", "1"]);
    assert_eq!(run.status.code(), Some(1));
    let s = statuses(&report);
    assert_eq!(s[0], ("0-broken.glb".to_string(), "failed".to_string()));
    assert!(s[1..].iter().all(|(_, st)| st == "cancelled"), "{s:?}");
}

#[test]
fn an_output_folder_inside_the_input_is_never_read_as_input() {
    let dir = corpus::temp_dir();
    let tree = tree(dir.path());
    let out = tree.join("smooth");
    let (_, first) = run(&tree, &out, &[]);
    let (_, second) = run(&tree, &out, &["--force"]);
    assert_eq!(statuses(&first).len(), 4);
    assert_eq!(statuses(&second).len(), 4);
    assert!(!out.join("smooth").exists());
}

#[test]
fn a_broken_folder_config_fails_its_assets_only() {
    let dir = corpus::temp_dir();
    let tree = tree(dir.path());
    let config = tree.join("chars/g2tess.toml");
    std::fs::write(&config, "level = 1\nlevle = 2\n").unwrap();
    let (run, report) = run(&tree, &dir.path().join("out"), &[]);
    assert_eq!(run.status.code(), Some(1));
    assert_eq!(record(&report, "a.glb")["status"], "done");
    let c = record(&report, "c.glb");
    assert_eq!(c["status"], "failed");
    let expected = format!(
        "{}: not processed: {}:2: ",
        tree.join("chars/c.glb").display(),
        config.display()
    );
    assert!(c["error"].as_str().unwrap().starts_with(&expected), "{c:#}");
}

#[test]
fn usage_errors_exit_2_and_say_what_was_expected() {
    let dir = corpus::temp_dir();
    let tree = tree(dir.path());
    let cases: Vec<(Vec<&std::ffi::OsStr>, &str)> = vec![
        (
            vec![tree.as_os_str()],
            "a folder input needs an output folder (expected e.g. -o ",
        ),
        (
            vec![tree.as_os_str(), "-o".as_ref(), tree.as_os_str()],
            "the output folder is the input folder",
        ),
        (
            vec![tree.as_os_str(), "-o".as_ref(), "x.glb".as_ref()],
            "-o names a file, but there are folder inputs (expected an output folder)",
        ),
        (
            vec![
                tree.as_os_str(),
                "--include".as_ref(),
                "a[".as_ref(),
                "-o".as_ref(),
                "o".as_ref(),
            ],
            "--include a[: ",
        ),
    ];
    for (args, expected) in cases {
        let run = g2tess(&args);
        let err = stderr(&run);
        assert_eq!(run.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.starts_with("g2tess: error: ") && err.contains(expected),
            "{err}"
        );
    }
    // Two inputs that would write one output.
    let other = dir.path().join("other");
    std::fs::create_dir(&other).unwrap();
    std::fs::copy(example(), other.join("a.glb")).unwrap();
    let run = corpus::g2tess()
        .arg(&tree)
        .arg(&other)
        .arg("-o")
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(2));
    assert!(
        stderr(&run).contains("is the output of both"),
        "{}",
        stderr(&run)
    );
}

/// Runs g2tess with `args` and returns the run.
fn g2tess_args(args: &[&Path]) -> Output {
    corpus::g2tess().args(args).output().unwrap()
}

#[test]
fn a_glb_and_a_gltf_sharing_a_fallback_buffer_are_refused_before_writing() {
    let dir = corpus::temp_dir();
    let input = dir.path().join("in");
    std::fs::create_dir(&input).unwrap();
    std::fs::copy(example(), input.join("x.glb")).unwrap();
    let made = g2tess(&[
        example().as_os_str(),
        "-o".as_ref(),
        input.join("x.gltf").as_os_str(),
    ]);
    assert_eq!(made.status.code(), Some(0), "{}", stderr(&made));
    let out = dir.path().join("out");
    let run = corpus::g2tess()
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .args(["--compress", "--compress-fallback"])
        .output()
        .unwrap();
    let err = stderr(&run);
    assert_eq!(run.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!(
            "{}: would be written for both {} and {}",
            out.join("x.fallback.bin").display(),
            input.join("x.glb").display(),
            input.join("x.gltf").display()
        )),
        "{err}"
    );
    assert!(!out.exists(), "something was written: {:?}", files(&out));
    // Without a fallback buffer the two outputs share no file.
    let run = g2tess_args(&[&input, Path::new("-o"), &out]);
    assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));
}

#[test]
fn an_output_never_replaces_a_file_another_input_reads() {
    let dir = corpus::temp_dir();
    let input = dir.path().join("in");
    std::fs::create_dir_all(input.join("out")).unwrap();
    // b.gltf + b.bin, and a.gltf whose buffer is out/b.bin (a copy of b.bin).
    let made = g2tess(&[
        example().as_os_str(),
        "-o".as_ref(),
        input.join("b.gltf").as_os_str(),
    ]);
    assert_eq!(made.status.code(), Some(0), "{}", stderr(&made));
    let b_json = std::fs::read_to_string(input.join("b.gltf")).unwrap();
    let a_json = b_json.replace("\"b.bin\"", "\"out/b.bin\"");
    assert_ne!(a_json, b_json);
    std::fs::write(input.join("a.gltf"), a_json).unwrap();
    std::fs::copy(input.join("b.bin"), input.join("out/b.bin")).unwrap();
    let before = std::fs::read(input.join("out/b.bin")).unwrap();
    let out = input.join("out");
    let run = g2tess_args(&[&input, Path::new("-o"), &out]);
    let err = stderr(&run);
    assert_eq!(run.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!(
            "{}: is read by {} and would be replaced by the output of {}",
            out.join("b.bin").display(),
            input.join("a.gltf").display(),
            input.join("b.gltf").display()
        )),
        "{err}"
    );
    assert_eq!(std::fs::read(input.join("out/b.bin")).unwrap(), before);
    assert_eq!(
        files(&out).len(),
        1,
        "an output was written: {:?}",
        files(&out)
    );
}

#[test]
fn an_output_folder_around_the_input_folder_is_a_usage_error() {
    let dir = corpus::temp_dir();
    let assets = dir.path().join("assets");
    std::fs::create_dir_all(assets.join("raw")).unwrap();
    std::fs::copy(example(), assets.join("raw/a.glb")).unwrap();
    let run = g2tess_args(&[&assets.join("raw"), Path::new("-o"), &assets]);
    let err = stderr(&run);
    assert_eq!(run.status.code(), Some(2), "{err}");
    assert!(
        err.contains("contains the input folder (expected an output folder outside it"),
        "{err}"
    );
    assert_eq!(files(&assets).len(), 1, "{:?}", files(&assets));
}

#[test]
fn a_folder_that_cannot_be_read_is_an_error_naming_it() {
    use std::os::unix::fs::PermissionsExt as _;
    let dir = corpus::temp_dir();
    let input = dir.path().join("in");
    std::fs::create_dir_all(input.join("locked")).unwrap();
    std::fs::copy(example(), input.join("a.glb")).unwrap();
    std::fs::copy(example(), input.join("locked/b.glb")).unwrap();
    let locked = input.join("locked");
    std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o000)).unwrap();
    let readable = std::fs::read_dir(&locked).is_ok();
    let run = g2tess_args(&[&input, Path::new("-o"), &dir.path().join("out")]);
    std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o755)).unwrap();
    if readable {
        // The walker's part is tested with an injected error in the unit tests of `scope`.
        eprintln!("skipped: running as a user who can read mode-000 folders");
        return;
    }
    let err = stderr(&run);
    assert_eq!(run.status.code(), Some(1), "{err}");
    assert!(
        err.contains(&format!(
            "g2tess: error: {}: cannot read: ",
            locked.display()
        )),
        "{err}"
    );
    assert!(dir.path().join("out/a.glb").is_file(), "{err}");
}

#[test]
fn linked_assets_and_folders_are_followed_and_a_link_loop_is_reported() {
    let dir = corpus::temp_dir();
    let elsewhere = dir.path().join("elsewhere");
    let input = dir.path().join("in");
    std::fs::create_dir_all(&elsewhere).unwrap();
    std::fs::create_dir_all(input.join("real")).unwrap();
    std::fs::copy(example(), elsewhere.join("shared.glb")).unwrap();
    std::fs::copy(example(), input.join("real/a.glb")).unwrap();
    std::os::unix::fs::symlink(elsewhere.join("shared.glb"), input.join("b.glb")).unwrap();
    std::os::unix::fs::symlink(input.join("real"), input.join("linked")).unwrap();
    std::os::unix::fs::symlink(&input, input.join("real/up")).unwrap();
    let out = dir.path().join("out");
    let run = g2tess_args(&[&input, Path::new("-o"), &out]);
    let err = stderr(&run);
    assert_eq!(run.status.code(), Some(0), "{err}");
    for made in ["b.glb", "real/a.glb", "linked/a.glb"] {
        assert!(out.join(made).is_file(), "{made} missing; {err}");
    }
    assert!(
        err.contains("g2tess: warning: ") && err.contains("a link back to"),
        "{err}"
    );
}

/// Starts g2tess with its stderr (or stdout) a pipe whose reading end is closed at once, as
/// `g2tess … 2>&1 | head -1` leaves it after the first line.
fn closed_pipe_run(args: &[&std::ffi::OsStr], stdout: bool) -> std::process::ExitStatus {
    use std::process::Stdio;
    let mut cmd = corpus::g2tess();
    cmd.args(args);
    match stdout {
        true => cmd.stdout(Stdio::piped()).stderr(Stdio::null()),
        false => cmd.stderr(Stdio::piped()).stdout(Stdio::null()),
    };
    let mut child = cmd.spawn().unwrap();
    drop(child.stdout.take());
    drop(child.stderr.take());
    child.wait().unwrap()
}

#[test]
fn a_closed_pipe_ends_the_output_not_the_run() {
    let dir = corpus::temp_dir();
    let input = dir.path().join("in");
    std::fs::create_dir(&input).unwrap();
    for name in ["a.glb", "b.glb", "c.glb"] {
        std::fs::copy(example(), input.join(name)).unwrap();
    }
    let out = dir.path().join("out");
    let status = closed_pipe_run(&[input.as_os_str(), "-o".as_ref(), out.as_os_str()], false);
    assert_eq!(status.code(), Some(0), "{status:?}");
    for name in ["a.glb", "b.glb", "c.glb"] {
        assert!(out.join(name).is_file(), "{name} missing");
    }
    let status = closed_pipe_run(
        &[example().as_os_str(), "--explain-h".as_ref(), "0".as_ref()],
        true,
    );
    assert_eq!(status.code(), Some(0), "{status:?}");
}
