//! The rules for files, one test each: no `uri` reads outside the asset's folder (`..`, absolute
//! paths, `file:`, links pointing out) unless allowed; never the network; outputs only inside the
//! output folder; a read-only folder or a full disk gives an error and leaves no file; an input is
//! never modified.

use crate::corpus;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use crate::hostile::{run_limited, verdict, write_tetrahedron, Run};

fn g2tess(args: &[&std::ffi::OsStr]) -> Run {
    let run = run_limited(args, None);
    assert_eq!(verdict(&run), None, "{run:?}");
    run
}

fn os(p: &Path) -> &std::ffi::OsStr {
    p.as_os_str()
}

/// Every file under `dir`, relative to it.
fn tree(dir: &Path) -> BTreeSet<PathBuf> {
    crate::hostile::files_under(dir)
}

#[test]
fn parent_dir_uri_is_refused_unless_allowed() {
    let root = corpus::temp_dir();
    let asset_dir = root.path().join("asset");
    std::fs::create_dir(&asset_dir).unwrap();
    let input = write_tetrahedron(
        &asset_dir,
        "t.gltf",
        "../secret.bin",
        Some(Path::new("../secret.bin")),
    );
    let out = root.path().join("out.glb");
    let run = g2tess(&[os(&input), "-o".as_ref(), os(&out)]);
    assert_eq!(run.code, Some(1));
    assert!(
        run.stderr.contains("buffers[0].uri") && run.stderr.contains("leaves the asset's folder"),
        "{}",
        run.stderr
    );
    assert!(!out.exists());
    let run = g2tess(&[
        os(&input),
        "-o".as_ref(),
        os(&out),
        "--allow-outside-uris".as_ref(),
    ]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
}

#[test]
fn absolute_uri_is_refused() {
    let root = corpus::temp_dir();
    let secret = root.path().join("secret.bin");
    let asset_dir = root.path().join("asset");
    std::fs::create_dir(&asset_dir).unwrap();
    let input = write_tetrahedron(
        &asset_dir,
        "t.gltf",
        secret.to_str().unwrap(),
        Some(&secret),
    );
    let run = g2tess(&[os(&input), "-o".as_ref(), os(&root.path().join("o.glb"))]);
    assert_eq!(run.code, Some(1));
    assert!(
        run.stderr.contains("leaves the asset's folder"),
        "{}",
        run.stderr
    );
}

#[test]
fn file_scheme_uri_is_refused() {
    let root = corpus::temp_dir();
    let secret = root.path().join("secret.bin");
    let uri = format!("file://{}", secret.display());
    let input = write_tetrahedron(root.path(), "t.gltf", &uri, Some(&secret));
    let run = g2tess(&[os(&input), "-o".as_ref(), os(&root.path().join("o.glb"))]);
    assert_eq!(run.code, Some(1));
    assert!(run.stderr.contains("file: scheme"), "{}", run.stderr);
}

#[test]
fn link_pointing_out_of_the_folder_is_refused() {
    let root = corpus::temp_dir();
    let asset_dir = root.path().join("asset");
    std::fs::create_dir(&asset_dir).unwrap();
    let input = write_tetrahedron(
        &asset_dir,
        "t.gltf",
        "t.bin",
        Some(Path::new("../secret.bin")),
    );
    std::os::unix::fs::symlink(root.path().join("secret.bin"), asset_dir.join("t.bin")).unwrap();
    let out = root.path().join("o.glb");
    let run = g2tess(&[os(&input), "-o".as_ref(), os(&out)]);
    assert_eq!(run.code, Some(1));
    assert!(
        run.stderr.contains("is a link to") && run.stderr.contains("outside the asset's folder"),
        "{}",
        run.stderr
    );
    assert!(!out.exists());
    // A link that stays inside the folder is an ordinary file name.
    std::fs::remove_file(asset_dir.join("t.bin")).unwrap();
    std::fs::rename(root.path().join("secret.bin"), asset_dir.join("data.bin")).unwrap();
    std::os::unix::fs::symlink("data.bin", asset_dir.join("t.bin")).unwrap();
    let run = g2tess(&[os(&input), "-o".as_ref(), os(&out)]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
}

#[test]
fn image_link_pointing_out_is_refused_when_embedding() {
    let root = corpus::temp_dir();
    let asset_dir = root.path().join("asset");
    std::fs::create_dir(&asset_dir).unwrap();
    let input = write_tetrahedron(&asset_dir, "t.gltf", "t.bin", Some(Path::new("t.bin")));
    let mut json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&input).unwrap()).unwrap();
    json["images"] = serde_json::json!([{"uri": "skin.png"}]);
    std::fs::write(&input, serde_json::to_vec(&json).unwrap()).unwrap();
    std::fs::write(root.path().join("private.png"), b"\x89PNG\r\n\x1a\nsecret").unwrap();
    std::os::unix::fs::symlink(root.path().join("private.png"), asset_dir.join("skin.png"))
        .unwrap();
    let out_dir = root.path().join("out");
    std::fs::create_dir(&out_dir).unwrap();
    let out = out_dir.join("t.glb");
    let run = g2tess(&[os(&input), "-o".as_ref(), os(&out)]);
    assert_eq!(run.code, Some(1), "{}", run.stderr);
    assert!(
        run.stderr.contains("images[0].uri") && run.stderr.contains("outside the asset's folder"),
        "{}",
        run.stderr
    );
    assert!(!out.exists());
}

