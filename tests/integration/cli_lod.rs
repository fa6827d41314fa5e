//! LOD chains end to end: one run writes every level from one surface set-up, as `MSFT_lod`
//! in one file or as one file per level; each level is watertight, meets its tolerance
//! (measured), is coarser than the one before, and is the same at any thread count. Sidecar
//! density keys per asset and per mesh, and their range errors, located.

use crate::corpus;
use crate::gltf_build::{gltf, Prim};
use crate::support;

use std::path::{Path, PathBuf};

use g2tess::gltf_io::{self, ReadOptions};
use g2tess::options::Options;
use g2tess::pipeline::{process_file, FileReport};
use serde_json::Value;

/// A closed cylinder of radius 1 and height 2: a curved side (12 segments, 3 rows) between
/// two flat caps, split at the 90° rim by normals (the crease-angle rule makes the rims
/// creases). Flat and curved parts in one mesh, so levels differ where the surface curves.
fn cylinder() -> Prim {
    const AROUND: usize = 12;
    const ROWS: usize = 3;
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut indices = Vec::new();
    let ring = |k: usize| {
        let a = std::f32::consts::TAU * k as f32 / AROUND as f32;
        (a.cos(), a.sin())
    };
    // Side: (ROWS + 1) rings of AROUND vertices.
    for r in 0..=ROWS {
        let z = -1.0 + 2.0 * r as f32 / ROWS as f32;
        for k in 0..AROUND {
            let (x, y) = ring(k);
            positions.push([x, y, z]);
            normals.push([x, y, 0.0]);
        }
    }
    for r in 0..ROWS {
        for k in 0..AROUND {
            let a = (r * AROUND + k) as u32;
            let b = (r * AROUND + (k + 1) % AROUND) as u32;
            let (c, d) = (a + AROUND as u32, b + AROUND as u32);
            indices.extend([a, b, d, a, d, c]);
        }
    }
    // Caps: a centre and a ring each, normals along ±z.
    for (z, up) in [(-1.0f32, false), (1.0, true)] {
        let centre = positions.len() as u32;
        positions.push([0.0, 0.0, z]);
        normals.push([0.0, 0.0, z]);
        for k in 0..AROUND {
            let (x, y) = ring(k);
            positions.push([x, y, z]);
            normals.push([0.0, 0.0, z]);
        }
        for k in 0..AROUND as u32 {
            let (a, b) = (centre + 1 + k, centre + 1 + (k + 1) % AROUND as u32);
            if up {
                indices.extend([centre, a, b]);
            } else {
                indices.extend([centre, b, a]);
            }
        }
    }
    Prim {
        positions,
        normals,
        uvs: None,
        indices,
        extras: None,
    }
}

/// The cylinder asset written into `dir` as `cyl.gltf`.
fn cylinder_asset(dir: &Path) -> PathBuf {
    let path = dir.join("cyl.gltf");
    std::fs::write(&path, gltf("cyl", None, &[cylinder()])).unwrap();
    path
}

/// Tolerances the cylinder reaches under the default cap of 64 segments (at 0.001 its rims,
/// where split normals give each side its own surface, would need more).
const TOLERANCES: [f64; 3] = [0.003, 0.01, 0.04];

fn lod_options() -> Options {
    let mut o = Options::default();
    // Any order: the chain is sorted finest first.
    o.lod = vec![TOLERANCES[1], TOLERANCES[0], TOLERANCES[2]];
    // As `--report` does: the reached error is measured.
    o.report_figures = true;
    o
}

fn json_of(gltf_path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(gltf_path).unwrap()).unwrap()
}

/// (triangles, boundary edges after welding by position) of every triangle primitive of mesh
/// `mesh` in the file at `path`, taken together.
fn mesh_shape(path: &Path, mesh: usize) -> (usize, usize) {
    let doc = gltf_io::read(path, &ReadOptions::default()).unwrap();
    let (mut positions, mut indices) = (Vec::<[f32; 3]>::new(), Vec::<u32>::new());
    for (m, p) in doc.triangle_primitives() {
        if m != mesh {
            continue;
        }
        let data = doc.read_primitive(m, p).unwrap();
        let offset = positions.len() as u32;
        positions.extend(
            data.positions("test")
                .unwrap()
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]]),
        );
        indices.extend(data.indices.iter().map(|i| i + offset));
    }
    (
        indices.len() / 3,
        support::boundary_edges(&positions, &indices),
    )
}

