//! The Bazel rule of `tests/buildsys/example` with the distribution's Bazel, fully offline: the
//! example builds to the bytes a direct run gives, a second build runs nothing, a copy of the
//! workspace in another folder is served whole from the shared cache (so no action key holds a
//! path of the machine), a sidecar edit runs one action again, a new sidecar runs the targets
//! of its asset, and an undeclared `.bin` is refused by name.

use crate::buildsys;
use crate::corpus;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A workspace with its own output base, sharing `cache` (a disk cache: what a remote cache
/// does, on the local disk).
struct Workspace {
    dir: PathBuf,
    output_base: PathBuf,
    cache: PathBuf,
    bazel: PathBuf,
}

impl Workspace {
    /// Lays out the example in `dir` with the test's g2tess binary as `//g2tess:g2tess`.
    fn new(bazel: &Path, dir: &Path, output_base: &Path, cache: &Path) -> Workspace {
        let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/buildsys/example");
        buildsys::copy_tree(&example, dir);
        std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_g2tess"), dir.join("g2tess/g2tess"))
            .unwrap();
        buildsys::example_assets(dir);
        Workspace {
            dir: dir.to_path_buf(),
            output_base: output_base.to_path_buf(),
            cache: cache.to_path_buf(),
            bazel: bazel.to_path_buf(),
        }
    }

    /// `bazel --batch` (no server left running) with the system's rc file only (it points
    /// Bazel at its installed files), and no user or workspace rc files.
    fn bazel(&self, args: &[&str]) -> Output {
        Command::new(&self.bazel)
            .current_dir(&self.dir)
            .arg("--batch")
            .arg(format!("--output_base={}", self.output_base.display()))
            .args(["--nohome_rc", "--noworkspace_rc"])
            .args(args)
            .output()
            .expect("bazel starts")
    }

    /// Builds `targets` with the shared cache; returns how the actions ran.
    fn build(&self, targets: &[&str]) -> Processes {
        let mut args = vec!["build", "--nosandbox_debug"];
        let cache = format!("--disk_cache={}", self.cache.display());
        args.push(&cache);
        args.extend(targets);
        let out = self.bazel(&args);
        let log = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(out.status.success(), "bazel build failed:\n{log}");
        Processes::of(&log)
    }

    fn expunge(&self) {
        self.bazel(&["clean", "--expunge"]);
    }
}

/// Bazel's "INFO: 7 processes: 3 remote cache hit, 4 internal." line, summed.
#[derive(Debug, Default, PartialEq)]
struct Processes {
    /// Actions whose command ran (sandboxed, local, worker …).
    executed: u32,
    /// Actions served from the cache.
    cached: u32,
}

impl Processes {
    fn of(log: &str) -> Processes {
        let line = log
            .lines()
            .find(|l| l.starts_with("INFO: ") && l.contains(" process"))
            .unwrap_or_else(|| panic!("no process count in:\n{log}"));
        let mut p = Processes::default();
        let Some((_, kinds)) = line.split_once(": ").and_then(|(_, r)| r.split_once(": ")) else {
            return p; // "1 process." with nothing after: no action at all.
        };
        for part in kinds.trim_end_matches('.').split(", ") {
            let (n, kind) = part.split_once(' ').expect("count and kind");
            let n: u32 = n.parse().expect("a count");
            match kind {
                "internal" => {}
                k if k.contains("cache hit") => p.cached += n,
                _ => p.executed += n,
            }
        }
        p
    }
}

#[test]
fn the_process_count_line_is_read() {
    let p = Processes::of("x\nINFO: 7 processes: 3 remote cache hit, 4 internal.\n");
    assert_eq!(
        p,
        Processes {
            executed: 0,
            cached: 3
        }
    );
    let p = Processes::of("INFO: 2 processes: 1 internal, 1 linux-sandbox.\n");
    assert_eq!(
        p,
        Processes {
            executed: 1,
            cached: 0
        }
    );
    assert_eq!(
        Processes::of("INFO: 1 process: 1 internal.\n"),
        Processes::default()
    );
}

#[test]
fn the_example_builds_caches_relocates_and_rebuilds_one_action() {
    let Some(bazel) = buildsys::tool("bazel") else {
        return;
    };
    let tmp = corpus::temp_dir();
    let cache = tmp.path().join("cache");
    let first = Workspace::new(
        &bazel,
        &tmp.path().join("one/ws"),
        &tmp.path().join("one/base"),
        &cache,
    );
    let targets = ["//:rock", "//:crate", "//:rock_pn"];

    // Three assets, three actions.
    assert_eq!(
        first.build(&targets),
        Processes {
            executed: 3,
            cached: 0
        }
    );
    // The rule's settings reach the tool: each output is what a direct run with the same files
    // and flags writes, byte for byte (rock: the folder's level 2; crate: its sidecar's level 3;
    // rock_pn: its own flags).
    for (target, direct) in [
        ("rock", vec!["assets/rock.glb"]),
        ("crate", vec!["assets/crate.gltf"]),
        (
            "rock_pn",
            vec!["assets/rock.glb", "--level", "6", "--scheme", "pn"],
        ),
    ] {
        let expected = tmp.path().join(format!("{target}.direct.glb"));
        buildsys::run_ok(
            corpus::g2tess()
                .current_dir(&first.dir)
                .args(&direct)
                .arg("-o")
                .arg(&expected)
                .arg("-q"),
        );
        let built = first.dir.join(format!("bazel-bin/{target}.glb"));
        assert!(
            std::fs::read(&built).unwrap() == std::fs::read(&expected).unwrap(),
            "{target}: the Bazel output differs from a direct run"
        );
    }

    // Nothing changed: nothing runs, not even a cache lookup.
    assert_eq!(first.build(&targets), Processes::default());

    // The same workspace in another folder, with its own output base: every action is found in
    // the shared cache, so no action key depends on where the workspace is.
    let second = Workspace::new(
        &bazel,
        &tmp.path().join("two/elsewhere/ws"),
        &tmp.path().join("two/base"),
        &cache,
    );
    assert_eq!(
        second.build(&targets),
        Processes {
            executed: 0,
            cached: 3
        }
    );

    // A sidecar edit runs exactly the action of its asset.
    std::fs::write(second.dir.join("assets/crate.g2tess.toml"), "level = 4\n").unwrap();
    assert_eq!(
        second.build(&targets),
        Processes {
            executed: 1,
            cached: 0
        }
    );

    // A sidecar created where there was none is found by the macro's glob: the two targets of
    // that asset run again, the third does not.
    std::fs::write(second.dir.join("assets/rock.g2tess.toml"), "level = 1\n").unwrap();
    assert_eq!(
        second.build(&targets),
        Processes {
            executed: 2,
            cached: 0
        }
    );

    // A target that does not declare the .bin its .gltf names is refused, naming the file.
    let mut build = std::fs::read_to_string(second.dir.join("BUILD")).unwrap();
    build.push_str(
        "\ng2tess_smooth(\n    name = \"crate_undeclared\",\n    src = \"assets/crate.gltf\",\n)\n",
    );
    std::fs::write(second.dir.join("BUILD"), build).unwrap();
    let cache_flag = format!("--disk_cache={}", cache.display());
    let refused = second.bazel(&[
        "build",
        "--nosandbox_debug",
        &cache_flag,
        "//:crate_undeclared",
    ]);
    let log = String::from_utf8_lossy(&refused.stderr);
    assert!(!refused.status.success(), "{log}");
    assert!(
        log.contains("assets/crate.gltf reads files that are not declared")
            && log.contains("  assets/crate.bin"),
        "{log}"
    );

    first.expunge();
    second.expunge();
}
