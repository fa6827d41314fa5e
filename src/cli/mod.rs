//! The binary's edge: parses [`args::Args`] once, resolves the settings, plans the jobs
//! ([`scope`]), runs them ([`batch`]) once or on every change ([`watch`]), prints ([`progress`]),
//! writes the JSON report ([`report`]) and chooses the exit status. For build systems it lists
//! what each asset reads ([`declared_inputs`]), writes depfiles ([`depfile`]), keeps one shard
//! of a batch ([`shard`]) and merges shard reports ([`merge_reports`]).
//!
//! It deliberately keeps going after a failed input (the failure shows in the exit status), like
//! any batch tool. Walking folders and watching them happen here, never in the library.

mod args;
mod batch;
mod collisions;
mod declared_inputs;
mod depfile;
mod dir_config;
mod html_report;
mod interrupt;
mod manifest;
mod merge_reports;
mod preview;
mod progress;
mod report;
mod scope;
mod shard;
mod watch;

use std::path::PathBuf;
use std::time::{Duration, Instant};

use clap::Parser;

use batch::{Outcome, RunSettings, Summary};
use dir_config::DirConfigs;
use manifest::Manifests;
use progress::{say, Progress, Verbosity};
use scope::{Job, Scope};

/// Every input processed.
pub const EXIT_OK: i32 = 0;
/// At least one input failed (or, with `--check`, is out of date); the others were processed.
pub const EXIT_SOME_FAILED: i32 = 1;
/// The command line or the configuration is wrong; nothing was processed.
pub const EXIT_USAGE: i32 = 2;
/// Ctrl-C stopped a run before every input was processed.
pub const EXIT_INTERRUPTED: i32 = 130;

/// Default of `--debounce`, in milliseconds.
const DEFAULT_DEBOUNCE_MS: u64 = 200;

/// Runs the command line; returns the exit status.
pub fn run() -> i32 {
    let args = match args::Args::try_parse() {
        Ok(a) => a,
        Err(e) => {
            let code = if e.use_stderr() { EXIT_USAGE } else { EXIT_OK };
            let _ = e.print();
            return code;
        }
    };
    if let Some(out) = &args.merge_reports {
        return merge_reports::run(&args.inputs, out).unwrap_or_else(|e| usage_error(&e));
    }
    let layers = match args.layers() {
        Ok(l) => l,
        Err(e) => return usage_error(&e.to_string()),
    };
    if let Some(sidecar) = args.sidecar.as_deref().filter(|s| !s.is_file()) {
        return usage_error(&format!(
            "{}: --sidecar: no such file (expected a sidecar such as <asset>{})",
            sidecar.display(),
            g2tess::sharpness::SIDECAR_SUFFIX
        ));
    }
    if let Some(mesh) = &args.explain_h {
        return explain_h(&args.inputs, &layers, mesh);
    }
    if args.render {
        return render(&args, &layers);
    }
    let scope = match Scope::new(
        &args.inputs,
        args.output.as_deref(),
        &args.include,
        &args.exclude,
    ) {
        Ok(s) => s,
        Err(e) => return usage_error(&e),
    };
    let (jobs, unreadable) = match scope.jobs() {
        Ok(j) => j,
        Err(e) => return usage_error(&e),
    };
    // A shard may be empty where the inputs are not.
    let found_any = !jobs.is_empty();
    // Collisions are checked over every input found, so that shards cannot write over each
    // other's files either.
    let all_jobs = jobs.clone();
    let jobs = match args.shard {
        Some(shard) => shard.select(jobs),
        None => jobs,
    };
    if let Some(format) = args.print_inputs {
        let mut configs = DirConfigs::new(&layers);
        let options: Vec<_> = jobs.iter().map(|j| configs.options(j)).collect();
        let known = declared_inputs::print(
            &jobs,
            &options,
            args.config.as_deref(),
            args.depfile,
            format,
        );
        return if known { EXIT_OK } else { EXIT_SOME_FAILED };
    }
    if args.jobs == Some(0) {
        return usage_error("command line: jobs: is 0 (expected at least 1)");
    }
    // The pipeline spreads each file's work over rayon's pool, and the file workers are as many
    // as its threads. Without -j, rayon sizes the pool itself (RAYON_NUM_THREADS, else the
    // number of CPUs).
    let _ = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs.unwrap_or(0))
        .build_global();
    let threads = rayon::current_num_threads();
    interrupt::install();

    let verbosity = match (args.quiet, args.verbose) {
        (true, _) => Verbosity::Quiet,
        (_, true) => Verbosity::Verbose,
        _ => Verbosity::Normal,
    };
    for problem in &unreadable {
        if problem.is_error || verbosity > Verbosity::Quiet {
            say(&problem.to_string());
        }
    }
    let unreadable = unreadable.iter().any(|p| p.is_error);
    if !found_any && !unreadable && verbosity > Verbosity::Quiet {
        say("g2tess: no .gltf or .glb file found in the inputs");
    }
    let runner = Runner {
        layers: &layers,
        settings: RunSettings {
            jobs: threads,
            force: args.force,
            check: args.check,
            fail_fast: args.fail_fast,
        },
        verbosity,
        timings: args.timings,
        report: args.report.clone(),
        depfile: args.depfile,
        config: args.config.clone(),
        previews: args.previews.clone(),
        html_report: args.html_report.clone(),
        picture_settings: args.picture_settings(),
        summary_always: args.inputs.len() > 1 || args.inputs.iter().any(|i| i.is_dir()),
        status: std::cell::Cell::new(EXIT_OK),
    };
    if args.watch {
        let settings = watch::WatchSettings {
            delete: args.delete,
            poll: args.poll,
            debounce: Duration::from_millis(args.debounce.unwrap_or(DEFAULT_DEBOUNCE_MS)),
        };
        return watch::run(&runner, &scope, jobs, settings);
    }
    let mut manifests = Manifests::load(&jobs);
    runner.round(&jobs, &all_jobs, &mut manifests, true);
    match unreadable {
        false => runner.status.get(),
        true => runner.status.get().max(EXIT_SOME_FAILED),
    }
}