#[test]
fn a_chain_of_three_is_coarser_each_level_within_tolerance_watertight_and_linked() {
    let dir = corpus::temp_dir();
    let input = cylinder_asset(dir.path());
    // Same file names in two folders: the .gltf names its .bin.
    let out = |tag: &str| dir.path().join(tag).join("cyl.gltf");
    for tag in ["1", "2"] {
        std::fs::create_dir_all(dir.path().join(tag)).unwrap();
    }
    let report: FileReport =
        support::in_pool(1, || process_file(&input, &out("1"), &lod_options())).unwrap();
    support::in_pool(2, || process_file(&input, &out("2"), &lod_options())).unwrap();
    for ext in ["gltf", "bin"] {
        let bytes = |tag: &str| std::fs::read(out(tag).with_extension(ext)).unwrap();
        assert!(
            bytes("1") == bytes("2"),
            ".{ext} differs between 1 and 2 threads"
        );
    }

    let levels = &report.meshes[0].lod;
    assert_eq!(levels.len(), 3);
    for (k, level) in levels.iter().enumerate() {
        assert_eq!(level.level, k);
        assert_eq!(level.figures.tolerance, TOLERANCES[k], "finest first");
        let reached = level.figures.chord_error.expect("measured for the report");
        assert!(
            reached <= TOLERANCES[k] * (1.0 + 1e-9),
            "level {k}: chord error {reached} over {}",
            TOLERANCES[k]
        );
        assert!(level.figures.min_angle_degrees > 0.0);
        let mesh = level.mesh.expect("every level linked");
        let (triangles, open) = mesh_shape(&out("1"), mesh);
        assert_eq!(triangles, level.triangles, "level {k}");
        assert_eq!(open, 0, "level {k} has {open} boundary edges");
    }
    assert!(
        levels.windows(2).all(|w| w[0].triangles > w[1].triangles),
        "triangles not strictly decreasing: {:?}",
        levels.iter().map(|l| l.triangles).collect::<Vec<_>>()
    );
    // Every written level counts as output.
    assert_eq!(
        report.triangles_out,
        levels.iter().map(|l| l.triangles).sum::<usize>()
    );

    let json = json_of(&out("1"));
    // The finest level is the mesh the scene's node always showed; the coarser ones hang off
    // it through the extension alone.
    let node = &json["nodes"][0];
    assert_eq!(node["mesh"], 0);
    assert_eq!(levels[0].mesh, Some(0));
    let ids: Vec<u64> = node["extensions"]["MSFT_lod"]["ids"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap())
        .collect();
    assert_eq!(ids.len(), 2);
    for (k, id) in ids.iter().enumerate() {
        let lod_node = &json["nodes"][*id as usize];
        assert_eq!(
            lod_node["mesh"].as_u64().map(|m| m as usize),
            levels[k + 1].mesh
        );
        assert_eq!(lod_node["name"], format!("cyl_LOD{}", k + 1));
        assert_eq!(
            json["meshes"][levels[k + 1].mesh.unwrap()]["name"],
            format!("cyl_LOD{}", k + 1)
        );
    }
    let coverage: Vec<f64> = node["extras"]["MSFT_screencoverage"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(coverage.len(), 3);
    assert!(coverage.windows(2).all(|w| w[0] >= w[1]), "{coverage:?}");
    assert_eq!(coverage[2], 0.0);
    // The rule: level k+1 takes over where its error (at most its target) is one pixel of 1080.
    let diagonal = (4.0f64 + 4.0 + 4.0).sqrt();
    let expected = (diagonal / (1080.0 * TOLERANCES[1])).min(1.0);
    assert!(
        (coverage[0] - expected).abs() < 1e-6 * expected.max(1e-9),
        "{coverage:?} vs {expected}"
    );

    // A loader without the extension: the scene reaches node 0 alone, which shows level 0.
    assert!(json["extensionsUsed"]
        .as_array()
        .unwrap()
        .contains(&Value::from("MSFT_lod")));
    assert!(json.get("extensionsRequired").is_none());
    assert_eq!(json["scenes"][0]["nodes"], serde_json::json!([0]));
    assert!(json["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .all(|n| n.get("children").is_none()));

    // What such a loader sees is exactly a one-level run at the finest tolerance.
    let mut single = Options::default();
    single.tolerance = TOLERANCES[0];
    let one = dir.path().join("one.gltf");
    process_file(&input, &one, &single).unwrap();
    let arrays = |path: &Path| {
        let doc = gltf_io::read(path, &ReadOptions::default()).unwrap();
        let data = doc.read_primitive(0, 0).unwrap();
        (
            data.positions("test").unwrap().to_vec(),
            data.indices.clone(),
        )
    };
    assert!(
        arrays(&one) == arrays(&out("1")),
        "level 0 differs from a one-level run"
    );

    if let Some(verdicts) = corpus::validate(&[out("1").as_path()]) {
        let v = &verdicts[&out("1")];
        assert_eq!(v.errors, 0, "{:?}", v.codes);
        assert!(v.codes.is_empty(), "validator: {:?}", v.codes);
    }
}

/// `--lod-files` writes `<stem>_LOD<k>` per level and nothing under the plain name; the
/// listing of written files, `--check` and the level files agree.
#[test]
fn lod_files_are_named_per_level_and_checked() {
    let dir = corpus::temp_dir();
    let input = cylinder_asset(dir.path());
    let output = dir.path().join("out").join("cyl.glb");
    let run = |extra: &[&str]| {
        corpus::g2tess()
            .arg(&input)
            .arg("-o")
            .arg(&output)
            .args(["--lod", "0.002,0.02", "--lod-files", "--quiet"])
            .args(extra)
            .output()
            .unwrap()
    };
    let listed = run(&["--print-inputs=json"]);
    assert!(
        listed.status.success(),
        "{}",
        String::from_utf8_lossy(&listed.stderr)
    );
    let text = String::from_utf8(listed.stdout).unwrap();
    assert!(
        text.contains("cyl_LOD0.glb") && text.contains("cyl_LOD1.glb"),
        "{text}"
    );

    let done = run(&[]);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let level = |k: usize| dir.path().join("out").join(format!("cyl_LOD{k}.glb"));
    assert!(level(0).is_file() && level(1).is_file());
    assert!(
        !output.exists(),
        "the plain output is not written with --lod-files"
    );
    assert!(!level(2).exists());
    let (fine, open0) = mesh_shape(&level(0), 0);
    let (coarse, open1) = mesh_shape(&level(1), 0);
    assert!(fine > coarse, "{fine} vs {coarse}");
    assert_eq!((open0, open1), (0, 0));
    // Each level file is a plain asset: no extension, the one mesh at its level.
    if let Some(verdicts) = corpus::validate(&[level(0).as_path(), level(1).as_path()]) {
        for (file, v) in &verdicts {
            assert!(
                v.errors == 0 && v.codes.is_empty(),
                "{}: {:?}",
                file.display(),
                v.codes
            );
        }
    }

    // A depfile names every level file as what the run makes.
    assert!(run(&["--depfile", "--force"]).status.success());
    let depfile = std::fs::read_to_string(dir.path().join("out").join("cyl.glb.d")).unwrap();
    let targets = depfile.split(':').next().unwrap();
    assert!(
        targets.contains("cyl_LOD0.glb") && targets.contains("cyl_LOD1.glb"),
        "{depfile}"
    );

    assert!(run(&["--check"]).status.success());
    std::fs::remove_file(level(1)).unwrap();
    let stale = run(&["--check"]);
    assert_eq!(stale.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&stale.stderr).contains("cyl_LOD1.glb"));
}

/// A mesh section's tolerance beats the sidecar's top level, which beats the flags; a section's
/// `level` makes that mesh uniform under an asset tolerance.
#[test]
fn sidecar_density_keys_per_asset_and_per_mesh() {
    let dir = corpus::temp_dir();
    let input = cylinder_asset(dir.path());
    let sidecar = dir.path().join("cyl.g2tess.toml");
    let out = dir.path().join("o.glb");
    let mut flags = Options::default();
    flags.tolerance = 0.1;

    std::fs::write(&sidecar, "tolerance = 0.01\n").unwrap();
    let asset = process_file(&input, &out, &flags).unwrap();
    assert_eq!(asset.meshes[0].adaptive.as_ref().unwrap().tolerance, 0.01);

    std::fs::write(
        &sidecar,
        "tolerance = 0.01\n[mesh.\"cyl\"]\ntolerance = 0.001\n",
    )
    .unwrap();
    let mesh = process_file(&input, &out, &flags).unwrap();
    assert_eq!(mesh.meshes[0].adaptive.as_ref().unwrap().tolerance, 0.001);
    assert!(mesh.triangles_out > asset.triangles_out);

    std::fs::write(&sidecar, "tolerance = 0.01\n[mesh.0]\nlevel = 2\n").unwrap();
    let uniform = process_file(&input, &out, &flags).unwrap();
    assert!(uniform.meshes[0].adaptive.is_none());
    assert_eq!(uniform.triangles_out, uniform.triangles_in * 4);

    std::fs::write(&sidecar, "relative_tolerance = 0.001\nmax_segments = 3\n").unwrap();
    let capped = process_file(&input, &out, &flags).unwrap();
    assert!(capped.meshes[0].adaptive.as_ref().unwrap().max_segments <= 3);
}

/// Under a LOD chain the sidecar's density keys apply to every level as to one: a block that
/// decides its mesh's density (here a section's `level`, then the top level's tolerance) fixes
/// it at every level, written once; `max_segments` alone leaves the chain's levels.
#[test]
fn sidecar_density_keys_under_a_lod_chain() {
    let dir = corpus::temp_dir();
    let input = cylinder_asset(dir.path());
    let sidecar = dir.path().join("cyl.g2tess.toml");
    let out = dir.path().join("o.gltf");

    std::fs::write(&sidecar, "[mesh.\"cyl\"]\nlevel = 2\n").unwrap();
    let report = process_file(&input, &out, &lod_options()).unwrap();
    let levels = &report.meshes[0].lod;
    assert_eq!(levels.len(), 3);
    for level in levels {
        assert_eq!(level.triangles, report.triangles_in * 4, "{levels:?}");
    }
    // One mesh in the file: the coarser levels' nodes show the finest level's mesh.
    let json = json_of(&out);
    assert_eq!(json["meshes"].as_array().unwrap().len(), 1);
    assert!(levels.iter().all(|l| l.mesh == Some(0)), "{levels:?}");
    assert_eq!(mesh_shape(&out, 0).0, report.triangles_in * 4);

    std::fs::write(&sidecar, "tolerance = 0.02\n").unwrap();
    let report = process_file(&input, &out, &lod_options()).unwrap();
    let levels = &report.meshes[0].lod;
    assert_eq!(levels.len(), 3);
    for level in levels {
        assert_eq!(level.figures.tolerance, 0.02);
        assert_eq!(level.triangles, levels[0].triangles);
        assert!(level.figures.chord_error.unwrap() <= 0.02 * (1.0 + 1e-9));
    }

    std::fs::write(&sidecar, "max_segments = 64\n").unwrap();
    let report = process_file(&input, &out, &lod_options()).unwrap();
    let levels = &report.meshes[0].lod;
    let tolerances: Vec<f64> = levels.iter().map(|l| l.figures.tolerance).collect();
    assert_eq!(tolerances, TOLERANCES);
}

/// `--max-triangles` bounds the sum of a chain's levels (the file holds them all), not each
/// level alone.
#[test]
fn max_triangles_counts_every_level_of_a_chain() {
    let dir = corpus::temp_dir();
    let input = cylinder_asset(dir.path());
    let out = dir.path().join("o.glb");
    let free = process_file(&input, &out, &lod_options()).unwrap();
    let sum: usize = free.meshes[0].lod.iter().map(|l| l.triangles).sum();
    let finest = free.meshes[0].lod[0].triangles;
    assert!(
        sum > finest,
        "the test needs the finest level under the limit"
    );

    let mut options = lod_options();
    options.max_output_triangles = sum as u64;
    let fits = process_file(&input, &out, &options).unwrap();
    assert_eq!(fits.triangles_out, free.triangles_out);

    options.max_output_triangles = sum as u64 - 1;
    let e = process_file(&input, &out, &options)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&format!(
            "levels 0 to 2 of its LOD chain would get {sum} triangles"
        )) && e.contains("--max-triangles"),
        "{e}"
    );
}

