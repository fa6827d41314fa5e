//! The build-system flags of the binary: `--print-inputs` lists exactly what a run reads,
//! `--depfile` writes it in Make's syntax, outputs are the same bytes wherever and however
//! they are made, `--shard` splits a batch into stable disjoint parts, and `--merge-reports`
//! puts their reports back together.

use crate::buildsys;
use crate::corpus;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Output;

use serde_json::Value;

fn g2tess_in(dir: &Path, args: &[&str]) -> Output {
    corpus::g2tess()
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A tree under `dir/lib` (paths relative to `dir`):
///
/// ```text
/// lib/g2tess.toml               level = 2
/// lib/a.glb
/// lib/kit/g2tess.toml           level = 1 (nearer: wins for the kit)
/// lib/kit/my crate.gltf + .bin  a name with a space
/// lib/kit/my crate.g2tess.toml  its sidecar
/// lib/kit/deep/b.glb            (uses lib/kit/g2tess.toml)
/// ```
fn tree(dir: &Path) {
    let lib = dir.join("lib");
    std::fs::create_dir_all(lib.join("kit/deep")).unwrap();
    std::fs::write(lib.join("g2tess.toml"), "level = 2\n").unwrap();
    std::fs::copy(buildsys::fixture(), lib.join("a.glb")).unwrap();
    std::fs::write(lib.join("kit/g2tess.toml"), "level = 1\n").unwrap();
    let made = g2tess_in(
        dir,
        &[
            buildsys::fixture().to_str().unwrap(),
            "--level",
            "1",
            "-q",
            "-o",
            "lib/kit/my crate.gltf",
        ],
    );
    assert!(made.status.success(), "{}", stderr(&made));
    std::fs::write(lib.join("kit/my crate.g2tess.toml"), "level = 3\n").unwrap();
    std::fs::copy(buildsys::fixture(), lib.join("kit/deep/b.glb")).unwrap();
}

/// `--print-inputs=json`'s record of each input, by input.
fn records(dir: &Path, args: &[&str]) -> std::collections::BTreeMap<String, Value> {
    let mut all = vec!["--print-inputs=json"];
    all.extend(args);
    let out = g2tess_in(dir, &all);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let doc: Value = serde_json::from_str(&stdout(&out)).unwrap();
    doc["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| (r["input"].as_str().unwrap().to_string(), r.clone()))
        .collect()
}

fn strings(v: &Value) -> Vec<&str> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap())
        .collect()
}

#[test]
fn print_inputs_lists_the_asset_its_files_its_sidecar_and_the_nearest_folder_config() {
    let tmp = corpus::temp_dir();
    tree(tmp.path());
    std::fs::write(tmp.path().join("base.toml"), "h = 0.1\n").unwrap();
    let r = records(
        tmp.path(),
        &["lib", "-o", "out", "--config", "base.toml", "--depfile"],
    );
    assert_eq!(r.len(), 3);

    let a = &r["lib/a.glb"];
    assert_eq!(
        strings(&a["reads"]),
        ["lib/a.glb", "lib/g2tess.toml", "base.toml"]
    );
    assert_eq!(strings(&a["reads_if_created"]), ["lib/a.g2tess.toml"]);
    assert_eq!(strings(&a["writes"]), ["out/a.glb", "out/a.glb.d"]);

    // The nearest config is the one read; a folder nearer than it could still get one.
    let c = &r["lib/kit/my crate.gltf"];
    assert_eq!(
        strings(&c["reads"]),
        [
            "lib/kit/my crate.gltf",
            "lib/kit/my crate.bin",
            "lib/kit/my crate.g2tess.toml",
            "lib/kit/g2tess.toml",
            "base.toml"
        ]
    );
    assert_eq!(strings(&c["reads_if_created"]), Vec::<&str>::new());
    assert_eq!(
        strings(&c["writes"]),
        [
            "out/kit/my crate.gltf",
            "out/kit/my crate.bin",
            "out/kit/my crate.gltf.d"
        ]
    );
    let b = &r["lib/kit/deep/b.glb"];
    assert_eq!(
        strings(&b["reads"]),
        ["lib/kit/deep/b.glb", "lib/kit/g2tess.toml", "base.toml"]
    );
    assert_eq!(
        strings(&b["reads_if_created"]),
        ["lib/kit/deep/b.g2tess.toml", "lib/kit/deep/g2tess.toml"]
    );

    // Lines: every file once, in the order first read.
    let out = g2tess_in(tmp.path(), &["--print-inputs", "lib", "-o", "out"]);
    assert_eq!(
        stdout(&out),
        "lib/a.glb\nlib/g2tess.toml\nlib/kit/deep/b.glb\nlib/kit/g2tess.toml\n\
         lib/kit/my crate.gltf\nlib/kit/my crate.bin\nlib/kit/my crate.g2tess.toml\n"
    );
    // It only lists: nothing was written.
    assert!(!tmp.path().join("out").exists());
}

