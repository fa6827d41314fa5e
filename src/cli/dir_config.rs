//! Folder settings: a `g2tess.toml` in a folder sets the defaults of the assets below it, the
//! nearest one winning, so that a project keeps its settings in its asset tree.
//!
//! The search goes up from the asset's folder to the folder named on the command line (a file
//! input: its own folder) and no further, so the settings of a run depend only on what it was
//! given. A folder config slots in between `--config` and the flags (see [`Layers`]); sidecars
//! beside each asset are found later, by the pipeline.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use g2tess::options::{ConfigFile, Options};

use super::args::Layers;
use super::scope::{parent_dir, Job};

/// The file name of a folder's settings.
pub const DIR_CONFIG: &str = "g2tess.toml";

/// Resolves each job's options, reading every folder config once.
pub struct DirConfigs<'a> {
    layers: &'a Layers,
    /// Folder → its parsed config (`None`: the folder has none).
    parsed: HashMap<PathBuf, Option<Result<ConfigFile, String>>>,
}

impl<'a> DirConfigs<'a> {
    pub fn new(layers: &'a Layers) -> Self {
        DirConfigs {
            layers,
            parsed: HashMap::new(),
        }
    }

    /// The options of `job`'s asset; the error is a message naming the asset, then the config
    /// file and line (each asset below a broken config fails with it, and the report and the
    /// log say which assets were not processed).
    pub fn options(&mut self, job: &Job) -> Result<Options, String> {
        self.resolve(job)
            .map_err(|e| format!("{}: not processed: {e}", job.input.display()))
    }

    fn resolve(&mut self, job: &Job) -> Result<Options, String> {
        let Some((file, config)) = self.nearest(job)? else {
            return self.layers.resolve(None).map_err(|e| e.to_string());
        };
        let origin = file.display().to_string();
        self.layers
            .resolve(Some((&config, &origin)))
            .map_err(|e| e.to_string())
    }

    fn nearest(&mut self, job: &Job) -> Result<Option<(PathBuf, ConfigFile)>, String> {
        for dir in searched_dirs(job) {
            let found = self
                .parsed
                .entry(dir.clone())
                .or_insert_with(|| read(&dir.join(DIR_CONFIG)));
            if let Some(result) = found {
                return result.clone().map(|c| Some((dir.join(DIR_CONFIG), c)));
            }
        }
        Ok(None)
    }
}

/// The folders searched for `job`'s folder config, nearest first: its asset's folder and each
/// one above it up to its config root.
pub fn searched_dirs(job: &Job) -> Vec<PathBuf> {
    let mut dirs = vec![parent_dir(&job.input).to_path_buf()];
    while let Some(dir) = dirs.last() {
        if *dir == job.config_root || !dir.starts_with(&job.config_root) {
            break;
        }
        dirs.push(parent_dir(dir).to_path_buf());
    }
    dirs
}

fn read(file: &Path) -> Option<Result<ConfigFile, String>> {
    if !file.is_file() {
        return None;
    }
    let shown = file.display().to_string();
    Some(
        std::fs::read_to_string(file)
            .map_err(|e| format!("{shown}: {}", e.to_string().to_lowercase()))
            .and_then(|text| {
                let config = ConfigFile::parse(&text, &shown).map_err(|e| e.to_string())?;
                check_ranges(&config, &text, &shown)?;
                Ok(config)
            }),
    )
}

/// Range-checks the settings a folder config sets on their own, so that an error names the
/// line of the key (a range error found later, once layered, names only the file).
fn check_ranges(config: &ConfigFile, text: &str, shown: &str) -> Result<(), String> {
    let Err(e) = Options::default().overlay(config).validate(shown) else {
        return Ok(());
    };
    let key = e.at.strip_prefix(shown).and_then(|k| k.strip_prefix(": "));
    let line = key.and_then(|key| {
        text.lines().position(|l| {
            l.trim_start()
                .strip_prefix(key)
                .is_some_and(|rest| rest.trim_start().starts_with('='))
        })
    });
    Err(match (key, line) {
        (Some(key), Some(line)) => format!("{shown}:{}: {key}: {}", line + 1, e.what),
        _ => e.to_string(),
    })
}
