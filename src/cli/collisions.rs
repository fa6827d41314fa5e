//! Refuses a run whose outputs would collide, before anything is written: two inputs whose
//! outputs share a file (not only the main output: a `.gltf`'s `.bin`, a compressed output's
//! `.fallback.bin`), or an output that would replace a file another input of the run reads.
//!
//! Both would otherwise go unnoticed until the results are wrong: the last writer wins (which
//! one depends on the schedule at `-j 2`), or a later input reads what an earlier one wrote.
//! An output replacing its own input's files is the writer's business (refused there unless
//! `--overwrite-input`).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use g2tess::options::Options;
use g2tess::pipeline;

use super::scope::{absolute, Job};

/// Checks the files every job (with its resolved options) would write against each other and
/// against the files every other job reads. The message is a usage error naming the file and
/// both inputs.
pub fn check(jobs: &[Job], options: &[Result<Options, String>]) -> Result<(), String> {
    let mut writers: HashMap<PathBuf, usize> = HashMap::new();
    for (i, (job, opts)) in jobs.iter().zip(options).enumerate() {
        let Ok(opts) = opts else { continue };
        for file in pipeline::files_written(&job.output, opts) {
            match writers.get(&identity(&file)) {
                Some(&first) if first != i => {
                    return Err(format!(
                        "{}: would be written for both {} and {} (expected inputs whose outputs share no file: rename one{})",
                        file.display(),
                        jobs[first].input.display(),
                        job.input.display(),
                        match file.to_string_lossy().ends_with(".fallback.bin") {
                            true => "; a .glb and a .gltf of one name share the fallback buffer's name",
                            false => "",
                        }
                    ));
                }
                _ => {
                    writers.insert(identity(&file), i);
                }
            }
        }
    }
    for (i, (job, opts)) in jobs.iter().zip(options).enumerate() {
        let Ok(opts) = opts else { continue };
        for file in pipeline::files_read(&job.input, opts) {
            if let Some(&w) = writers.get(&identity(&file)).filter(|w| **w != i) {
                return Err(format!(
                    "{}: is read by {} and would be replaced by the output of {} (expected an output folder apart from every file the inputs read)",
                    file.display(),
                    job.input.display(),
                    jobs[w].input.display()
                ));
            }
        }
    }
    Ok(())
}

/// A name for the file at `path` that is the same however the path was spelled: the real path
/// of its folder (links resolved) and its name, or the path made absolute when the folder does
/// not exist yet.
fn identity(path: &Path) -> PathBuf {
    let real_dir = path
        .parent()
        .map(|d| match d.as_os_str().is_empty() {
            true => Path::new("."),
            false => d,
        })
        .and_then(|d| d.canonicalize().ok());
    match (real_dir, path.file_name()) {
        (Some(dir), Some(name)) => dir.join(name),
        _ => absolute(path),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn job(input: &str, output: &str) -> Job {
        Job {
            input: input.into(),
            output: output.into(),
            config_root: ".".into(),
            manifest_dir: None,
            key: String::new(),
        }
    }

    #[test]
    fn a_shared_fallback_buffer_is_refused_naming_both_inputs() {
        let mut compressed = Options::default();
        compressed.compress = true;
        compressed.compress_fallback = true;
        let jobs = [job("in/x.glb", "out/x.glb"), job("in/x.gltf", "out/x.gltf")];
        let opts = [Ok(compressed.clone()), Ok(compressed)];
        let e = check(&jobs, &opts).unwrap_err();
        assert!(
            e.starts_with("out/x.fallback.bin: would be written for both in/x.glb and in/x.gltf"),
            "{e}"
        );
        // Uncompressed, the two outputs share nothing.
        let plain = [Ok(Options::default()), Ok(Options::default())];
        assert_eq!(check(&jobs, &plain), Ok(()));
    }
}