#[test]
fn print_inputs_lists_images_and_names_an_unreadable_asset() {
    let tmp = corpus::temp_dir();
    if let Some(real) = corpus::fixtures_real() {
        let dir = real.join("valid/BoxTextured");
        let r = records(&dir, &["BoxTextured.gltf"]);
        assert_eq!(
            strings(&r["BoxTextured.gltf"]["reads"]),
            ["BoxTextured.gltf", "BoxTextured0.bin", "CesiumLogoFlat.png"]
        );
    }
    std::fs::write(tmp.path().join("gone.gltf"), b"not json").unwrap();
    std::fs::remove_file(tmp.path().join("gone.gltf")).unwrap();
    std::fs::copy(buildsys::fixture(), tmp.path().join("ok.glb")).unwrap();
    let out = g2tess_in(
        tmp.path(),
        &["--print-inputs", "ok.glb", "gone.gltf", "-o", "o"],
    );
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(stdout(&out), "ok.glb\n");
    assert!(
        stderr(&out).contains("gone.gltf: cannot be read"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn the_depfile_lists_what_exists_in_make_syntax_and_follows_skips() {
    let tmp = corpus::temp_dir();
    tree(tmp.path());
    let run = g2tess_in(tmp.path(), &["lib", "-o", "out", "--depfile", "-q"]);
    assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));
    let d = std::fs::read_to_string(tmp.path().join("out/kit/my crate.gltf.d")).unwrap();
    assert_eq!(
        d,
        "out/kit/my\\ crate.gltf: \\\n  lib/kit/my\\ crate.gltf \\\n  lib/kit/my\\ crate.bin \\\n  \
         lib/kit/my\\ crate.g2tess.toml \\\n  lib/kit/g2tess.toml\n\n\
         lib/kit/my\\ crate.bin:\n\nlib/kit/my\\ crate.g2tess.toml:\n\nlib/kit/g2tess.toml:\n"
    );
    // An up-to-date output that is skipped still gets its depfile.
    std::fs::remove_file(tmp.path().join("out/a.glb.d")).unwrap();
    let again = g2tess_in(tmp.path(), &["lib", "-o", "out", "--depfile", "-v"]);
    assert!(stderr(&again).contains("skipped"), "{}", stderr(&again));
    assert_eq!(
        std::fs::read_to_string(tmp.path().join("out/a.glb.d")).unwrap(),
        "out/a.glb: \\\n  lib/a.glb \\\n  lib/g2tess.toml\n\nlib/g2tess.toml:\n"
    );
    // A failed input gets none.
    std::fs::write(tmp.path().join("lib/bad.glb"), b"glTF not really").unwrap();
    let failed = g2tess_in(tmp.path(), &["lib", "-o", "out", "--depfile", "-q"]);
    assert_eq!(failed.status.code(), Some(1));
    assert!(!tmp.path().join("out/bad.glb.d").exists());
}

/// Every file below `dir`, by relative path, with its bytes.
fn files_below(dir: &Path) -> std::collections::BTreeMap<PathBuf, Vec<u8>> {
    walkdir::WalkDir::new(dir)
        .into_iter()
        .map(Result::unwrap)
        .filter(|e| e.file_type().is_file())
        .map(|e| {
            let rel = e.path().strip_prefix(dir).unwrap().to_path_buf();
            (rel, std::fs::read(e.path()).unwrap())
        })
        .collect()
}

#[test]
fn outputs_and_depfiles_are_the_same_bytes_in_any_folder_at_any_thread_count() {
    let tmp = corpus::temp_dir();
    let mut runs = Vec::new();
    for (place, jobs) in [
        ("first", "1"),
        ("first", "2"),
        ("second/deeper", "1"),
        ("second/deeper", "2"),
    ] {
        let dir = tmp.path().join(place).join(format!("j{jobs}"));
        std::fs::create_dir_all(&dir).unwrap();
        tree(&dir);
        let run = g2tess_in(&dir, &["lib", "-o", "out", "--depfile", "-j", jobs, "-q"]);
        assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));
        let mut outputs = files_below(&dir.join("out"));
        // The manifest is a cache of file times, not an output.
        outputs.retain(|p, _| !p.ends_with(".g2tess-manifest.json"));
        for (path, bytes) in &outputs {
            let text = String::from_utf8_lossy(bytes);
            for leak in [
                dir.to_str().unwrap(),
                tmp.path().to_str().unwrap(),
                &hostname(),
            ] {
                assert!(!text.contains(leak), "{}: holds {leak:?}", path.display());
            }
        }
        runs.push((format!("{place} -j {jobs}"), outputs));
    }
    let names: BTreeSet<_> = runs[0].1.keys().cloned().collect();
    // The outputs (.glb, .gltf + .bin) and a depfile for each of the three assets.
    assert_eq!(names.len(), 7, "{names:?}");
    for (what, outputs) in &runs[1..] {
        assert!(*outputs == runs[0].1, "{what} differs from {}", runs[0].0);
    }
}

fn hostname() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|h| h.trim().to_string())
        .ok()
        .filter(|h| h.len() >= 4)
        .unwrap_or_else(|| "\u{0}no host name\u{0}".into())
}

