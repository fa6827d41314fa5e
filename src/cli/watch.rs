//! `--watch`: after the first run, wait for changes and process only what they affect: a changed
//! asset, the asset of a changed sidecar, the assets using a changed buffer or image file, the
//! assets below a changed `g2tess.toml`, the assets of a folder moved in. Outputs of deleted
//! inputs are removed only with `--delete`.
//!
//! Changes arrive from notify through a path-level debouncer (`notify-debouncer-mini`): an
//! editor's save by temporary file and rename shows up as a few paths, and every path is looked
//! at again on disk, so what the events were called does not matter. A file whose size still
//! changes is waited for. The tool's own outputs, temporary files and manifests are never taken
//! for changes, even when the output folder is inside a watched one, and neither is its own
//! reading of a file (notify reports opens): a path counts as changed only when its size or
//! modification time differs from when it was last read, so an input that failed is tried
//! again only once it, or a file it reads, has changed.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use notify::{PollWatcher, RecommendedWatcher, RecursiveMode};
use notify_debouncer_mini::{new_debouncer_opt, Config, DebounceEventResult, Debouncer};

use super::batch::Outcome;
use super::dir_config::DIR_CONFIG;
use super::manifest::{written_files, Manifests, Stamp};
use super::progress::{say, Verbosity};
use super::scope::{absolute, is_asset_name, parent_dir, Job, Scope};
use super::{interrupt, Runner, EXIT_OK, EXIT_USAGE};

/// Longest wait for a file whose size keeps changing before it is processed anyway.
const STABLE_WAIT: Duration = Duration::from_secs(10);
/// Shortest interval between two scans with `--poll` (each one reads every watched file).
const MIN_POLL: Duration = Duration::from_millis(500);
/// Interval between two size checks.
const STABLE_STEP: Duration = Duration::from_millis(100);

/// What wakes the watch loop.
enum Wake {
    Changes(Vec<PathBuf>),
    Error(String),
    Stop,
}

/// Keeps the watcher alive.
#[allow(dead_code)]
enum Watcher {
    Native(Debouncer<RecommendedWatcher>),
    Poll(Debouncer<PollWatcher>),
}

/// How to watch.
#[derive(Debug, Clone, Copy)]
pub struct WatchSettings {
    pub delete: bool,
    pub poll: bool,
    pub debounce: Duration,
}

/// Runs the first round over `jobs`, then watches until Ctrl-C. Returns the exit status.
pub fn run(runner: &Runner, scope: &Scope, jobs: Vec<Job>, settings: WatchSettings) -> i32 {
    let mut manifests = Manifests::load(&jobs);
    let mut state = State::default();
    let outcomes = runner.round(&jobs, &jobs, &mut manifests, true);
    state.learn(&jobs, &outcomes);

    let (tx, rx) = mpsc::channel::<Wake>();
    let stop = tx.clone();
    interrupt::on_stop(move || {
        let _ = stop.send(Wake::Stop);
    });
    if interrupt::requested() {
        return EXIT_OK;
    }
    let _watcher = match start(scope, settings, tx) {
        Ok(w) => w,
        Err(e) => {
            say(&format!("g2tess: error: {e}"));
            return EXIT_USAGE;
        }
    };
    let shown: Vec<String> = scope
        .watched()
        .iter()
        .map(|(p, _)| p.display().to_string())
        .collect();
    if runner.verbosity > Verbosity::Quiet {
        say(&format!(
            "g2tess: watching {} for changes (Ctrl-C to stop)",
            shown.join(", ")
        ));
    }
    while let Ok(wake) = rx.recv() {
        let mut paths = match wake {
            Wake::Stop => break,
            Wake::Error(e) => {
                say(&format!("g2tess: error: watching: {e}"));
                continue;
            }
            Wake::Changes(p) => p,
        };
        // Changes that arrived meanwhile join this round.
        let mut stopping = false;
        while let Ok(more) = rx.try_recv() {
            match more {
                Wake::Changes(p) => paths.extend(p),
                Wake::Stop => stopping = true,
                Wake::Error(e) => say(&format!("g2tess: error: watching: {e}")),
            }
        }
        if stopping || interrupt::requested() {
            break;
        }
        let (changed, deleted) = state.affected(scope, &paths);
        for job in &deleted {
            remove_outputs(runner, job, settings.delete, &mut manifests);
        }
        if !changed.is_empty() {
            wait_until_stable(&changed);
            let context = state.context(&changed);
            let outcomes = runner.round(&changed, &context, &mut manifests, false);
            state.learn(&changed, &outcomes);
        } else if !deleted.is_empty() {
            runner.save(&mut manifests);
        }
        if interrupt::requested() {
            break;
        }
    }
    runner.save(&mut manifests);
    if runner.verbosity > Verbosity::Quiet {
        say("g2tess: stopped watching");
    }
    EXIT_OK
}

