//! Runs many jobs: a fixed number of files in flight, one bad file never stopping the others,
//! up-to-date outputs skipped, `--check` comparing instead of writing.
//!
//! Files are handed to `-j` worker threads from a shared queue, and the pipeline spreads each
//! file's meshes over the rayon pool. Workers are plain threads rather than rayon tasks on
//! purpose: a rayon worker that waits for its own mesh tasks may steal another file's task, so
//! more files than `-j` (and their memory) could be in flight; here exactly `-j` documents can
//! be. Outputs do not depend on the schedule, and results are reported in job order.

use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::Instant;

use g2tess::options::Options;
use g2tess::pipeline::{self, FileReport};

use super::manifest::{Fingerprint, Manifests};
use super::progress::Progress;
use super::scope::Job;

/// What happened to one job.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Processed and written.
    Done,
    /// Its output was up to date.
    Skipped,
    /// It could not be processed; see the error.
    Failed,
    /// `--check`: the output on disk is what a run would write.
    Unchanged,
    /// `--check`: the output is missing or differs.
    Changed,
    /// Not started: `--fail-fast` or Ctrl-C stopped the run first.
    Cancelled,
}

/// One job's result.
#[derive(Debug, Clone)]
pub struct Outcome {
    pub status: Status,
    /// The message of a failed or changed job, without the `g2tess: error: ` prefix.
    pub error: Option<String>,
    /// The pipeline's report of a processed (or checked) file.
    pub report: Option<FileReport>,
    /// Wall time spent on this job, in seconds.
    pub seconds: f64,
    /// What its input consisted of (absent when its options could not be resolved).
    pub fingerprint: Option<Fingerprint>,
}

impl Outcome {
    fn new(status: Status) -> Outcome {
        Outcome {
            status,
            error: None,
            report: None,
            seconds: 0.0,
            fingerprint: None,
        }
    }

    /// Not started.
    pub fn cancelled() -> Outcome {
        Outcome::new(Status::Cancelled)
    }

    fn failed(error: String) -> Outcome {
        Outcome {
            error: Some(error),
            ..Outcome::new(Status::Failed)
        }
    }

    /// Whether this job makes the exit status 1.
    pub fn is_failure(&self) -> bool {
        matches!(self.status, Status::Failed | Status::Changed)
    }
}

/// How to run.
#[derive(Debug, Clone, Copy)]
pub struct RunSettings {
    /// Files in flight.
    pub jobs: usize,
    /// Process up-to-date outputs too.
    pub force: bool,
    /// Compare instead of writing.
    pub check: bool,
    /// Stop starting files after the first failure.
    pub fail_fast: bool,
}

/// Runs `jobs` (each with its resolved options), reporting each result to `progress` as it
/// comes and recording written outputs in `manifests`. Returns the outcomes in job order.
/// Stops starting new files once `stop` is set.
pub fn run(
    jobs: &[Job],
    options: &[Result<Options, String>],
    manifests: &mut Manifests,
    settings: RunSettings,
    stop: &AtomicBool,
    progress: &Progress,
) -> Vec<Outcome> {
    let next = AtomicUsize::new(0);
    let halt = AtomicBool::new(false);
    let mut outcomes: Vec<Outcome> = vec![Outcome::new(Status::Cancelled); jobs.len()];
    let shared: &Manifests = manifests;
    let (tx, rx) = mpsc::channel::<(usize, Outcome)>();
    let workers = settings.jobs.clamp(1, jobs.len().max(1));
    std::thread::scope(|s| {
        for _ in 0..workers {
            let tx = tx.clone();
            let (next, halt) = (&next, &halt);
            s.spawn(move || loop {
                if stop.load(Ordering::SeqCst) || halt.load(Ordering::SeqCst) {
                    break;
                }
                let i = next.fetch_add(1, Ordering::SeqCst);
                let Some(job) = jobs.get(i) else { break };
                progress.started(job);
                // With one file in flight no other file's task can be stolen, so the file
                // runs on a pool thread: each of its parallel passes then starts on the thread
                // that asks for it, instead of handing the work to the pool and sleeping until
                // it is done (two thread wake-ups a pass, about 40 a run). Measured: 1.0 ms
                // less per run of the bundled icosahedron (5.9 -> 4.8 ms, voluntary context
                // switches 50 -> 22), the same output.
                let outcome = if workers == 1 {
                    rayon::scope(|_| run_one(job, &options[i], shared, settings))
                } else {
                    run_one(job, &options[i], shared, settings)
                };
                if settings.fail_fast && outcome.is_failure() {
                    halt.store(true, Ordering::SeqCst);
                }
                if tx.send((i, outcome)).is_err() {
                    break;
                }
            });
        }
        drop(tx);
        for (i, outcome) in rx {
            progress.finished(&jobs[i], &outcome);
            outcomes[i] = outcome;
        }
    });
    for (job, outcome) in jobs.iter().zip(&outcomes) {
        match (outcome.status, &outcome.fingerprint) {
            (Status::Done, Some(fp)) => manifests.record(job, fp),
            (Status::Failed, _) if !settings.check => manifests.forget(job),
            _ => {}
        }
    }
    outcomes
}

