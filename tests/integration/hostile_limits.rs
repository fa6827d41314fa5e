//! Resource bounds, each checked before the memory it protects is allocated: JSON size and
//! depth, `data:` URI size, accessors and primitives that declare more than the file holds, and
//! an output larger than `--max-triangles` refused with the level that would fit.

use crate::corpus;
use crate::hostile;

use std::path::Path;

use crate::hostile::{mesh_gltf, run_limited, tetrahedron, verdict};
use g2tess::gltf_io::{self, ReadOptions};
use g2tess::options::Options;
use g2tess::pipeline;
use serde_json::{json, Value};

fn tetra_json() -> (Value, Vec<u8>) {
    let (p, i) = tetrahedron();
    mesh_gltf(&p, None, &i, "t.bin")
}

/// The asset as one `.gltf` text with its buffer in a `data:` URI.
fn embedded(mut json: Value, bin: &[u8]) -> Vec<u8> {
    use base64::Engine as _;
    let b64 = base64::engine::general_purpose::STANDARD.encode(bin);
    json["buffers"][0]["uri"] = json!(format!("data:application/octet-stream;base64,{b64}"));
    serde_json::to_vec(&json).unwrap()
}

fn read_error(bytes: &[u8], opts: &ReadOptions) -> String {
    gltf_io::read_bytes(bytes, None, opts)
        .unwrap_err()
        .to_string()
}

#[test]
fn json_larger_than_the_limit_is_refused_before_parsing() {
    let (json, bin) = tetra_json();
    let bytes = embedded(json, &bin);
    let mut opts = ReadOptions::default();
    opts.max_json_bytes = 100;
    let e = read_error(&bytes, &opts);
    assert!(
        e.starts_with("json: is ") && e.contains("(expected at most 100;"),
        "{e}"
    );
}

#[test]
fn deeply_nested_json_is_refused_with_the_limit() {
    let (mut json, bin) = tetra_json();
    let mut deep = json!(1);
    for _ in 0..100 {
        deep = json!([deep]);
    }
    json["extras"] = deep;
    let e = read_error(&embedded(json, &bin), &ReadOptions::default());
    assert!(e.contains("nest deeper than 64 levels"), "{e}");
    // Braces inside strings do not count.
    let (mut json, bin) = tetra_json();
    json["extras"] = json!("[".repeat(1000));
    assert!(gltf_io::read_bytes(&embedded(json, &bin), None, &ReadOptions::default()).is_ok());
}

#[test]
fn data_uri_larger_than_the_limit_is_refused_before_decoding() {
    let (json, bin) = tetra_json();
    let mut opts = ReadOptions::default();
    opts.max_data_uri_bytes = 64;
    let e = read_error(&embedded(json, &bin), &opts);
    assert!(
        e.starts_with("buffers[0].uri: data: uri holds about"),
        "{e}"
    );
    assert!(e.contains("(expected at most 64;"), "{e}");
}

#[test]
fn zero_filled_accessor_declaring_gigabytes_is_refused() {
    // A 300-byte file whose accessor without a bufferView declares 100 million vectors (1.2 GB
    // of zeros): the count is bounded by the data the file holds, not by the machine.
    let (mut json, bin) = tetra_json();
    json["accessors"].as_array_mut().unwrap().push(json!({
        "componentType": 5126, "count": 100_000_000u64, "type": "VEC3"
    }));
    let e = read_error(&embedded(json, &bin), &ReadOptions::default());
    assert!(
        e.starts_with("accessors[2].count: the accessors up to this one decode to 1200000"),
        "{e}"
    );
    assert!(e.contains("over the budget of"), "{e}");
}

#[test]
fn many_primitives_sharing_one_accessor_are_refused_before_decoding() {
    // Every primitive decodes its own copy of the shared arrays: 100 000 references to one
    // accessor are cheap to write and expensive to decode.
    let (mut json, bin) = tetra_json();
    let prim = json["meshes"][0]["primitives"][0].clone();
    json["meshes"][0]["primitives"] = Value::Array(vec![prim; 100_000]);
    let dir = corpus::temp_dir();
    let input = dir.path().join("many.gltf");
    std::fs::write(&input, embedded(json, &bin)).unwrap();
    let mut doc = gltf_io::read(&input, &ReadOptions::default()).unwrap();
    let mut options = Options::default();
    options.max_output_triangles = 1000;
    let e = pipeline::process_document(&mut doc, &input, &options)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("the triangle primitives decode to")
            && e.contains("--max-triangles 1000 allows"),
        "{e}"
    );
}

#[test]
fn output_over_the_cap_names_the_level_that_fits() {
    let dir = corpus::temp_dir();
    let input = hostile::write_tetrahedron(dir.path(), "t.gltf", "t.bin", Some(Path::new("t.bin")));
    let out = dir.path().join("o.glb");
    let args = [
        input.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--level".as_ref(),
        "64".as_ref(),
        "--max-triangles".as_ref(),
        "1000".as_ref(),
    ];
    let run = run_limited(&args, None);
    assert_eq!(verdict(&run), None, "{run:?}");
    assert_eq!(run.code, Some(1));
    let want = "level 64 would produce 16384 triangles from 4 (about 8.0 MiB of memory), over --max-triangles 1000 (expected --level 15 would give 900 triangles";
    assert!(run.stderr.contains(want), "{}", run.stderr);
    assert!(!out.exists());
}