/// What the watcher knows between rounds.
#[derive(Default)]
struct State {
    /// Every asset seen, by input path.
    known: BTreeMap<PathBuf, Job>,
    /// A buffer, image or sidecar file (absolute) → the assets made from it: every file
    /// [`g2tess::pipeline::files_read`] lists but the asset, sidecars that do not exist yet
    /// included (so a new sidecar is a change of its asset).
    users: HashMap<PathBuf, BTreeSet<PathBuf>>,
    /// Each path's size and time (absolute; `None`: absent) when it was last read or looked
    /// at. Reading a file is an event too (notify reports opens), so an event on a path whose
    /// stamp is unchanged is the tool's own reading, not a change: without this, every round
    /// would cause the next, and a broken input would be retried forever.
    seen: HashMap<PathBuf, Option<Stamp>>,
}

impl State {
    fn learn(&mut self, jobs: &[Job], outcomes: &[Outcome]) {
        for (job, outcome) in jobs.iter().zip(outcomes) {
            self.known.insert(job.input.clone(), job.clone());
            if let Some(fp) = &outcome.fingerprint {
                for (file, stamp) in fp.files.iter().zip(&fp.stamps) {
                    // Taken just before the job read the file: a later change differs.
                    self.seen.insert(absolute(file), *stamp);
                }
            }
            for file in outcome
                .fingerprint
                .iter()
                .flat_map(|f| f.files.iter().skip(1))
            {
                self.users
                    .entry(absolute(file))
                    .or_default()
                    .insert(job.input.clone());
            }
            // The folder configs the round read (each round reads them afresh).
            for dir in parent_dir(&job.input).ancestors() {
                let config = absolute(&dir.join(DIR_CONFIG));
                self.seen.entry(config).or_insert_with_key(|c| Stamp::of(c));
                if dir == job.config_root || dir.as_os_str().is_empty() {
                    break;
                }
            }
        }
    }

    /// Every job of the run as far as the watcher knows, `changed` included: the files they
    /// write and read must not collide.
    fn context(&self, changed: &[Job]) -> Vec<Job> {
        let mut all = self.known.clone();
        for job in changed {
            all.insert(job.input.clone(), job.clone());
        }
        all.into_values().collect()
    }

    /// Whether `path` differs from when it was last seen (and remembers it as it is now).
    fn is_changed(&mut self, path: &Path) -> bool {
        let now = Stamp::of(path);
        let before = self.seen.insert(absolute(path), now);
        before != Some(now)
    }

    /// The jobs to run again and the jobs whose input is gone, for these changed paths.
    fn affected(&mut self, scope: &Scope, paths: &[PathBuf]) -> (Vec<Job>, Vec<Job>) {
        let mut changed: BTreeMap<PathBuf, Job> = BTreeMap::new();
        let mut deleted: BTreeMap<PathBuf, Job> = BTreeMap::new();
        let add = |jobs: Vec<Job>, into: &mut BTreeMap<PathBuf, Job>| {
            for j in jobs {
                into.insert(j.input.clone(), j);
            }
        };
        for path in paths.iter().filter_map(|p| scope.given_form(p)) {
            if scope.is_own(&path) || !self.is_changed(&path) {
                continue;
            }
            let name = path.file_name().unwrap_or_default().to_string_lossy();
            if let Some(users) = self.users.get(&absolute(&path)) {
                let jobs = users.iter().filter_map(|i| self.known.get(i)).cloned();
                add(jobs.collect(), &mut changed);
            }
            if name == DIR_CONFIG {
                add(scope.jobs_at(parent_dir(&path)), &mut changed);
            } else if path.is_dir() {
                add(scope.jobs_at(&path), &mut changed);
            } else if path.is_file() && is_asset_name(&path) {
                add(scope.job_for(&path).into_iter().collect(), &mut changed);
            } else if !path.exists() {
                // A deleted asset, or a deleted folder of them.
                let gone = self
                    .known
                    .range(path.clone()..)
                    .take_while(|(i, _)| i.starts_with(&path))
                    .filter(|(i, _)| !i.exists())
                    .map(|(_, j)| j.clone());
                add(gone.collect(), &mut deleted);
            }
        }
        for input in deleted.keys() {
            self.known.remove(input);
            changed.remove(input);
        }
        (
            changed.into_values().collect(),
            deleted.into_values().collect(),
        )
    }
}