fn run_one(
    job: &Job,
    options: &Result<Options, String>,
    manifests: &Manifests,
    settings: RunSettings,
) -> Outcome {
    let started = Instant::now();
    let options = match options {
        Ok(o) => o,
        Err(e) => return Outcome::failed(e.clone()),
    };
    let fp = Fingerprint::of(job, options);
    let mut outcome = if settings.check {
        check_one(job, options)
    } else if !settings.force && manifests.is_current(job, &fp) {
        Outcome::new(Status::Skipped)
    } else {
        write_one(job, options)
    };
    outcome.seconds = started.elapsed().as_secs_f64();
    outcome.fingerprint = Some(fp);
    outcome
}

fn write_one(job: &Job, options: &Options) -> Outcome {
    if let Err(e) = create_parent(&job.output) {
        return Outcome::failed(e);
    }
    match pipeline::process_file_guarded(&job.input, &job.output, options) {
        Ok(report) => Outcome {
            report: Some(report),
            ..Outcome::new(Status::Done)
        },
        // Stopped by Ctrl-C or SIGTERM between stages: nothing was written.
        Err(pipeline::Error::Cancelled { .. }) => Outcome::new(Status::Cancelled),
        Err(e) => Outcome::failed(e.to_string()),
    }
}

/// Makes the output exactly as a run would, and compares every file it would write with disk
/// as it is produced.
fn check_one(job: &Job, options: &Options) -> Outcome {
    let checked = pipeline::guarded(&job.input, || {
        pipeline::check_file(&job.input, &job.output, options)
    });
    let (report, stale) = match checked {
        Ok(r) => r,
        Err(e) => return Outcome::failed(e.to_string()),
    };
    let (status, error) = match stale {
        None => (Status::Unchanged, None),
        Some(file) => (
            Status::Changed,
            Some(format!(
                "{}: {} (expected what {} gives now; run without --check to update it)",
                file.display(),
                if file.exists() {
                    "out of date"
                } else {
                    "missing"
                },
                job.input.display()
            )),
        ),
    };
    Outcome {
        error,
        report: Some(report),
        ..Outcome::new(status)
    }
}

fn create_parent(output: &Path) -> Result<(), String> {
    let Some(dir) = output.parent().filter(|d| !d.as_os_str().is_empty()) else {
        return Ok(());
    };
    std::fs::create_dir_all(dir).map_err(|e| {
        format!(
            "{}: cannot create the output folder: {}",
            dir.display(),
            e.to_string().to_lowercase()
        )
    })
}

/// The totals of a run, for the summary line and the report.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Summary {
    pub done: usize,
    pub skipped: usize,
    pub failed: usize,
    pub unchanged: usize,
    pub changed: usize,
    pub cancelled: usize,
    pub triangles_in: u64,
    pub triangles_out: u64,
    pub bytes_in: u64,
    pub bytes_out: u64,
    pub seconds: f64,
}

impl Summary {
    pub fn of(outcomes: &[Outcome], started: Instant) -> Summary {
        let mut s = Summary {
            seconds: started.elapsed().as_secs_f64(),
            ..Summary::default()
        };
        for o in outcomes {
            *match o.status {
                Status::Done => &mut s.done,
                Status::Skipped => &mut s.skipped,
                Status::Failed => &mut s.failed,
                Status::Unchanged => &mut s.unchanged,
                Status::Changed => &mut s.changed,
                Status::Cancelled => &mut s.cancelled,
            } += 1;
            if let Some(r) = &o.report {
                s.triangles_in += r.triangles_in as u64;
                s.triangles_out += r.triangles_out as u64;
                s.bytes_in += r.bytes_in;
                s.bytes_out += r.bytes_out;
            }
        }
        s
    }

    /// Whether the exit status must be 1.
    pub fn any_failure(&self) -> bool {
        self.failed > 0 || self.changed > 0
    }
}