fn usage_error(message: &str) -> i32 {
    say(&format!("g2tess: error: {message}"));
    EXIT_USAGE
}

/// Runs rounds of jobs with the settings of the command line.
pub struct Runner<'a> {
    layers: &'a args::Layers,
    settings: RunSettings,
    verbosity: Verbosity,
    timings: bool,
    report: Option<PathBuf>,
    /// `--depfile`: write one beside each current output.
    depfile: bool,
    /// `--config`, which every asset's run reads.
    config: Option<PathBuf>,
    /// `--previews DIR`.
    previews: Option<PathBuf>,
    /// `--html-report FILE`.
    html_report: Option<PathBuf>,
    /// What previews and the HTML report draw.
    picture_settings: g2tess::render::Settings,
    /// Print the summary line even for a single file.
    summary_always: bool,
    /// The exit status of the last round.
    status: std::cell::Cell<i32>,
}

impl Runner<'_> {
    /// Processes `jobs` (reading folder configs afresh), prints, saves the manifests, writes
    /// the report; sets [`Runner::status`]. `context` is every job of the run (`jobs` among
    /// them): when the files some of them write collide (see [`collisions`]), nothing is
    /// processed, the status is [`EXIT_USAGE`] and every outcome is `Cancelled`.
    pub fn round(
        &self,
        jobs: &[Job],
        context: &[Job],
        manifests: &mut Manifests,
        first: bool,
    ) -> Vec<Outcome> {
        let started = Instant::now();
        let mut configs = DirConfigs::new(self.layers);
        let options: Vec<_> = jobs.iter().map(|j| configs.options(j)).collect();
        let context_options: Vec<_> = context.iter().map(|j| configs.options(j)).collect();
        if let Err(e) = collisions::check(context, &context_options) {
            self.status.set(usage_error(&e));
            return jobs.iter().map(|_| Outcome::cancelled()).collect();
        }
        let progress = Progress::new(jobs.len(), self.verbosity, self.timings);
        let mut outcomes = batch::run(
            jobs,
            &options,
            manifests,
            self.settings,
            interrupt::flag(),
            &progress,
        );
        if self.depfile {
            depfile::write_all(jobs, &options, &mut outcomes, self.config.as_deref());
        }
        let summary = Summary::of(&outcomes, started);
        let show = self.summary_always && (first || jobs.len() > 1)
            || self.verbosity == Verbosity::Verbose;
        progress.finish(&summary, self.settings.check, show);
        self.save(manifests);
        let mut status = match summary.any_failure() {
            true => EXIT_SOME_FAILED,
            false => EXIT_OK,
        };
        if summary.cancelled > 0 && interrupt::requested() {
            status = EXIT_INTERRUPTED;
        }
        if let Some(file) = &self.report {
            let written =
                report::write(file, jobs, &outcomes, &summary, self.settings.check, status);
            if let Err(e) = written {
                say(&format!("g2tess: error: {e}"));
                status = status.max(EXIT_SOME_FAILED);
            }
        }
        if self.previews.is_some() || self.html_report.is_some() {
            status = status.max(self.pictures(jobs, &options, &outcomes, &summary, status));
        }
        self.status.set(status);
        outcomes
    }

    /// Draws the previews and writes them and the HTML report; returns the exit status their
    /// failures call for.
    fn pictures(
        &self,
        jobs: &[Job],
        options: &[Result<g2tess::options::Options, String>],
        outcomes: &[Outcome],
        summary: &Summary,
        status: i32,
    ) -> i32 {
        let pictures = preview::pictures(jobs, options, outcomes, &self.picture_settings);
        let mut errors = Vec::new();
        if let Some(dir) = &self.previews {
            errors.extend(preview::write_previews(dir, jobs, &pictures));
        }
        if let Some(file) = &self.html_report {
            let run = html_report::Run {
                jobs,
                outcomes,
                summary,
                check: self.settings.check,
                exit_status: status,
                pictures: &pictures,
                settings: &self.picture_settings,
            };
            errors.extend(html_report::write(file, &run).err());
        }
        for e in &errors {
            eprintln!("g2tess: error: {e}");
        }
        match errors.is_empty() {
            true => EXIT_OK,
            false => EXIT_SOME_FAILED,
        }
    }

    /// Saves the manifests (never with `--check`); a failure only costs the next run its skips.
    pub fn save(&self, manifests: &mut Manifests) {
        if self.settings.check {
            return;
        }
        if let Err(e) = manifests.save() {
            say(&format!(
                "g2tess: warning: {e}: the next run will process every file again"
            ));
        }
    }
}