/// The inputs of shard `k` of `n` of `dir/lib`.
fn shard(dir: &Path, k: u32, n: u32) -> BTreeSet<String> {
    records(dir, &["lib", "-o", "out", "--shard", &format!("{k}/{n}")])
        .into_keys()
        .collect()
}

#[test]
fn shards_split_a_batch_into_disjoint_parts_that_stay_put_when_files_are_added() {
    let tmp = corpus::temp_dir();
    let lib = tmp.path().join("lib");
    for i in 0..24 {
        let folder = lib.join(format!("set{}", i % 3));
        std::fs::create_dir_all(&folder).unwrap();
        std::fs::copy(buildsys::fixture(), folder.join(format!("m{i}.glb"))).unwrap();
    }
    let all: BTreeSet<String> = records(tmp.path(), &["lib", "-o", "out"])
        .into_keys()
        .collect();
    let parts: Vec<_> = (1..=3).map(|k| shard(tmp.path(), k, 3)).collect();
    let total: usize = parts.iter().map(BTreeSet::len).sum();
    let union: BTreeSet<String> = parts.iter().flatten().cloned().collect();
    assert_eq!(
        (total, &union),
        (all.len(), &all),
        "shards overlap or miss inputs"
    );
    assert!(parts.iter().all(|p| !p.is_empty()), "{parts:?}");

    // New files, in new and in existing folders, sorting before and after the others.
    for name in ["set0/a0.glb", "set1/zz.glb", "aaa/n.glb", "set2/m100.glb"] {
        std::fs::create_dir_all(lib.join(name).parent().unwrap()).unwrap();
        std::fs::copy(buildsys::fixture(), lib.join(name)).unwrap();
    }
    for (k, before) in (1..=3).zip(&parts) {
        let after = shard(tmp.path(), k, 3);
        assert!(
            after.is_superset(before),
            "shard {k} lost inputs when files were added"
        );
    }
    let bad = g2tess_in(tmp.path(), &["lib", "-o", "out", "--shard", "4/3"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(
        stderr(&bad).contains("4/3 is out of range"),
        "{}",
        stderr(&bad)
    );
}

/// Runs `lib` into `out` with a report at `report` and `extra` flags.
fn report_run(dir: &Path, report: &str, extra: &[&str]) -> Value {
    let mut args = vec!["lib", "-o", "out", "-q", "--force", "--report", report];
    args.extend(extra);
    let run = g2tess_in(dir, &args);
    assert!(
        run.status.code() == Some(0) || run.status.code() == Some(1),
        "{}",
        stderr(&run)
    );
    serde_json::from_slice(&std::fs::read(dir.join(report)).unwrap()).unwrap()
}

#[test]
fn merged_shard_reports_equal_the_report_of_one_run() {
    let tmp = corpus::temp_dir();
    tree(tmp.path());
    std::fs::write(tmp.path().join("lib/kit/broken.glb"), b"glTF not really").unwrap();
    let whole = report_run(tmp.path(), "whole.json", &[]);
    let mut shards = Vec::new();
    for k in 1..=2 {
        let name = format!("shard{k}.json");
        report_run(tmp.path(), &name, &["--shard", &format!("{k}/2")]);
        shards.push(name);
    }
    let mut args = vec!["--merge-reports", "merged.json"];
    args.extend(shards.iter().map(String::as_str));
    let merge = g2tess_in(tmp.path(), &args);
    // The broken file fails its shard: the merged status is 1, as the whole run's.
    assert_eq!(merge.status.code(), Some(1), "{}", stderr(&merge));
    let merged: Value =
        serde_json::from_slice(&std::fs::read(tmp.path().join("merged.json")).unwrap()).unwrap();

    assert_eq!(merged["exit_status"], whole["exit_status"]);
    assert_eq!(merged["mode"], whole["mode"]);
    for key in [
        "done",
        "failed",
        "skipped",
        "triangles_in",
        "triangles_out",
        "bytes_in",
        "bytes_out",
    ] {
        assert_eq!(
            merged["summary"][key], whole["summary"][key],
            "summary.{key}"
        );
    }
    // The same records (times aside), sorted by input.
    let strip = |v: &Value| -> Vec<Value> {
        let mut files: Vec<Value> = v["files"].as_array().unwrap().clone();
        for f in &mut files {
            let f = f.as_object_mut().unwrap();
            f.retain(|k, _| !k.contains("seconds") && k != "times");
        }
        files.sort_by(|a, b| a["input"].as_str().cmp(&b["input"].as_str()));
        files
    };
    assert_eq!(strip(&merged), strip(&whole));
    let inputs: Vec<&str> = merged["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["input"].as_str().unwrap())
        .collect();
    let mut sorted = inputs.clone();
    sorted.sort();
    assert_eq!(inputs, sorted);

    // A report given twice overlaps itself: refused, naming both.
    let twice = g2tess_in(
        tmp.path(),
        &["--merge-reports", "m2.json", "shard1.json", "shard1.json"],
    );
    assert_eq!(twice.status.code(), Some(2));
    assert!(
        stderr(&twice).contains("is also in shard1.json"),
        "{}",
        stderr(&twice)
    );
}
