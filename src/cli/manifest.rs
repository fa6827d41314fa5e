//! Incremental runs: a small manifest beside the outputs (`.g2tess-manifest.json` in the `-o`
//! folder; named output files and outputs beside their inputs have none) records, per output, a
//! hash of everything its input consisted of (the files [`pipeline::files_read`] lists: the
//! asset, its buffer and image files, its sidecar) and a hash of the effective settings, with the size and modification time of each
//! file written. An output is skipped when both hashes and its files are unchanged.
//!
//! Contents are hashed rather than timestamps compared, because checkouts, copies and archive
//! tools set timestamps freely. The manifest is a cache: a missing, foreign or corrupt one only
//! means everything is processed again. It deliberately records nothing about failed files.

use std::collections::BTreeMap;
use std::hash::Hasher as _;
use std::path::{Path, PathBuf};

use g2tess::options::Options;
use g2tess::pipeline;
use serde::{Deserialize, Serialize};

use super::scope::Job;

/// The manifest's file name in each output folder.
pub const MANIFEST_NAME: &str = ".g2tess-manifest.json";
/// Bumped when the format changes; older manifests are ignored.
const FORMAT: u32 = 1;

/// What an output was made from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Fingerprint {
    /// Hash of the asset, its buffer and image files, and its sidecar (or their absence);
    /// empty for a job without a manifest, where nothing reads it.
    pub inputs: String,
    /// Hash of the tool's version and the effective options.
    pub settings: String,
    /// Every file the input consists of (hashed into `inputs` where there is a manifest), as
    /// the asset's path names them (for watching).
    pub files: Vec<PathBuf>,
    /// Each of `files`' size and time just before it was read (`None`: absent).
    pub stamps: Vec<Option<Stamp>>,
    /// Every file the output may consist of.
    pub written: Vec<PathBuf>,
}

impl Fingerprint {
    /// Reads and hashes what `job` is made of under `options` (the files
    /// [`pipeline::files_read`] lists). Never fails: an unreadable file hashes as absent, and
    /// the pipeline reports why it cannot be read.
    ///
    /// Each file's [`Stamp`] is taken before it is read, so that a change made while the job
    /// runs shows as a change afterwards.
    ///
    /// The contents are read only for a job that has a manifest, the one reader of the hash:
    /// a named output file or an output beside its input would otherwise read its whole input
    /// a second time on every run (28 MB for a million triangles) for nothing. Such a job's
    /// `inputs` is empty; its files and stamps (which `--watch` reads) are taken all the same.
    pub fn of(job: &Job, options: &Options) -> Fingerprint {
        let files = pipeline::files_read(&job.input, options);
        let mut stamps = Vec::with_capacity(files.len());
        let mut h = fnv::FnvHasher::default();
        let hashed = job.manifest_dir.is_some();
        for file in &files {
            stamps.push(Stamp::of(file));
            if !hashed {
                continue;
            }
            h.write(file.file_name().unwrap_or_default().as_encoded_bytes());
            match std::fs::read(file).ok().map(|b| hash(&b)) {
                Some(c) => h.write_u64(c),
                None => h.write(b"\0absent"),
            }
        }
        // The report's own figures change the report, not the output: a run with `--report` may
        // skip what a run without it made.
        let mut output_settings = options.clone();
        output_settings.report_figures = false;
        let settings = format!("{} {output_settings:?}", env!("CARGO_PKG_VERSION"));
        Fingerprint {
            inputs: if hashed {
                format!("{:016x}", h.finish())
            } else {
                String::new()
            },
            settings: format!("{:016x}", hash(settings.as_bytes())),
            files,
            stamps,
            written: pipeline::files_written(&job.output, options),
        }
    }
}

fn hash(bytes: &[u8]) -> u64 {
    let mut h = fnv::FnvHasher::default();
    h.write(bytes);
    h.finish()
}

/// One file's size and modification time: enough to notice that someone replaced or removed
/// it, read without opening it (opening a file is itself an event to a watcher).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Stamp {
    pub size: u64,
    pub mtime_ns: u64,
}

impl Stamp {
    pub fn of(file: &Path) -> Option<Stamp> {
        let meta = std::fs::metadata(file).ok()?;
        let mtime = meta
            .modified()
            .ok()?
            .duration_since(std::time::UNIX_EPOCH)
            .ok()?;
        Some(Stamp {
            size: meta.len(),
            mtime_ns: u64::try_from(mtime.as_nanos()).unwrap_or(u64::MAX),
        })
    }
}

/// One output's record.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Entry {
    pub inputs: String,
    pub settings: String,
    /// Every file written (the output, a `.gltf`'s `.bin`), by name relative to the manifest.
    pub outputs: BTreeMap<String, Stamp>,
}

#[derive(Debug, Default, Serialize, Deserialize)]
struct File {
    format: u32,
    files: BTreeMap<String, Entry>,
}

/// The manifests of every output folder of a run.
#[derive(Debug, Default)]
pub struct Manifests {
    folders: BTreeMap<PathBuf, File>,
    dirty: bool,
}