#[test]
fn density_and_lod_range_errors_are_located() {
    let dir = corpus::temp_dir();
    let input = cylinder_asset(dir.path());
    let sidecar = dir.path().join("cyl.g2tess.toml");
    let out = dir.path().join("o.glb");
    for (text, needle) in [
        ("tolerance = -1.0\n", "cyl.g2tess.toml:1: tolerance: is -1"),
        (
            "h = 0.1\n[mesh.\"cyl\"]\nrelative_tolerance = 2.0\n",
            "cyl.g2tess.toml:3: relative_tolerance: is 2",
        ),
        (
            "\n[mesh.0]\nmax_segments = 65\n",
            "cyl.g2tess.toml:3: max_segments: is 65 (expected 1 to 64)",
        ),
        ("[mesh.0]\nlevel = 0\n", "cyl.g2tess.toml:2: level"),
        (
            "triangle_budget = -5\n",
            "cyl.g2tess.toml:1: triangle_budget",
        ),
    ] {
        std::fs::write(&sidecar, text).unwrap();
        let e = process_file(&input, &out, &Options::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle), "{text:?}: {e}");
    }
    std::fs::remove_file(&sidecar).unwrap();

    // The LOD lists on the command line and in a folder config.
    for (args, needle) in [
        (vec!["--lod", "0.01,0.01"], "lod: lists 0.01 twice"),
        (vec!["--lod", "0.01,-1"], "lod: level 1 is -1"),
        (
            vec!["--lod-relative", "0.5,1.5"],
            "lod_relative: level 1 is 1.5",
        ),
        (
            vec!["--lod", "0.1", "--lod-budget", "100"],
            "lod_budget: is set with lod",
        ),
        (vec!["--lod-files"], "lod_files: is set without a LOD list"),
    ] {
        let run = corpus::g2tess()
            .arg(&input)
            .arg("-o")
            .arg(&out)
            .args(&args)
            .output()
            .unwrap();
        assert_eq!(run.status.code(), Some(2), "{args:?}");
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
    }
    std::fs::write(dir.path().join("g2tess.toml"), "\nlod_budget = [100, 0]\n").unwrap();
    let run = corpus::g2tess()
        .arg(dir.path())
        .arg("-o")
        .arg(dir.path().join("outs"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains("g2tess.toml:2: lod_budget: level 1 is 0"),
        "{stderr}"
    );
}

