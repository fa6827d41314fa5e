//! Tolerance runs on the real fixtures: every one that processes at a level also processes to
//! a relative tolerance, with morph targets, skins and attributes carried; the output passes
//! the validator where the input does, is the same at one and two threads, and is smaller than
//! the uniform level its counts are capped at.

use crate::corpus;

use std::path::{Path, PathBuf};

use g2tess::options::Options;
use g2tess::pipeline::process_file;

fn adaptive() -> Options {
    let mut options = Options::default();
    options.relative_tolerance = 0.002;
    options.max_segments = 8;
    options.report_figures = true;
    options
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

#[test]
fn real_fixtures_to_a_tolerance_are_valid_deterministic_and_capped() {
    let Some(root) = corpus::fixtures_real() else {
        println!("fixtures-real not found: skipped");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let names = [
        "Duck",
        "Suzanne",
        "Fox",
        "AnimatedMorphCube",
        "MorphPrimitivesTest",
        "SkinnedCylinder",
        "BoxTextured",
        "MultiPrimCustomAttribute",
    ];
    let mut pairs: Vec<(PathBuf, PathBuf)> = Vec::new();
    for name in names {
        let Some(input) = corpus::gltf_files(&root.join("valid").join(name))
            .into_iter()
            .next()
        else {
            continue;
        };
        let out = |tag: &str| dir.path().join(format!("{name}.{tag}.glb"));
        let one = in_pool(1, || process_file(&input, &out("1"), &adaptive()))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let two = in_pool(2, || process_file(&input, &out("2"), &adaptive())).unwrap();
        assert_eq!(
            std::fs::read(out("1")).unwrap(),
            std::fs::read(out("2")).unwrap(),
            "{name}: bytes differ between 1 and 2 threads"
        );
        assert_eq!(one.triangles_out, two.triangles_out);
        // At most the uniform level of the cap, and every mesh reports its figures.
        assert!(one.triangles_out <= one.triangles_in * 64, "{name}");
        for mesh in &one.meshes {
            let figures = mesh.adaptive.as_ref().expect("adaptive figures");
            assert!(figures.max_segments <= 8, "{name}");
            assert!(figures.chord_error.is_some(), "{name}");
        }
        pairs.push((input, out("1")));
    }
    assert!(pairs.len() >= 6, "only {} fixtures found", pairs.len());
    let inputs: Vec<&Path> = pairs.iter().map(|(i, _)| i.as_path()).collect();
    let outputs: Vec<&Path> = pairs.iter().map(|(_, o)| o.as_path()).collect();
    let (Some(before), Some(after)) = (corpus::validate(&inputs), corpus::validate(&outputs))
    else {
        println!("validator not installed: validation skipped");
        return;
    };
    for (input, output) in &pairs {
        if before[input].errors == 0 {
            assert_eq!(
                after[output].errors,
                0,
                "{}: {:?}",
                input.display(),
                after[output].codes
            );
        }
    }
}

/// Patterns finer than those measured at every output triangle (inner level 12) rest on the
/// lattice model. Near a corner the G² blend's curvature changes on the scale of the distance to
/// it, faster than the lattice sees, and while only the triangles at the corners were measured
/// the output came out over the tolerance at boundary triangles one to eleven steps from them:
/// at 2e-4 the bundled icosahedron 1.004×, Pirate 1.25×, Suzanne 1.64×, PalmTree 1.98× (1.0285×
/// with the triangles within four steps of a corner measured). The measured error of every
/// mesh must be within its tolerance, on files with patterns finer than 12 (so that it is the
/// measurement along the edges that holds it).
#[test]
fn fine_patterns_meet_the_tolerance_along_the_edges_near_corners() {
    let mut options = Options::default();
    options.relative_tolerance = 2e-4;
    options.report_figures = true;
    let mut inputs = vec![Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/icosahedron.glb")];
    match corpus::fixtures_real() {
        Some(root) => {
            for name in ["Suzanne", "Pirate", "PalmTree"] {
                inputs.extend(
                    corpus::gltf_files(&root.join("valid").join(name))
                        .into_iter()
                        .next(),
                );
            }
        }
        None => println!("fixtures-real not found: Suzanne, Pirate and PalmTree skipped"),
    }
    let dir = tempfile::tempdir().unwrap();
    for input in &inputs {
        let name = input.file_name().unwrap().to_string_lossy().to_string();
        let report = process_file(input, &dir.path().join(format!("{name}.glb")), &options)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let mut finest = 0;
        for mesh in &report.meshes {
            let figures = mesh.adaptive.as_ref().expect("adaptive figures");
            let error = figures.chord_error.expect("measured");
            assert!(
                error <= figures.tolerance,
                "{name}: measured {error:e} over the tolerance {:e}",
                figures.tolerance
            );
            finest = finest.max(figures.max_segments);
        }
        assert!(finest > 12, "{name}: no fine pattern");
    }
}

/// The interior of a fine pattern rests on the lattice check at twice its resolution, which
/// holds where the surface is smooth at the scale of two lattice steps. Where stage 1's lattice
/// is rough (its spread adds more than a quarter of the tolerance to the inner error) the model
/// at twice the resolution under-predicted interiors, and such patterns are measured at every
/// output triangle. Before: PalmTree under `--scheme coons` at 5e-4 measured 1.009× its
/// tolerance, 2CylinderEngineDraco at 2e-4 1.24× (1.11× while a pattern found rough only after
/// it was measured was not measured again). Every mesh below the segment cap must meet its
/// tolerance.
#[test]
fn rough_fine_patterns_meet_the_tolerance_inside() {
    let Some(root) = corpus::fixtures_real() else {
        println!("fixtures-real not found: PalmTree and 2CylinderEngineDraco skipped");
        return;
    };
    let mut coons = Options::default();
    coons.relative_tolerance = 5e-4;
    coons.scheme = g2tess::surface::scheme::Scheme::Coons;
    let mut g2 = Options::default();
    g2.relative_tolerance = 2e-4;
    let dir = tempfile::tempdir().unwrap();
    for (name, mut options) in [("PalmTree", coons), ("2CylinderEngineDraco", g2)] {
        options.report_figures = true;
        let input = corpus::gltf_files(&root.join("valid").join(name))
            .into_iter()
            .next()
            .unwrap_or_else(|| panic!("{name}: no glTF file"));
        let report = process_file(&input, &dir.path().join(format!("{name}.glb")), &options)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let mut below_cap = 0;
        for mesh in &report.meshes {
            let figures = mesh.adaptive.as_ref().expect("adaptive figures");
            if figures.max_segments >= options.max_segments {
                continue;
            }
            below_cap += 1;
            let error = figures.chord_error.expect("measured");
            assert!(
                error <= figures.tolerance,
                "{name}: {:?} measured {error:e} over the tolerance {:e}",
                mesh.name,
                figures.tolerance
            );
        }
        assert!(below_cap > 0, "{name}: every mesh at the cap");
    }
}