#[test]
fn network_uris_are_never_fetched() {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    listener.set_nonblocking(true).unwrap();
    let port = listener.local_addr().unwrap().port();
    let root = corpus::temp_dir();
    for scheme in ["http", "https", "ftp"] {
        let uri = format!("{scheme}://127.0.0.1:{port}/t.bin");
        let input = write_tetrahedron(root.path(), "t.gltf", &uri, None);
        let run = g2tess(&[
            os(&input),
            "-o".as_ref(),
            os(&root.path().join("o.glb")),
            "--allow-outside-uris".as_ref(),
        ]);
        assert_eq!(run.code, Some(1));
        assert!(
            run.stderr
                .contains(&format!("{scheme}: scheme, which is never fetched")),
            "{}",
            run.stderr
        );
    }
    assert!(
        listener.accept().is_err(),
        "g2tess connected to the network"
    );
}

#[test]
fn outputs_stay_in_the_output_folder_whatever_the_names_inside() {
    let root = corpus::temp_dir();
    let asset_dir = root.path().join("asset");
    let out_dir = root.path().join("out");
    std::fs::create_dir(&asset_dir).unwrap();
    std::fs::create_dir(&out_dir).unwrap();
    let input = write_tetrahedron(&asset_dir, "t.gltf", "t.bin", Some(Path::new("t.bin")));
    let mut json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&input).unwrap()).unwrap();
    let hostile = "../../escaped/../../../tmp/x";
    json["meshes"][0]["name"] = serde_json::json!(hostile);
    json["nodes"][0]["name"] = serde_json::json!("/etc/escaped");
    json["buffers"][0]["name"] = serde_json::json!(hostile);
    json["images"] =
        serde_json::json!([{"uri": "data:image/png;base64,iVBORw0KGgo=", "name": hostile}]);
    std::fs::write(&input, serde_json::to_vec(&json).unwrap()).unwrap();
    let before = tree(root.path());
    for (out, args) in [
        ("t.gltf", vec![]),
        ("t.glb", vec!["--compress", "--compress-fallback"]),
    ] {
        let mut a = vec![os(&input), "-o".as_ref(), os(&out_dir)];
        let target = out_dir.join(out);
        if out.ends_with(".gltf") {
            a[2] = os(&target);
        }
        a.extend(args.iter().map(std::ffi::OsStr::new));
        let run = g2tess(&a);
        assert_eq!(run.code, Some(0), "{}", run.stderr);
    }
    let after = tree(root.path());
    let new: Vec<_> = after.difference(&before).collect();
    assert!(!new.is_empty());
    for f in &new {
        assert!(
            f.starts_with("out"),
            "wrote {} outside the output folder",
            f.display()
        );
    }
}

#[test]
fn read_only_output_folder_is_an_error_and_leaves_nothing() {
    let root = corpus::temp_dir();
    let input = write_tetrahedron(root.path(), "t.gltf", "t.bin", Some(Path::new("t.bin")));
    let out_dir = root.path().join("ro");
    std::fs::create_dir(&out_dir).unwrap();
    use std::os::unix::fs::PermissionsExt as _;
    std::fs::set_permissions(&out_dir, std::fs::Permissions::from_mode(0o555)).unwrap();
    if std::fs::write(out_dir.join("probe"), b"").is_ok() {
        eprintln!("skipped: running as a user who can write to read-only folders");
        return;
    }
    let run = g2tess(&[os(&input), "-o".as_ref(), os(&out_dir.join("t.glb"))]);
    std::fs::set_permissions(&out_dir, std::fs::Permissions::from_mode(0o755)).unwrap();
    assert_eq!(run.code, Some(1));
    assert!(run.stderr.contains("permission denied"), "{}", run.stderr);
    assert!(tree(&out_dir).is_empty(), "left {:?}", tree(&out_dir));
}