#[test]
fn default_cap_fits_comfortably_in_24_gib() {
    let bytes =
        g2tess::options::DEFAULT_MAX_OUTPUT_TRIANGLES * pipeline::PEAK_BYTES_PER_OUTPUT_TRIANGLE;
    assert!(
        bytes <= 12 << 30,
        "{bytes} bytes is more than half of 24 GiB"
    );
}

#[test]
fn guarded_run_reports_errors_like_the_plain_one() {
    let dir = corpus::temp_dir();
    let missing = dir.path().join("missing.glb");
    let e =
        pipeline::process_file_guarded(&missing, &dir.path().join("o.glb"), &Options::default())
            .unwrap_err();
    assert!(e.to_string().contains("missing.glb"), "{e}");
    let bug = pipeline::Error::internal(&missing, &"index out of bounds");
    assert_eq!(
        bug.to_string(),
        format!("{}: internal error: index out of bounds (this is a bug in g2tess, not in the file; please report it with the file)", missing.display())
    );
}

/// The documented bound of h, 0.3536 (√2/4 rounded up), is accepted from the flag, the
/// `--config` file and a sidecar alike; just above it is refused by each with the same range.
#[test]
fn the_printed_h_bound_is_accepted_by_every_source() {
    let dir = corpus::temp_dir();
    let input = hostile::write_tetrahedron(dir.path(), "t.gltf", "t.bin", Some(Path::new("t.bin")));
    let out = dir.path().join("out.glb");
    let config = dir.path().join("c.toml");
    let sidecar = dir.path().join("s.toml");
    for (h, ok) in [("0.3536", true), ("0.3537", false)] {
        std::fs::write(&config, format!("h = {h}\n")).unwrap();
        std::fs::write(&sidecar, format!("h = {h}\n")).unwrap();
        for extra in [
            vec!["--h", h],
            vec!["--config", config.to_str().unwrap()],
            vec!["--sidecar", sidecar.to_str().unwrap()],
        ] {
            let mut args = vec![input.to_str().unwrap(), "-o", out.to_str().unwrap()];
            args.extend(&extra);
            let run = run_limited(&args, None);
            if ok {
                assert_eq!(run.code, Some(0), "{extra:?}: {}", run.stderr);
            } else {
                assert_ne!(run.code, Some(0), "{extra:?} accepted h = {h}");
                assert!(
                    run.stderr.contains("0 to 0.3536") || run.stderr.contains("[0, 0.3536]"),
                    "{extra:?}: {}",
                    run.stderr
                );
            }
        }
    }
}

/// A sidecar `level` beyond 64 is refused like `--level 65`, not accepted (65–255) or left to an
/// internal assertion (256 and more).
#[test]
fn a_sidecar_level_past_64_is_refused() {
    let dir = corpus::temp_dir();
    let input = hostile::write_tetrahedron(dir.path(), "t.gltf", "t.bin", Some(Path::new("t.bin")));
    let out = dir.path().join("out.glb");
    for level in [65, 255, 256, 100_000] {
        std::fs::write(
            dir.path().join("t.g2tess.toml"),
            format!("level = {level}\n"),
        )
        .unwrap();
        let run = run_limited(&[input.as_os_str(), "-o".as_ref(), out.as_os_str()], None);
        assert_eq!(verdict(&run), None, "{run:?}");
        assert_eq!(run.code, Some(1), "level {level}: {}", run.stderr);
        assert!(
            run.stderr
                .contains(&format!("level must be in [1, 64], got {level}")),
            "{}",
            run.stderr
        );
    }
}

/// One SIGTERM stops the file in flight between its stages: exit status 130 and no output,
/// where it used to finish the file (14.4 million output triangles here) first.
#[test]
fn sigterm_stops_the_file_in_flight() {
    let dir = corpus::temp_dir();
    // A fan of 100 000 triangles at level 12 (14.4 M output triangles).
    let n = 100_000u32;
    let turn = |i: u32| std::f32::consts::TAU * i as f32 / n as f32;
    let mut p = vec![[0.0f32, 0.0, 0.0]];
    p.extend((0..n).map(|i| [turn(i).cos(), turn(i).sin(), 0.3 * (7.0 * turn(i)).sin()]));
    let normals = vec![[0.0f32, 0.0, 1.0]; p.len()];
    let idx: Vec<u32> = (0..n).flat_map(|i| [0, i + 1, (i + 1) % n + 1]).collect();
    let input = hostile::write_mesh(dir.path(), &p, Some(&normals), &idx);
    let output = dir.path().join("out.glb");
    let args = [
        input.as_os_str(),
        "-o".as_ref(),
        output.as_os_str(),
        "--level".as_ref(),
        "12".as_ref(),
    ];
    // The signal must land while the file is in flight, before the poll ahead of its write,
    // whatever this machine's and this build's speed: a whole run is timed first, and the
    // signal sent at a fifth of it, inside the tessellation (a fixed 0.7 s was after the end
    // of a 0.55 s optimized run on a fast machine).
    let clock = std::time::Instant::now();
    let whole = corpus::g2tess().args(args).output().unwrap();
    assert_eq!(whole.status.code(), Some(0), "{whole:?}");
    let fifth = clock.elapsed() / 5;
    std::fs::remove_file(&output).unwrap();
    let child = corpus::g2tess()
        .args(args)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(fifth);
    let killed = std::process::Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(
        !output.exists(),
        "the file in flight was finished: {stderr}"
    );
}
