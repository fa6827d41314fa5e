//! Pictures from the command line: `--render` (any files side by side into one PNG) and the
//! previews of a run (`--previews DIR`, and the pictures of `--html-report`).
//!
//! Pictures are drawn after the run from the files on disk, so a run without them does no
//! work for them, and a preview shows exactly what was written.

use std::path::{Path, PathBuf};

use g2tess::gltf_io;
use g2tess::options::Options;
use g2tess::render::{self, MeshEdges, Scene, Settings, Subject};

use super::batch::{Outcome, Status};
use super::scope::Job;

/// Draws `paths` side by side; the first one's edges make the `h` rows. The error names the
/// file.
pub fn draw(paths: &[&Path], options: &Options, settings: &Settings) -> Result<Vec<u8>, String> {
    let (width, height) = render::sheet_size(paths.len(), settings);
    if width.saturating_mul(height) > render::MAX_PIXELS {
        return Err(format!(
            "{}: the picture would be {width} × {height} pixels (expected at most {} million: a smaller --render-size, or fewer views, modes or files)",
            paths.first().map_or(String::new(), |p| p.display().to_string()),
            render::MAX_PIXELS / 1_000_000,
        ));
    }
    let mut scenes = Vec::with_capacity(paths.len());
    let mut edges = None;
    for (k, path) in paths.iter().enumerate() {
        let doc = gltf_io::read(path, &options.read_options()).map_err(|e| e.to_string())?;
        let scene = Scene::from_document(&doc).map_err(|e| format!("{}: {e}", path.display()))?;
        if k == 0 && settings.modes.contains(&render::Mode::H) {
            edges = Some(edge_h(&doc, path, options)?);
        }
        scenes.push(scene);
    }
    let subjects: Vec<Subject> = scenes
        .iter()
        .enumerate()
        .map(|(k, scene)| Subject {
            scene,
            edges: if k == 0 { edges.as_deref() } else { None },
        })
        .collect();
    Ok(render::sheet(&subjects, settings).to_png())
}

/// Every welded edge of `doc` with the h processing would give it: the one place pictures
/// depend on how h is resolved.
fn edge_h(
    doc: &gltf_io::Document,
    path: &Path,
    options: &Options,
) -> Result<Vec<MeshEdges>, String> {
    let resolved =
        g2tess::pipeline::resolved_edges(doc, path, options).map_err(|e| e.to_string())?;
    Ok(resolved
        .iter()
        .map(|r| MeshEdges::from_topology(r.mesh, &r.topo, &r.h))
        .collect())
}

/// `--render`: draws `inputs` (files) into `output` (default: the first input with `.png`);
/// the error is a message naming the file.
pub fn render_command(
    inputs: &[PathBuf],
    output: Option<&Path>,
    options: &Options,
    settings: &Settings,
) -> Result<PathBuf, String> {
    let target = match output {
        Some(o) => o.to_path_buf(),
        None => inputs[0].with_extension("png"),
    };
    let paths: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
    let png = draw(&paths, options, settings)?;
    if let Some(dir) = target.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| {
            format!(
                "{}: cannot create the output folder: {}",
                dir.display(),
                e.to_string().to_lowercase()
            )
        })?;
    }
    gltf_io::write::atomic_write(&target, &png).map_err(|e| e.to_string())?;
    Ok(target)
}

/// Whether a job's files are worth drawing: its output is what the run produced or checked.
fn drawable(outcome: &Outcome) -> bool {
    matches!(
        outcome.status,
        Status::Done | Status::Skipped | Status::Unchanged | Status::Changed
    )
}

/// The picture of every job that has one (input beside output; the input alone when the
/// output is missing), in job order; `None` for jobs that failed or were not started.
/// A picture that cannot be drawn is an error message in its place.
pub fn pictures(
    jobs: &[Job],
    options: &[Result<Options, String>],
    outcomes: &[Outcome],
    settings: &Settings,
) -> Vec<Option<Result<Vec<u8>, String>>> {
    jobs.iter()
        .zip(options)
        .zip(outcomes)
        .map(|((job, options), outcome)| {
            let options = options.as_ref().ok().filter(|_| drawable(outcome))?;
            let mut paths = vec![job.input.as_path()];
            if job.output.is_file() {
                paths.push(job.output.as_path());
            }
            Some(draw(&paths, options, settings))
        })
        .collect()
}

/// Where `--previews DIR` puts a job's picture: its output's name below the output folder
/// (or its file name), with `.png` added.
pub fn preview_path(dir: &Path, job: &Job) -> PathBuf {
    let name = match &job.manifest_dir {
        Some(_) => job.key.clone(),
        None => job
            .output
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default(),
    };
    dir.join(format!("{name}.png"))
}

/// Writes the pictures into `dir`; returns the messages of those that could not be written.
pub fn write_previews(
    dir: &Path,
    jobs: &[Job],
    pictures: &[Option<Result<Vec<u8>, String>>],
) -> Vec<String> {
    let mut errors = Vec::new();
    for (job, picture) in jobs.iter().zip(pictures) {
        match picture {
            Some(Ok(png)) => {
                let path = preview_path(dir, job);
                let written = path
                    .parent()
                    .map_or(Ok(()), std::fs::create_dir_all)
                    .map_err(|e| format!("{}: {}", dir.display(), e.to_string().to_lowercase()))
                    .and_then(|()| {
                        gltf_io::write::atomic_write(&path, png).map_err(|e| e.to_string())
                    });
                if let Err(e) = written {
                    errors.push(e);
                }
            }
            Some(Err(e)) => errors.push(format!("cannot draw the preview: {e}")),
            None => {}
        }
    }
    errors
}