impl Manifests {
    /// Loads the manifest of every folder these jobs write to (absent or unreadable: empty).
    pub fn load(jobs: &[Job]) -> Manifests {
        let mut m = Manifests::default();
        for dir in jobs.iter().filter_map(|j| j.manifest_dir.as_deref()) {
            m.folder(dir);
        }
        m
    }

    fn folder(&mut self, dir: &Path) -> &mut File {
        self.folders.entry(dir.to_path_buf()).or_insert_with(|| {
            std::fs::read(dir.join(MANIFEST_NAME))
                .ok()
                .and_then(|b| serde_json::from_slice::<File>(&b).ok())
                .filter(|f| f.format == FORMAT)
                .unwrap_or_default()
        })
    }

    /// Whether `job`'s outputs on disk were made from exactly `fp`.
    pub fn is_current(&self, job: &Job, fp: &Fingerprint) -> bool {
        let Some(dir) = &job.manifest_dir else {
            return false;
        };
        let Some(entry) = self.folders.get(dir).and_then(|f| f.files.get(&job.key)) else {
            return false;
        };
        entry.inputs == fp.inputs
            && entry.settings == fp.settings
            && !entry.outputs.is_empty()
            && entry
                .outputs
                .iter()
                .all(|(name, stamp)| Stamp::of(&dir.join(name)) == Some(*stamp))
    }

    /// Records the files just written for `job`.
    pub fn record(&mut self, job: &Job, fp: &Fingerprint) {
        let Some(dir) = &job.manifest_dir else {
            return;
        };
        let mut outputs = BTreeMap::new();
        for file in &fp.written {
            // A `.gltf` without binary data has no `.bin`.
            if let Some(stamp) = Stamp::of(file) {
                let name = file
                    .strip_prefix(dir)
                    .unwrap_or(file)
                    .to_string_lossy()
                    .replace(std::path::MAIN_SEPARATOR, "/");
                outputs.insert(name, stamp);
            }
        }
        let entry = Entry {
            inputs: fp.inputs.clone(),
            settings: fp.settings.clone(),
            outputs,
        };
        self.folder(dir).files.insert(job.key.clone(), entry);
        self.dirty = true;
    }

    /// Forgets `job` (its output failed, or its input was deleted).
    pub fn forget(&mut self, job: &Job) {
        let Some(dir) = &job.manifest_dir else {
            return;
        };
        if self.folder(dir).files.remove(&job.key).is_some() {
            self.dirty = true;
        }
    }

    /// Writes every changed manifest atomically; the error names the file.
    pub fn save(&mut self) -> Result<(), String> {
        if !std::mem::take(&mut self.dirty) {
            return Ok(());
        }
        for (dir, file) in &mut self.folders {
            file.format = FORMAT;
            if file.files.is_empty() && !dir.join(MANIFEST_NAME).exists() {
                continue;
            }
            let mut text = serde_json::to_vec_pretty(file).map_err(|e| e.to_string())?;
            text.push(b'\n');
            g2tess::gltf_io::write::atomic_write(&dir.join(MANIFEST_NAME), &text)
                .map_err(|e| e.to_string())?;
        }
        Ok(())
    }
}

/// Every file writing `output` may create under any settings (for telling outputs from
/// inputs, and removing the outputs of a deleted input).
pub fn written_files(output: &Path) -> Vec<PathBuf> {
    let any = g2tess::gltf_io::Compression::new(true);
    let mut files = g2tess::gltf_io::output_files(output, Some(any));
    // `--lod-files` writes one file per level instead.
    for level in 0..g2tess::options::MAX_LOD_LEVELS {
        let path = g2tess::pipeline::lod::level_path(output, level);
        files.extend(g2tess::gltf_io::output_files(&path, Some(any)));
    }
    files
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_job_with_a_manifest_reads_its_input_for_the_hash() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("a.glb");
        std::fs::write(&input, b"not read without a manifest").unwrap();
        let mut job = Job {
            input: input.clone(),
            output: dir.path().join("out/a.glb"),
            config_root: dir.path().into(),
            manifest_dir: None,
            key: "a.glb".into(),
        };
        let options = Options::default();
        let plain = Fingerprint::of(&job, &options);
        assert_eq!(plain.inputs, "");
        // The watcher's stamps are taken either way.
        assert_eq!(plain.files[0], input);
        assert_eq!(plain.stamps[0], Stamp::of(&input));

        job.manifest_dir = Some(dir.path().join("out"));
        let before = Fingerprint::of(&job, &options).inputs;
        assert_eq!(before.len(), 16);
        std::fs::write(&input, b"same size, other bytes!!!!!!").unwrap();
        assert_ne!(Fingerprint::of(&job, &options).inputs, before);
    }

    #[test]
    fn the_hash_is_fnv1a_64() {
        // Published test vector: FNV-1a 64 of "a".
        assert_eq!(hash(b"a"), 0xaf63_dc4c_8601_ec8c);
    }
}
