//! `--watch` as a child process: each change (an asset, a sidecar, a folder config, a save by
//! temporary file and rename, a broken file and its fix, a deletion) gives the right output
//! within a few seconds, the watcher's own outputs inside the watched folder cause nothing, and
//! SIGINT ends it cleanly with status 0 and no temporary file left.
#![cfg(unix)]

use crate::corpus;

use std::io::{BufRead as _, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use serde_json::Value;

/// How long any one change may take to show.
const WAIT: Duration = Duration::from_secs(15);

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/icosahedron.glb")
}

/// The watcher child, with its stderr collected as it comes; killed if a test fails.
struct Watcher {
    child: Child,
    log: Arc<Mutex<String>>,
}

impl Watcher {
    fn start(args: &[&std::ffi::OsStr]) -> Watcher {
        let mut child = corpus::g2tess()
            .args(args)
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let log = Arc::new(Mutex::new(String::new()));
        let sink = Arc::clone(&log);
        let stderr = child.stderr.take().unwrap();
        std::thread::spawn(move || {
            for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                let mut log = sink.lock().unwrap();
                log.push_str(&line);
                log.push('\n');
            }
        });
        let w = Watcher { child, log };
        w.wait_for("the watch to start", |log| {
            log.contains("g2tess: watching ")
        });
        w
    }

    fn log(&self) -> String {
        self.log.lock().unwrap().clone()
    }

    /// Waits until `done(log)` holds, failing after [`WAIT`] or if the watcher died.
    fn wait_for(&self, what: &str, done: impl Fn(&str) -> bool) {
        let start = Instant::now();
        loop {
            if done(&self.log()) {
                return;
            }
            assert!(
                start.elapsed() < WAIT,
                "timed out waiting for {what}; log:\n{}",
                self.log()
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    fn assert_alive(&mut self) {
        assert!(
            self.child.try_wait().unwrap().is_none(),
            "the watcher died; log:\n{}",
            self.log()
        );
    }

    /// Sends SIGINT and returns the exit status within [`WAIT`].
    fn interrupt(&mut self) -> Option<i32> {
        let pid = self.child.id().to_string();
        assert!(std::process::Command::new("kill")
            .args(["-INT", &pid])
            .status()
            .unwrap()
            .success());
        let start = Instant::now();
        while start.elapsed() < WAIT {
            if let Some(status) = self.child.try_wait().unwrap() {
                return status.code();
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        panic!("the watcher ignored SIGINT; log:\n{}", self.log());
    }
}

impl Drop for Watcher {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Lines saying that `name` was processed.
fn done_count(log: &str, name: &str) -> usize {
    log.lines()
        .filter(|l| !l.starts_with("g2tess: error") && l.contains(&format!("{name} -> ")))
        .count()
}

fn report(path: &Path) -> Value {
    std::fs::read(path)
        .ok()
        .and_then(|b| serde_json::from_slice(&b).ok())
        .unwrap_or(Value::Null)
}

/// The triangles of the latest report's record for the input ending in `name`, if any.
fn triangles_out(path: &Path, name: &str) -> Option<u64> {
    report(path)["files"]
        .as_array()?
        .iter()
        .find(|r| r["input"].as_str().is_some_and(|i| i.ends_with(name)))?["triangles_out"]
        .as_u64()
}

/// An 80-triangle asset (the example at level 2), to tell a changed asset from the original.
fn denser(dir: &Path) -> PathBuf {
    let file = dir.join("dense.glb");
    let run = corpus::g2tess()
        .arg(example())
        .args(["--level", "2", "-o"])
        .arg(&file)
        .output()
        .unwrap();
    assert!(run.status.success());
    file
}

fn temp_files(dir: &Path) -> Vec<PathBuf> {
    walkdir::WalkDir::new(dir)
        .into_iter()
        .filter_map(Result::ok)
        .filter(|e| {
            e.file_name().to_string_lossy().starts_with(".g2tess-")
                && e.file_name() != ".g2tess-manifest.json"
        })
        .map(|e| e.into_path())
        .collect()
}

#[test]
fn every_kind_of_change_is_processed_and_sigint_ends_the_watch() {
    let dir = corpus::temp_dir();
    let dense = denser(dir.path());
    let tree = dir.path().join("tree");
    std::fs::create_dir_all(tree.join("sub")).unwrap();
    std::fs::write(tree.join("g2tess.toml"), "level = 2\n").unwrap();
    std::fs::copy(example(), tree.join("a.glb")).unwrap();
    std::fs::copy(example(), tree.join("sub/b.glb")).unwrap();
    // The output folder is inside the watched one: its writes must not be taken for changes.
    let out = tree.join("out");
    let rep = dir.path().join("report.json");
    let mut w = Watcher::start(&[
        tree.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--watch".as_ref(),
        "--delete".as_ref(),
        "--debounce".as_ref(),
        "100".as_ref(),
        "--report".as_ref(),
        rep.as_os_str(),
    ]);
    assert!(out.join("a.glb").is_file() && out.join("sub/b.glb").is_file());
    // Own outputs cause no second round.
    std::thread::sleep(Duration::from_millis(800));
    assert_eq!(done_count(&w.log(), "a.glb"), 1, "{}", w.log());

    // A changed asset.
    std::fs::copy(&dense, tree.join("a.glb")).unwrap();
    w.wait_for("the changed asset", |_| {
        triangles_out(&rep, "a.glb") == Some(80 * 4)
    });

    // A new sidecar.
    std::fs::write(tree.join("a.g2tess.toml"), "level = 3\n").unwrap();
    w.wait_for("the sidecar", |_| {
        triangles_out(&rep, "a.glb") == Some(80 * 9)
    });

    // A changed folder config: the assets below it (a.glb keeps its sidecar's level).
    std::fs::write(tree.join("g2tess.toml"), "level = 1\n").unwrap();
    w.wait_for("the folder config", |_| {
        triangles_out(&rep, "b.glb") == Some(20)
    });

    // A save by temporary file and rename.
    let tmp = tree.join("sub/.n.glb.part");
    std::fs::copy(example(), &tmp).unwrap();
    std::fs::rename(&tmp, tree.join("sub/n.glb")).unwrap();
    w.wait_for("the renamed file", |_| out.join("sub/n.glb").is_file());

    // A broken file is reported and the watch goes on; its fix is processed.
    let n_out_before = std::fs::read(out.join("sub/n.glb")).unwrap();
    std::fs::write(tree.join("sub/n.glb"), b"glTF broken").unwrap();
    let broken = format!("g2tess: error: {}: ", tree.join("sub/n.glb").display());
    w.wait_for("the error", |log| log.contains(&broken));
    w.assert_alive();
    assert_eq!(std::fs::read(out.join("sub/n.glb")).unwrap(), n_out_before);
    std::fs::copy(&dense, tree.join("sub/n.glb")).unwrap();
    w.wait_for("the fix", |_| triangles_out(&rep, "n.glb") == Some(80));

    // A deleted input loses its output (--delete).
    std::fs::remove_file(tree.join("sub/n.glb")).unwrap();
    w.wait_for("the deletion", |_| !out.join("sub/n.glb").exists());

    w.assert_alive();
    assert!(
        !w.log().contains(&format!("{} -> ", out.display())),
        "an output was taken for an input:\n{}",
        w.log()
    );
    assert_eq!(w.interrupt(), Some(0), "{}", w.log());
    assert!(w.log().contains("g2tess: stopped watching"), "{}", w.log());
    assert!(
        temp_files(dir.path()).is_empty(),
        "{:?}",
        temp_files(dir.path())
    );
}

#[test]
fn polling_sees_changes_too() {
    let dir = corpus::temp_dir();
    let dense = denser(dir.path());
    let tree = dir.path().join("tree");
    std::fs::create_dir_all(&tree).unwrap();
    std::fs::copy(example(), tree.join("a.glb")).unwrap();
    let out = dir.path().join("out");
    let rep = dir.path().join("report.json");
    let mut w = Watcher::start(&[
        tree.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--level".as_ref(),
        "1".as_ref(),
        "--watch".as_ref(),
        "--poll".as_ref(),
        "--debounce".as_ref(),
        "100".as_ref(),
        "--report".as_ref(),
        rep.as_os_str(),
    ]);
    std::fs::copy(&dense, tree.join("a.glb")).unwrap();
    w.wait_for("the changed asset", |_| {
        triangles_out(&rep, "a.glb") == Some(80)
    });
    // Without --delete, a deleted input keeps its output.
    std::fs::remove_file(tree.join("a.glb")).unwrap();
    w.wait_for("the deletion note", |log| {
        log.contains("is kept (pass --delete")
    });
    assert!(out.join("a.glb").is_file());
    assert_eq!(w.interrupt(), Some(0), "{}", w.log());
}

#[test]
fn a_broken_input_is_tried_again_only_when_it_or_a_file_it_reads_changes() {
    let dir = corpus::temp_dir();
    let tree = dir.path().join("tree");
    std::fs::create_dir_all(&tree).unwrap();
    std::fs::copy(example(), tree.join("a.glb")).unwrap();
    let out = dir.path().join("out");
    let mut w = Watcher::start(&[
        tree.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--level".as_ref(),
        "1".as_ref(),
        "--watch".as_ref(),
        "-v".as_ref(),
        "--debounce".as_ref(),
        "100".as_ref(),
    ]);
    let broken = format!("g2tess: error: {}: ", tree.join("b.glb").display());
    let errors = |log: &str| log.matches(&broken).count();
    std::fs::write(tree.join("b.glb"), b"garbage").unwrap();
    w.wait_for("the error", |log| errors(log) == 1);
    // Reading it again is no change: no second attempt, and no round at all (under -v a
    // round of the good file would say "up to date, skipped").
    std::thread::sleep(Duration::from_millis(1500));
    assert_eq!(errors(&w.log()), 1, "{}", w.log());
    assert!(!w.log().contains("up to date, skipped"), "{}", w.log());
    // A file it reads (its sidecar) changes: one more attempt.
    std::fs::write(tree.join("b.g2tess.toml"), "level = 2\n").unwrap();
    w.wait_for("the retry", |log| errors(log) == 2);
    std::thread::sleep(Duration::from_millis(1500));
    assert_eq!(errors(&w.log()), 2, "{}", w.log());
    // Fixed: processed.
    std::fs::copy(example(), tree.join("b.glb")).unwrap();
    w.wait_for("the fix", |_| out.join("b.glb").is_file());
    w.assert_alive();
    assert_eq!(w.interrupt(), Some(0), "{}", w.log());
}
