//! Where the levels of a LOD chain go: into the one document, as coarser meshes on new nodes
//! linked by `MSFT_lod` from every node that shows the mesh, or one document per level
//! (`--lod-files`), and the screen-coverage hints that say when a viewer may switch.
//!
//! It deliberately makes no geometry: the mesh job tessellates every level from one
//! surface set-up, this module only stores what it made.

use std::path::{Path, PathBuf};

use super::error::Error;
use super::mesh_job::MeshOutput;
use super::report::MeshReport;
use super::warning::Warning;
use crate::gltf_io::{self, lod, Document};

/// The screen height, in pixels, the coverage hints are computed for.
pub const COVERAGE_SCREEN_PIXELS: f64 = 1080.0;

/// The `MSFT_screencoverage` values of one mesh's chain, one per level, the finest first.
///
/// Value `k` is the smallest screen coverage (the mesh's bounding-box diagonal as a fraction of
/// the screen's height) at which level `k` is still drawn; below it level `k + 1` is. A level's
/// chord error `e` (its target tolerance, which bounds it) covers `coverage · P · e / D` pixels on a screen of `P` =
/// [`COVERAGE_SCREEN_PIXELS`] pixels for a diagonal `D`, so level `k + 1` takes over once its
/// error is at most one pixel: `value[k] = min(1, D / (P · e[k + 1]))`, kept non-increasing. The
/// last value is 0: the coarsest level is drawn down to nothing, never culled.
pub fn screen_coverage(diagonal: f64, errors: &[f64]) -> Vec<f64> {
    let mut values = Vec::with_capacity(errors.len());
    let mut previous = 1.0f64;
    for next in errors.iter().skip(1) {
        let c = if *next > 0.0 {
            (diagonal / (COVERAGE_SCREEN_PIXELS * next)).min(1.0)
        } else {
            1.0
        };
        previous = previous.min(c);
        values.push(previous);
    }
    if !errors.is_empty() {
        values.push(0.0);
    }
    values
}

/// `dir/robot.glb` → `dir/robot_LOD2.glb`: the file of level `level` under `--lod-files`.
pub fn level_path(output: &Path, level: usize) -> PathBuf {
    let stem = output.file_stem().unwrap_or_default().to_string_lossy();
    let name = match output.extension() {
        Some(ext) => format!("{stem}_LOD{level}.{}", ext.to_string_lossy()),
        None => format!("{stem}_LOD{level}"),
    };
    output.with_file_name(name)
}

/// Stores one mesh's output in `doc`: the finest level in place of its triangle primitives,
/// and, when it has coarser levels, each as a new mesh shown by a new node beside every node
/// that shows the mesh and can carry levels (the report says which could not, and why).
pub fn store_with_msft_lod(
    doc: &mut Document,
    out: MeshOutput,
    asset: &Path,
) -> Result<MeshReport, Error> {
    let located = |e: gltf_io::Error| Error::gltf(asset, e);
    let MeshOutput {
        primitives,
        lods,
        mut report,
        diagonal,
    } = out;
    let mesh = report.mesh;
    for (prim, data) in primitives {
        gltf_io::replace_primitive_owned(doc, mesh, prim, data).map_err(located)?;
    }
    if lods.is_empty() {
        return Ok(report);
    }
    if let Some(first) = report.lod.first_mut() {
        first.mesh = Some(mesh);
    }
    let mut nodes = Vec::new();
    for node in lod::nodes_using(doc, mesh) {
        match lod::why_not_linkable(doc, node) {
            None => nodes.push(node),
            Some(why) => report.warnings.0.push(Warning::LodNodeNotLinked {
                mesh,
                node,
                reason: why.to_string(),
            }),
        }
    }
    if nodes.is_empty() {
        // Coarser meshes no node shows would only be dead weight.
        report.warnings.0.push(Warning::LodNotShown { mesh });
        return Ok(report);
    }
    let mut meshes: Vec<usize> = Vec::with_capacity(lods.len());
    for (k, level) in lods.into_iter().enumerate() {
        let shown = match level {
            Some(level) => {
                let copy = lod::add_mesh_copy(doc, mesh, k + 1).map_err(located)?;
                for (prim, data) in level {
                    gltf_io::replace_primitive_owned(doc, copy, prim, data).map_err(located)?;
                }
                copy
            }
            // The same output as the level before: its node shows that level's mesh.
            None => meshes.last().copied().unwrap_or(mesh),
        };
        if let Some(r) = report.lod.get_mut(k + 1) {
            r.mesh = Some(shown);
        }
        meshes.push(shown);
    }
    // The targets, not the measured errors: the output must not depend on whether a report
    // is written, and each level's error is at most its target, so the hints err towards
    // keeping the finer level.
    let errors: Vec<f64> = report.lod.iter().map(|l| l.figures.tolerance).collect();
    let coverage = screen_coverage(diagonal, &errors);
    for node in nodes {
        lod::link_levels(doc, node, &meshes, &coverage).map_err(located)?;
    }
    Ok(report)
}

/// Stores level `level` of one mesh's output in `doc` (one document of a `--lod-files` run):
/// that level in place of the mesh's triangle primitives, no new meshes or nodes.
pub fn store_level(
    doc: &mut Document,
    out: &mut MeshOutput,
    level: usize,
    asset: &Path,
) -> Result<(), Error> {
    // A level the same as the one before is that level's arrays again; levels are stored
    // finest first, so the arrays are copied while still held and moved out last.
    let repeated = out.lods.get(level).is_some_and(Option::is_none);
    let data = if level == 0 {
        if repeated {
            out.primitives.clone()
        } else {
            std::mem::take(&mut out.primitives)
        }
    } else {
        let mut source = level - 1;
        while source > 0 && out.lods[source].is_none() {
            source -= 1;
        }
        let held = match &mut out.lods[source] {
            Some(held) => held,
            None => &mut out.primitives,
        };
        if repeated {
            held.clone()
        } else {
            std::mem::take(held)
        }
    };
    for (prim, data) in data {
        gltf_io::replace_primitive_owned(doc, out.report.mesh, prim, data)
            .map_err(|e| Error::gltf(asset, e))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn level_files_keep_folder_and_extension() {
        assert_eq!(
            level_path(Path::new("out/robot.smooth.glb"), 2),
            Path::new("out/robot.smooth_LOD2.glb")
        );
        assert_eq!(level_path(Path::new("x.gltf"), 0), Path::new("x_LOD0.gltf"));
    }

    /// One pixel of error decides each switch; the values never rise and the coarsest level is
    /// never culled.
    #[test]
    fn coverage_switches_where_the_next_level_is_one_pixel_off() {
        let c = screen_coverage(1.0, &[0.0001, 0.001, 0.01]);
        assert_eq!(c.len(), 3);
        assert!((c[0] - 1.0 / 1.08).abs() < 1e-12, "{c:?}");
        assert!((c[1] - 1.0 / 10.8).abs() < 1e-12, "{c:?}");
        assert_eq!(c[2], 0.0);
        // A flat mesh (no error at any level) may always show its coarsest level.
        assert_eq!(screen_coverage(1.0, &[0.0, 0.0]), [1.0, 0.0]);
        // Measured errors that do not rise still give non-increasing values.
        let c = screen_coverage(1.0, &[0.01, 0.0001, 0.001]);
        assert!(c.windows(2).all(|w| w[0] >= w[1]), "{c:?}");
    }
}