/// Real assets: a skinned mesh's levels follow the same skin, morph targets are carried per
/// level, instanced nodes keep their instancing, budgets give decreasing counts, and a node
/// with children is left unlinked with a warning. Validator-clean.
#[test]
fn real_fixtures_skins_morphs_instancing_budgets() {
    let Some(root) = corpus::fixtures_real() else {
        println!("fixtures-real not found: skipped");
        return;
    };
    let dir = corpus::temp_dir();
    let mut written = Vec::new();
    let (mut skinned, mut instanced, mut morphed, mut same_shared) = (0, 0, 0, 0);
    for name in [
        "SkinnedCylinder",
        "AnimatedMorphCube",
        "GpuInstancing",
        "Duck",
    ] {
        let Some(input) = corpus::gltf_files(&root.join("valid").join(name))
            .into_iter()
            .next()
        else {
            continue;
        };
        let mut options = Options::default();
        options.lod_budget = vec![4000, 600];
        options.max_segments = 16;
        let out = dir.path().join(format!("{name}.gltf"));
        let report = process_file(&input, &out, &options).unwrap_or_else(|e| panic!("{name}: {e}"));
        let json = json_of(&out);
        for mesh in &report.meshes {
            let levels = &mesh.lod;
            assert_eq!(levels.len(), 2, "{name}");
            // Never more (a mesh already at its input's triangles, or one under both budgets,
            // gets the same counts twice; the cylinder test asserts strictly fewer).
            assert!(
                levels[0].triangles >= levels[1].triangles,
                "{name}: {} then {}",
                levels[0].triangles,
                levels[1].triangles
            );
            // Within its budget, or at the input's own triangles when the budget is below them.
            let input: usize = mesh.primitives.iter().map(|p| p.triangles_in).sum();
            assert!(levels[1].triangles <= 600.max(input), "{name}");
            // A level with the counts of the one before is written once and shown twice.
            if levels[0].triangles == levels[1].triangles && levels[1].mesh.is_some() {
                assert_eq!(levels[1].mesh, levels[0].mesh, "{name}");
                same_shared += 1;
            }
            let Some(coarse) = levels[1].mesh else {
                assert!(
                    !mesh.warnings.0.is_empty(),
                    "{name}: unlinked without a warning"
                );
                continue;
            };
            let fine = &json["meshes"][mesh.mesh];
            let copy = &json["meshes"][coarse];
            for (p, q) in fine["primitives"]
                .as_array()
                .unwrap()
                .iter()
                .zip(copy["primitives"].as_array().unwrap())
            {
                let targets = |v: &Value| {
                    v.get("targets")
                        .and_then(Value::as_array)
                        .map_or(0, Vec::len)
                };
                assert_eq!(targets(p), targets(q), "{name}: morph targets per level");
                morphed += usize::from(targets(q) > 0);
                assert_eq!(p.get("material"), q.get("material"), "{name}");
            }
            assert_eq!(fine.get("weights"), copy.get("weights"), "{name}");
            for (n, node) in json["nodes"].as_array().unwrap().iter().enumerate() {
                let Some(ids) = node.pointer("/extensions/MSFT_lod/ids") else {
                    continue;
                };
                if node["mesh"].as_u64() != Some(mesh.mesh as u64) {
                    continue;
                }
                let lod_node = &json["nodes"][ids[0].as_u64().unwrap() as usize];
                assert_eq!(lod_node["mesh"].as_u64(), Some(coarse as u64), "{name}");
                skinned += usize::from(lod_node.get("skin").is_some());
                instanced += usize::from(
                    lod_node
                        .pointer("/extensions/EXT_mesh_gpu_instancing")
                        .is_some(),
                );
                for key in [
                    "skin",
                    "translation",
                    "rotation",
                    "scale",
                    "matrix",
                    "weights",
                ] {
                    assert_eq!(node.get(key), lod_node.get(key), "{name}: nodes[{n}].{key}");
                }
                assert_eq!(
                    node.pointer("/extensions/EXT_mesh_gpu_instancing"),
                    lod_node.pointer("/extensions/EXT_mesh_gpu_instancing"),
                    "{name}"
                );
            }
        }
        written.push(out);
    }
    assert_eq!(written.len(), 4, "fixtures missing");
    assert!(
        skinned > 0 && instanced > 0 && morphed > 0,
        "{skinned} {instanced} {morphed}"
    );
    // GpuInstancing's flat plane fits both budgets at the same counts.
    assert!(same_shared > 0, "no level was shared");
    let paths: Vec<&Path> = written.iter().map(PathBuf::as_path).collect();
    if let Some(verdicts) = corpus::validate(&paths) {
        // These inputs are clean: so must every output be, warnings included.
        for (file, v) in &verdicts {
            assert!(
                v.errors == 0 && v.codes.is_empty(),
                "{}: {:?}",
                file.display(),
                v.codes
            );
        }
    }
}