/// Deletes a deleted input's outputs with `--delete`; says that they were kept otherwise.
fn remove_outputs(runner: &Runner, job: &Job, delete: bool, manifests: &mut Manifests) {
    let input = job.input.display();
    let output = job.output.display();
    if !delete {
        if runner.verbosity > Verbosity::Quiet {
            say(&format!(
                "g2tess: {input} was deleted; {output} is kept (pass --delete to remove it)"
            ));
        }
        return;
    }
    manifests.forget(job);
    for file in written_files(&job.output) {
        match std::fs::remove_file(&file) {
            Ok(()) => {
                if runner.verbosity > Verbosity::Quiet {
                    say(&format!(
                        "g2tess: {input} was deleted; removed {}",
                        file.display()
                    ));
                }
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => say(&format!(
                "g2tess: error: {}: cannot remove: {}",
                file.display(),
                e.to_string().to_lowercase()
            )),
        }
    }
}

/// Waits until no input's size or modification time changes over one step (an exporter may
/// still be writing it), for at most [`STABLE_WAIT`].
fn wait_until_stable(jobs: &[Job]) {
    let stamp = |j: &Job| {
        std::fs::metadata(&j.input)
            .ok()
            .map(|m| (m.len(), m.modified().ok()))
    };
    let deadline = Instant::now() + STABLE_WAIT;
    let mut before: Vec<_> = jobs.iter().map(stamp).collect();
    loop {
        std::thread::sleep(STABLE_STEP);
        let now: Vec<_> = jobs.iter().map(stamp).collect();
        if now == before || Instant::now() >= deadline || interrupt::requested() {
            return;
        }
        before = now;
    }
}

/// Starts notify (or polling) on every watched folder, reporting to `tx`.
fn start(
    scope: &Scope,
    settings: WatchSettings,
    tx: mpsc::Sender<Wake>,
) -> Result<Watcher, String> {
    let handler = move |result: DebounceEventResult| {
        let wake = match result {
            Ok(events) => Wake::Changes(events.into_iter().map(|e| e.path).collect()),
            Err(e) => Wake::Error(e.to_string().to_lowercase()),
        };
        let _ = tx.send(wake);
    };
    // notify's poller keeps modification times in whole seconds, so a save within the second
    // of the last scan would go unseen: with --poll it compares contents too.
    let notify_config = notify::Config::default()
        .with_poll_interval(settings.debounce.max(MIN_POLL))
        .with_compare_contents(settings.poll);
    let config = Config::default()
        .with_timeout(settings.debounce)
        .with_notify_config(notify_config);
    let err = |e: notify::Error| {
        format!(
            "cannot watch for changes: {} (expected a file system with change notifications; pass --poll to poll instead)",
            e.to_string().to_lowercase()
        )
    };
    let mut watcher = match settings.poll {
        true => Watcher::Poll(new_debouncer_opt(config, handler).map_err(err)?),
        false => Watcher::Native(new_debouncer_opt(config, handler).map_err(err)?),
    };
    for (dir, recursive) in scope.watched() {
        let mode = match recursive {
            true => RecursiveMode::Recursive,
            false => RecursiveMode::NonRecursive,
        };
        let at = canonical(&dir);
        let result = match &mut watcher {
            Watcher::Native(d) => d.watcher().watch(&at, mode),
            Watcher::Poll(d) => d.watcher().watch(&at, mode),
        };
        result.map_err(|e| format!("{}: {}", dir.display(), err(e)))?;
    }
    Ok(watcher)
}

/// The form notify reports paths in below a watched folder.
pub fn canonical(dir: &Path) -> PathBuf {
    dir.canonicalize().unwrap_or_else(|_| absolute(dir))
}
