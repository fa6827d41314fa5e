//! The example's `build.ninja` and `Makefile` with the real `ninja` and `make`, driven by the
//! depfiles g2tess writes: a first build runs every asset, a second runs none, and an edit to a
//! sidecar, a `.bin` or the folder config (or deleting the sidecar) rebuilds exactly the assets
//! made from it; names with spaces, `#` and `$` are read back from the depfile as written.

use crate::buildsys;
use crate::corpus;

use std::path::{Path, PathBuf};
use std::process::Command;

/// The example in a fresh folder, with the test's g2tess binary at `g2tess/g2tess`.
fn example(dir: &Path) -> PathBuf {
    let root = dir.join("example");
    let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/buildsys/example");
    buildsys::copy_tree(&source, &root);
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_g2tess"), root.join("g2tess/g2tess")).unwrap();
    buildsys::example_assets(&root);
    root
}

/// Runs `tool` in `dir`; returns the outputs it made, sorted (from the `-o OUT` of each g2tess
/// command it printed).
fn built(tool: &Path, dir: &Path, args: &[&str]) -> Vec<String> {
    let out = buildsys::run_ok(Command::new(tool).current_dir(dir).args(args));
    let log = String::from_utf8_lossy(&out.stdout);
    let mut made: Vec<String> = log
        .lines()
        .filter_map(|l| l.split_once(" -o ").map(|(_, rest)| rest))
        .map(|rest| rest.split_whitespace().next().unwrap().to_string())
        .collect();
    made.sort();
    made
}

/// Sets a file's contents and makes sure its time is after every output's, whatever the file
/// system's time resolution.
fn edit(file: &Path, text: &str) {
    std::thread::sleep(std::time::Duration::from_millis(20));
    std::fs::write(file, text).unwrap();
}

/// The edits and what each must rebuild, shared by Ninja and Make.
fn check_edits(tool: &Path, dir: &Path, args: &[&str]) {
    let all = ["out/crate.glb", "out/rock.glb", "out/rock_pn.glb"];
    assert_eq!(built(tool, dir, args), all);
    assert_eq!(
        built(tool, dir, args),
        Vec::<String>::new(),
        "a no-op build ran something"
    );

    edit(&dir.join("assets/crate.g2tess.toml"), "level = 4\n");
    assert_eq!(built(tool, dir, args), ["out/crate.glb"]);

    let bin = std::fs::read(dir.join("assets/crate.bin")).unwrap();
    std::thread::sleep(std::time::Duration::from_millis(20));
    std::fs::write(dir.join("assets/crate.bin"), bin).unwrap();
    assert_eq!(built(tool, dir, args), ["out/crate.glb"]);

    // Every asset of the folder reads its g2tess.toml (rock_pn too: its flags override it).
    edit(&dir.join("assets/g2tess.toml"), "level = 3\n");
    assert_eq!(built(tool, dir, args), all);

    // Deleting a sidecar changes the output: it rebuilds, and the build does not stop.
    std::fs::remove_file(dir.join("assets/crate.g2tess.toml")).unwrap();
    assert_eq!(built(tool, dir, args), ["out/crate.glb"]);
    assert_eq!(built(tool, dir, args), Vec::<String>::new());
}

#[test]
fn ninja_rebuilds_exactly_the_assets_an_edit_touches() {
    let Some(ninja) = buildsys::tool("ninja") else {
        return;
    };
    let tmp = corpus::temp_dir();
    let dir = example(tmp.path());
    // -v prints each command, so the outputs made can be read from it.
    check_edits(&ninja, &dir, &["-v"]);
    // Ninja keeps what the depfiles said in its log: the crate's .bin is among its inputs.
    let deps = buildsys::run_ok(Command::new(&ninja).current_dir(&dir).args([
        "-t",
        "deps",
        "out/crate.glb",
    ]));
    let deps = String::from_utf8_lossy(&deps.stdout);
    assert!(
        deps.contains("assets/crate.bin") && deps.contains("assets/g2tess.toml"),
        "{deps}"
    );
}

#[test]
fn make_rebuilds_exactly_the_assets_an_edit_touches() {
    let Some(make) = buildsys::tool("make") else {
        return;
    };
    let tmp = corpus::temp_dir();
    let dir = example(tmp.path());
    check_edits(&make, &dir, &[]);
}

/// A `.gltf` whose name holds a space, a `#` and (for Ninja) a `$`, with its `.bin` and
/// sidecar, under `dir/lib`.
fn awkward_asset(dir: &Path, name: &str) {
    std::fs::create_dir_all(dir.join("lib")).unwrap();
    buildsys::run_ok(
        corpus::g2tess()
            .current_dir(dir)
            .arg(buildsys::fixture())
            .args(["--level", "1", "-q", "-o"])
            .arg(format!("lib/{name}.gltf")),
    );
    std::fs::write(dir.join(format!("lib/{name}.g2tess.toml")), "level = 2\n").unwrap();
}

/// Builds, builds again, edits the sidecar, then deletes it: 1, 0, 1, 1, 0 runs.
fn check_awkward(tool: &Path, dir: &Path, args: &[&str], sidecar: &str) {
    let runs = |dir: &Path| built(tool, dir, args).len();
    assert_eq!(runs(dir), 1);
    assert_eq!(
        runs(dir),
        0,
        "the escaped depfile was not read back as written"
    );
    edit(&dir.join(sidecar), "level = 3\n");
    assert_eq!(runs(dir), 1, "the sidecar's escaped name was not matched");
    std::fs::remove_file(dir.join(sidecar)).unwrap();
    assert_eq!(runs(dir), 1);
    assert_eq!(runs(dir), 0);
}

#[test]
fn ninja_reads_names_with_spaces_hashes_and_dollars_from_the_depfile() {
    let Some(ninja) = buildsys::tool("ninja") else {
        return;
    };
    let tmp = corpus::temp_dir();
    awkward_asset(tmp.path(), "my crate#2 $x");
    let rule = format!(
        "rule smooth\n  command = {} --quiet --depfile $in -o $out\n  depfile = $out.d\n  deps = gcc\n\
         build out/a$ b#$$.glb: smooth lib/my$ crate#2$ $$x.gltf\n",
        env!("CARGO_BIN_EXE_g2tess")
    );
    std::fs::write(tmp.path().join("build.ninja"), rule).unwrap();
    check_awkward(&ninja, tmp.path(), &["-v"], "lib/my crate#2 $x.g2tess.toml");
}

#[test]
fn make_reads_names_with_spaces_and_hashes_from_the_depfile() {
    let Some(make) = buildsys::tool("make") else {
        return;
    };
    let tmp = corpus::temp_dir();
    awkward_asset(tmp.path(), "my crate#2");
    let rules = format!(
        "out/a\\ b.glb: lib/my\\ crate\\#2.gltf ; {} --quiet --depfile '$<' -o '$@'\n\
         -include out/a\\ b.glb.d\n",
        env!("CARGO_BIN_EXE_g2tess")
    );
    std::fs::write(tmp.path().join("Makefile"), rules).unwrap();
    check_awkward(&make, tmp.path(), &[], "lib/my crate#2.g2tess.toml");
}
