//! The output written as it is produced: byte for byte what the in-memory writer gives (on the
//! real fixtures, `.glb` and `.gltf`, images embedded or not), `--check` exactly as strict as a
//! whole-file comparison (one byte changed in either chunk, a truncated or extended file, a
//! JSON chunk of another length, a missing `.bin`), and a write that fails while the binary
//! chunk is written behind the JSON leaves the previous output and no temporary file.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use g2tess::options::Options;
use g2tess::pipeline;

use crate::corpus;
use crate::hostile::{run_limited, verdict, write_tetrahedron};

use crate::hostile::files_under as tree;

fn level(l: u32) -> Options {
    let mut options = Options::default();
    options.level = l;
    options
}

/// Writes `input` to `output` streamed, and checks every file against the in-memory encoding.
fn assert_streamed_equals_encoded(input: &Path, output: &Path, options: &Options) {
    let encoded = pipeline::encode_file(input, output, options);
    let written = pipeline::process_file(input, output, options);
    let (encoded, written) = match (encoded, written) {
        (Ok((_, files)), Ok(report)) => (files, report),
        (Err(a), Err(b)) => {
            assert_eq!(a.to_string(), b.to_string(), "{}", input.display());
            return;
        }
        (a, b) => panic!(
            "{}: encoded {:?}, written {:?}",
            input.display(),
            a.err(),
            b.err()
        ),
    };
    let total: u64 = encoded.iter().map(|f| f.len()).sum();
    assert_eq!(written.bytes_out, total, "{}", input.display());
    for f in &encoded {
        let on_disk = std::fs::read(&f.path).unwrap();
        assert!(
            on_disk == f.to_bytes(),
            "{} -> {}: streamed bytes differ from the in-memory writer's",
            input.display(),
            f.path.display()
        );
        assert!(f.matches_disk());
    }
    // Nothing is left beside the outputs but the outputs.
    let dir = output.parent().unwrap();
    let names: BTreeSet<PathBuf> = encoded
        .iter()
        .map(|f| f.path.strip_prefix(dir).unwrap().to_path_buf())
        .collect();
    assert_eq!(tree(dir), names, "{}", input.display());
}

#[test]
fn streamed_output_is_byte_identical_to_the_in_memory_writer_on_the_fixtures() {
    let Some(root) = corpus::fixtures_real() else {
        return;
    };
    let files = corpus::gltf_files(&root.join("valid"));
    assert!(files.len() > 20, "the corpus is too small to mean anything");
    for input in &files {
        for ext in ["glb", "gltf"] {
            // Another folder: external images are embedded.
            let dir = corpus::temp_dir();
            let output = dir.path().join(format!("out.{ext}"));
            assert_streamed_equals_encoded(input, &output, &level(2));
        }
    }
}

#[test]
fn streamed_output_beside_the_input_keeps_image_uris() {
    let Some(root) = corpus::fixtures_real() else {
        return;
    };
    let source = root.join("valid/BoxTextured");
    let dir = corpus::temp_dir();
    for entry in std::fs::read_dir(&source).unwrap() {
        let path = entry.unwrap().path();
        if path.is_file() {
            std::fs::copy(&path, dir.path().join(path.file_name().unwrap())).unwrap();
        }
    }
    let input = corpus::gltf_files(dir.path())
        .into_iter()
        .find(|p| p.extension().is_some_and(|e| e == "gltf"))
        .expect("BoxTextured has a .gltf");
    let beside = dir.path().join("smooth.gltf");
    let encoded = pipeline::encode_file(&input, &beside, &level(2)).unwrap().1;
    pipeline::process_file(&input, &beside, &level(2)).unwrap();
    for f in &encoded {
        assert_eq!(std::fs::read(&f.path).unwrap(), f.to_bytes());
    }
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&beside).unwrap()).unwrap();
    assert!(
        json["images"][0]["uri"].is_string(),
        "an image beside the output was embedded: {}",
        json["images"]
    );
}

/// What `--check` says of `output` now.
fn stale(input: &Path, output: &Path) -> Option<PathBuf> {
    pipeline::check_file(input, output, &level(4)).unwrap().1
}

/// Runs `change` on the file at `path`, checks that `--check` names `named`, and restores it.
fn assert_caught(
    input: &Path,
    output: &Path,
    path: &Path,
    named: &Path,
    what: &str,
    change: impl FnOnce(&mut Vec<u8>),
) {
    let before = std::fs::read(path).unwrap();
    let mut bytes = before.clone();
    change(&mut bytes);
    std::fs::write(path, &bytes).unwrap();
    assert_eq!(stale(input, output).as_deref(), Some(named), "{what}");
    std::fs::write(path, &before).unwrap();
    assert_eq!(stale(input, output), None, "{what}: restored");
}