/// `--max-triangles` bounds a file: with per-edge counts, known only once each mesh's surface
/// is built, two meshes that each fit but together do not are refused, whatever the threads.
#[test]
fn max_triangles_bounds_the_whole_file_with_per_edge_counts() {
    let dir = corpus::temp_dir();
    let mut json: Value = serde_json::from_str(&gltf("cyl", None, &[cylinder()])).unwrap();
    let mut twin = json["meshes"][0].clone();
    twin["name"] = Value::from("cyl twin");
    json["meshes"].as_array_mut().unwrap().push(twin);
    json["nodes"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({ "mesh": 1 }));
    let node = json["nodes"].as_array().unwrap().len() - 1;
    json["scenes"][0]["nodes"]
        .as_array_mut()
        .unwrap()
        .push(Value::from(node));
    let input = dir.path().join("twins.gltf");
    std::fs::write(&input, json.to_string()).unwrap();
    let out = dir.path().join("o.glb");
    let mut options = Options::default();
    options.tolerance = TOLERANCES[1];

    let free = process_file(&input, &out, &options).unwrap();
    assert_eq!(free.meshes.len(), 2);
    let of = |m: &g2tess::pipeline::MeshReport| -> usize {
        m.primitives.iter().map(|p| p.triangles_out).sum()
    };
    let each = of(&free.meshes[0]);
    assert_eq!(each, of(&free.meshes[1]));
    let total = free.triangles_out as u64;
    assert_eq!(total, 2 * each as u64);
    assert!(each > 8, "the tolerance must refine the cylinder");

    options.max_output_triangles = total;
    assert_eq!(
        process_file(&input, &out, &options).unwrap().triangles_out,
        free.triangles_out
    );
    options.max_output_triangles = total - 1;
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let e = pool
            .install(|| process_file(&input, &out, &options))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!(
                "its meshes up to mesh 1 would get {total} triangles"
            )) && e.contains("--max-triangles"),
            "{e}"
        );
    }
}