#[test]
fn full_disk_is_an_error_and_keeps_the_previous_output() {
    let root = corpus::temp_dir();
    let input = write_tetrahedron(root.path(), "t.gltf", "t.bin", Some(Path::new("t.bin")));
    let out_dir = root.path().join("out");
    std::fs::create_dir(&out_dir).unwrap();
    let out = out_dir.join("t.glb");
    std::fs::write(&out, b"previous output").unwrap();
    // A file-size limit of 1 KiB stands for a disk that fills up during the write.
    let args = [
        os(&input),
        "-o".as_ref(),
        os(&out),
        "--level".as_ref(),
        "8".as_ref(),
    ];
    let run = run_limited(&args, Some(2));
    assert_eq!(verdict(&run), None, "{run:?}");
    assert_eq!(run.code, Some(1), "{}", run.stderr);
    assert!(run.stderr.contains("file too large"), "{}", run.stderr);
    assert_eq!(std::fs::read(&out).unwrap(), b"previous output");
    assert_eq!(
        tree(&out_dir),
        BTreeSet::from([PathBuf::from("t.glb")]),
        "a partial file was left"
    );
}

#[test]
fn inputs_are_never_modified() {
    let root = corpus::temp_dir();
    let input = write_tetrahedron(root.path(), "a.gltf", "t.bin", Some(Path::new("t.bin")));
    let snapshot = |p: &Path| {
        let m = std::fs::metadata(p).unwrap();
        (std::fs::read(p).unwrap(), m.modified().unwrap())
    };
    let before = [snapshot(&input), snapshot(&root.path().join("t.bin"))];
    // The default output goes beside the input under a new name.
    assert_eq!(g2tess(&[os(&input)]).code, Some(0));
    assert!(root.path().join("a.smooth.gltf").exists());
    // Writing over the input, or over its buffer (t.gltf's .bin is t.bin), is refused.
    for target in ["a.gltf", "t.gltf"] {
        let run = g2tess(&[os(&input), "-o".as_ref(), os(&root.path().join(target))]);
        assert_eq!(run.code, Some(1), "{}", run.stderr);
        assert!(
            run.stderr.contains("would overwrite the input"),
            "{}",
            run.stderr
        );
    }
    let after = [snapshot(&input), snapshot(&root.path().join("t.bin"))];
    assert_eq!(before, after);
}

#[test]
fn full_disk_keeps_the_previous_gltf_and_bin_together() {
    let root = corpus::temp_dir();
    // A small mesh with a large JSON part (40 KB of extras, carried to the output): the `.bin`
    // fits under the file-size limit and the `.gltf` does not, so the `.bin` would be renamed
    // into place first if the two were not replaced as a set.
    let input = crate::hostile::tetrahedron_with_large_json(root.path(), 40_000);
    let out_dir = root.path().join("out");
    let out = out_dir.join("t.gltf");
    let level = |l: &'static str| {
        [
            os(&input),
            "-o".as_ref(),
            os(&out),
            "--level".as_ref(),
            l.as_ref(),
        ]
    };
    assert_eq!(g2tess(&level("1")).code, Some(0));
    let previous = (
        std::fs::read(&out).unwrap(),
        std::fs::read(out_dir.join("t.bin")).unwrap(),
    );
    assert!(previous.1.len() < 20 * 512 && previous.0.len() > 40 * 512);
    // 40 blocks of 512 bytes: the new level-2 `.bin` fits, the `.gltf` does not.
    let run = run_limited(&level("2"), Some(40));
    assert_eq!(verdict(&run), None, "{run:?}");
    assert_eq!(run.code, Some(1), "{}", run.stderr);
    assert!(run.stderr.contains("file too large"), "{}", run.stderr);
    let now = (
        std::fs::read(&out).unwrap(),
        std::fs::read(out_dir.join("t.bin")).unwrap(),
    );
    assert!(
        now == previous,
        "the previous .gltf and .bin were not kept together"
    );
    assert_eq!(
        tree(&out_dir),
        BTreeSet::from([PathBuf::from("t.gltf"), PathBuf::from("t.bin")]),
        "a temporary file was left"
    );
}