#[test]
fn check_is_as_strict_as_a_whole_file_comparison() {
    let dir = corpus::temp_dir();
    let input = write_tetrahedron(dir.path(), "t.gltf", "t.bin", Some(Path::new("t.bin")));
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();

    let glb = out.join("t.glb");
    assert_eq!(
        stale(&input, &glb).as_deref(),
        Some(glb.as_path()),
        "missing"
    );
    pipeline::process_file(&input, &glb, &level(4)).unwrap();
    let listing = tree(&out);
    assert_eq!(stale(&input, &glb), None);
    let len = std::fs::read(&glb).unwrap().len();
    let json_len = u32::from_le_bytes(std::fs::read(&glb).unwrap()[12..16].try_into().unwrap());
    let bin_start = 20 + json_len as usize + 8;
    assert!(
        bin_start + 100 < len,
        "the binary chunk is too small to test"
    );
    for at in [0, 12, 30, bin_start - 1, bin_start, bin_start + 50, len - 1] {
        assert_caught(&input, &glb, &glb, &glb, &format!("byte {at}"), |b| {
            b[at] ^= 0x20
        });
    }
    assert_caught(&input, &glb, &glb, &glb, "truncated", |b| {
        b.pop();
    });
    assert_caught(&input, &glb, &glb, &glb, "extended", |b| b.push(0));
    assert_caught(&input, &glb, &glb, &glb, "not a glb", |b| {
        *b = b"{}".to_vec()
    });
    // The same binary chunk behind a JSON chunk four spaces longer (a valid GLB that another
    // writer could have made): the binary chunk is compared where this file has it.
    assert_caught(&input, &glb, &glb, &glb, "longer JSON chunk", |b| {
        let json_end = 20 + json_len as usize;
        b.splice(json_end..json_end, *b"    ");
        let (json, total) = (json_len + 4, b.len() as u32);
        b[8..12].copy_from_slice(&total.to_le_bytes());
        b[12..16].copy_from_slice(&json.to_le_bytes());
        g2tess::gltf_io::glb::split(b).expect("still a valid GLB");
    });

    let gltf = out.join("t.gltf");
    let bin = out.join("t.bin");
    pipeline::process_file(&input, &gltf, &level(4)).unwrap();
    assert_eq!(stale(&input, &gltf), None);
    for at in [0, 77, std::fs::read(&bin).unwrap().len() - 1] {
        assert_caught(&input, &gltf, &bin, &bin, &format!(".bin byte {at}"), |b| {
            b[at] ^= 1
        });
    }
    assert_caught(&input, &gltf, &bin, &bin, ".bin truncated", |b| {
        b.pop();
    });
    assert_caught(&input, &gltf, &bin, &bin, ".bin extended", |b| b.push(0));
    assert_caught(&input, &gltf, &gltf, &gltf, ".gltf byte", |b| b[5] ^= 1);
    assert_caught(&input, &gltf, &gltf, &gltf, ".gltf extended", |b| {
        b.push(b' ')
    });
    let kept = std::fs::read(&bin).unwrap();
    std::fs::remove_file(&bin).unwrap();
    assert_eq!(
        stale(&input, &gltf).as_deref(),
        Some(bin.as_path()),
        "missing .bin"
    );
    std::fs::write(&bin, kept).unwrap();
    assert_eq!(stale(&input, &gltf), None);

    // Checking never wrote anything, not even a temporary file.
    let mut expected = listing;
    expected.extend(["t.gltf", "t.bin"].map(PathBuf::from));
    assert_eq!(tree(&out), expected);
}

#[test]
fn a_glb_that_fails_behind_its_json_keeps_the_previous_output() {
    let root = corpus::temp_dir();
    // 20 KB of extras make the JSON chunk large; the level is raised until the binary chunk is
    // larger still. A file-size limit just under the whole .glb then lets the staged binary
    // chunk and the JSON through, and fails while the binary chunk is written behind the JSON.
    let input = crate::hostile::tetrahedron_with_large_json(root.path(), 20_000);
    let out_dir = root.path().join("out");
    std::fs::create_dir(&out_dir).unwrap();
    let out = out_dir.join("t.glb");
    let mut chosen = None;
    for l in [4u32, 8, 16, 32] {
        pipeline::process_file(&input, &out, &level(l)).unwrap();
        let bytes = std::fs::read(&out).unwrap();
        let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        if bytes.len() - json_len > json_len + 4096 {
            chosen = Some((l, bytes, json_len));
            break;
        }
    }
    let (l, full, json_len) = chosen.expect("a level whose binary chunk outweighs the JSON");
    // Write another output first, to see that the failed run keeps it.
    pipeline::process_file(&input, &out, &level(1)).unwrap();
    let previous = std::fs::read(&out).unwrap();
    let blocks = (full.len() as u64 - 1) / 512;
    let bin_len = full.len() - json_len - 28;
    assert!(json_len as u64 + 28 < blocks * 512 && (bin_len as u64) < blocks * 512);
    let l = l.to_string();
    let args = [
        input.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--level".as_ref(),
        l.as_ref(),
    ];
    let run = run_limited(&args, Some(blocks));
    assert_eq!(verdict(&run), None, "{run:?}");
    assert_eq!(run.code, Some(1), "{}", run.stderr);
    assert!(run.stderr.contains("file too large"), "{}", run.stderr);
    assert_eq!(std::fs::read(&out).unwrap(), previous);
    assert_eq!(
        tree(&out_dir),
        BTreeSet::from([PathBuf::from("t.glb")]),
        "a temporary file was left"
    );
}
