//! Declared inputs: every file a run reads for an asset, so that a build system (Make, Ninja,
//! Bazel, Buck2) can know an action's inputs. `--print-inputs` prints them without processing;
//! the depfiles of [`super::depfile`] are written from the same list.
//!
//! Which files an asset reads is decided in one place, [`discover`], from the discovery the run
//! itself uses (the companions named in the asset's JSON, the sidecar naming rule, the folder
//! config search); this module only sorts the answer into what exists and what would be read
//! once created. Paths are kept in the form the run uses them (as given on the command line, or
//! joined below a folder input), so relative inputs give relative, relocatable lists.

use std::path::{Path, PathBuf};

use g2tess::options::Options;
use serde::Serialize;

use super::args::InputsFormat;
use super::dir_config::{searched_dirs, DIR_CONFIG};
use super::manifest::written_files;
use super::scope::Job;

/// What one asset's run reads.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct Reads {
    /// Files read: the asset, every buffer and image file it names (present or not: a missing
    /// one fails the run), its sidecar, its folder config and `--config` when they exist.
    pub reads: Vec<PathBuf>,
    /// Files that are absent but would be read, changing the output, once created: the
    /// sidecar beside the asset, and a `g2tess.toml` in a folder nearer than the one in use.
    pub reads_if_created: Vec<PathBuf>,
}

/// Where the run's own discovery is asked what `job` reads: the one adapter between this module
/// and the knowledge of companions, sidecars and folder configs. `None` when the asset cannot
/// be read (the run would fail on it).
fn discover(job: &Job, options: &Options) -> Option<Discovered> {
    std::fs::File::open(&job.input).ok()?;
    // The asset first, then its buffers and images, then the sidecar it would use.
    let mut files = g2tess::pipeline::files_read(&job.input, options);
    let sidecar = files.pop()?;
    let companions = files.split_off(1);
    Some(Discovered {
        companions,
        sidecar: (sidecar, options.sidecar.is_some()),
        folder_configs: searched_dirs(job)
            .into_iter()
            .map(|d| d.join(DIR_CONFIG))
            .collect(),
    })
}

/// The raw answer of [`discover`].
struct Discovered {
    /// Buffer and image files named by the asset, in document order.
    companions: Vec<PathBuf>,
    /// The sidecar's path, and whether it was named (`--sidecar`: required) or only looked for.
    sidecar: (PathBuf, bool),
    /// The folder configs searched, nearest first; the first that exists is the one used.
    folder_configs: Vec<PathBuf>,
}

impl Reads {
    /// What `job` reads under `options`, with `config` (`--config`) read by every run. The error
    /// names the asset when it cannot be read.
    pub fn of(job: &Job, options: &Options, config: Option<&Path>) -> Result<Reads, String> {
        let found = discover(job, options).ok_or_else(|| {
            format!(
                "{}: cannot be read, so the files it names are unknown",
                job.input.display()
            )
        })?;
        let mut reads = Reads::default();
        reads.reads.push(job.input.clone());
        reads.reads.extend(found.companions);
        let (sidecar, named) = found.sidecar;
        match named || sidecar.is_file() {
            true => reads.reads.push(sidecar),
            false => reads.reads_if_created.push(sidecar),
        }
        for folder_config in found.folder_configs {
            if folder_config.is_file() {
                reads.reads.push(folder_config);
                break;
            }
            reads.reads_if_created.push(folder_config);
        }
        reads.reads.extend(config.map(Path::to_path_buf));
        for path in reads.reads.iter_mut().chain(&mut reads.reads_if_created) {
            *path = without_dot(path);
        }
        dedupe(&mut reads.reads);
        Ok(reads)
    }
}

/// `./a.bin` → `a.bin`: a file beside a bare asset name is named as the user would name it,
/// which is also how a build file names it (Make compares names as written).
fn without_dot(path: &Path) -> PathBuf {
    match path.strip_prefix(".") {
        Ok(rest) if !rest.as_os_str().is_empty() => rest.to_path_buf(),
        _ => path.to_path_buf(),
    }
}

/// Keeps the first of each path.
fn dedupe(paths: &mut Vec<PathBuf>) {
    let mut seen = std::collections::HashSet::new();
    paths.retain(|p| seen.insert(p.clone()));
}

/// One record of `--print-inputs json`.
#[derive(Serialize)]
struct Record<'a> {
    input: &'a Path,
    output: &'a Path,
    #[serde(flatten)]
    reads: &'a Reads,
    /// The files the run writes (a `.gltf`'s `.bin`, the depfile with `--depfile`).
    writes: Vec<PathBuf>,
    /// Why its inputs are unknown, when they are.
    error: Option<&'a str>,
}

/// `--print-inputs`: prints what `jobs` read to stdout; returns whether every job's inputs are
/// known (an unreadable asset or a broken folder config makes it false, named on stderr).
pub fn print(
    jobs: &[Job],
    options: &[Result<Options, String>],
    config: Option<&Path>,
    depfile: bool,
    format: InputsFormat,
) -> bool {
    let results: Vec<Result<Reads, String>> = jobs
        .iter()
        .zip(options)
        .map(|(job, o)| o.clone().and_then(|o| Reads::of(job, &o, config)))
        .collect();
    for e in results.iter().filter_map(|r| r.as_ref().err()) {
        eprintln!("g2tess: error: {e}");
    }
    let text = match format {
        InputsFormat::Lines => {
            let mut all: Vec<PathBuf> = results
                .iter()
                .flatten()
                .flat_map(|r| r.reads.iter().cloned())
                .collect();
            dedupe(&mut all);
            all.iter().map(|p| format!("{}\n", p.display())).collect()
        }
        InputsFormat::Json => {
            let empty = Reads::default();
            let records: Vec<Record> = jobs
                .iter()
                .zip(&results)
                .zip(options)
                .map(|((job, r), o)| {
                    let mut writes = match o {
                        Ok(o) => g2tess::pipeline::files_written(&job.output, o),
                        Err(_) => written_files(&job.output),
                    };
                    // The output first, then the files written beside it.
                    writes.sort_by_key(|w| *w != job.output);
                    if depfile {
                        writes.push(super::depfile::path_for(&job.output));
                    }
                    Record {
                        input: &job.input,
                        output: &job.output,
                        reads: r.as_ref().unwrap_or(&empty),
                        writes,
                        error: r.as_ref().err().map(String::as_str),
                    }
                })
                .collect();
            let doc = serde_json::json!({ "format": 1, "files": records });
            let mut text = serde_json::to_string_pretty(&doc).expect("paths serialize");
            text.push('\n');
            text
        }
    };
    print!("{text}");
    results.iter().all(Result::is_ok)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_leading_dot_folder_is_dropped_and_nothing_else() {
        // Compared as text: `Path` equality would see past some `.` components.
        let w = |s: &str| without_dot(Path::new(s)).to_str().unwrap().to_string();
        assert_eq!(w("./a.bin"), "a.bin");
        assert_eq!(w("./sub/g2tess.toml"), "sub/g2tess.toml");
        assert_eq!(w("../a.bin"), "../a.bin");
        assert_eq!(w("/abs/a.bin"), "/abs/a.bin");
        assert_eq!(w("."), ".");
    }
}