/// `--render`: draws the inputs side by side into one PNG; processes nothing.
fn render(args: &args::Args, layers: &args::Layers) -> i32 {
    let options = match layers.resolve(None) {
        Ok(o) => o,
        Err(e) => return usage_error(&e.to_string()),
    };
    let _ = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs.unwrap_or(0))
        .build_global();
    if let Some(dir) = args.inputs.iter().find(|i| i.is_dir()) {
        return usage_error(&format!(
            "{}: --render draws files (expected .gltf or .glb files, not a folder)",
            dir.display()
        ));
    }
    let settings = args.picture_settings();
    match preview::render_command(&args.inputs, args.output.as_deref(), &options, &settings) {
        Ok(path) => {
            if !args.quiet {
                eprintln!("g2tess: drew {}", path.display());
            }
            EXIT_OK
        }
        Err(e) => {
            eprintln!("g2tess: error: {e}");
            EXIT_SOME_FAILED
        }
    }
}

/// `--explain-h MESH`: prints, per input, which source set each edge's h; writes nothing.
///
/// A closed stdout (`| head`) ends it quietly with the status so far: the reader has what it
/// wanted.
fn explain_h(inputs: &[PathBuf], layers: &args::Layers, mesh: &str) -> i32 {
    use std::io::Write as _;
    let options = match layers.resolve(None) {
        Ok(o) => o,
        Err(e) => return usage_error(&e.to_string()),
    };
    let mut status = EXIT_OK;
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    for input in inputs {
        match g2tess::pipeline::explain_h(input, &options, mesh) {
            Ok(lines) => {
                let written = writeln!(out, "{}: mesh {mesh}", input.display())
                    .and_then(|()| lines.iter().try_for_each(|l| writeln!(out, "  {l}")))
                    .and_then(|()| out.flush());
                match written {
                    Ok(()) => {}
                    Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => return status,
                    Err(e) => {
                        say(&format!("g2tess: error: standard output: {e}"));
                        return EXIT_SOME_FAILED;
                    }
                }
            }
            Err(e) => {
                say(&format!("g2tess: error: {e}"));
                status = EXIT_SOME_FAILED;
            }
        }
    }
    status
}
