//! What a run prints on stderr: a progress bar when stderr is a terminal, one plain line per
//! file otherwise (logs of build systems and CI), errors always, and a summary at the end.
//!
//! It deliberately prints nothing on stdout, which stays free for the caller.

use std::io::{IsTerminal as _, Write as _};
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};

use super::batch::{Outcome, Status, Summary};
use super::scope::Job;

/// How much to print.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Verbosity {
    /// Errors only.
    Quiet,
    /// Errors, one line per processed file, warning counts, the summary.
    Normal,
    /// Also skipped and unchanged files and every warning.
    Verbose,
}

/// The printer of one run (or one round of a watch).
pub struct Progress {
    bar: Option<ProgressBar>,
    verbosity: Verbosity,
    /// `--timings`: a line of stage times per file.
    timings: bool,
}

impl Progress {
    /// A printer for `total` files: a bar if stderr is a terminal and there is more than one.
    pub fn new(total: usize, verbosity: Verbosity, timings: bool) -> Progress {
        let bar = (verbosity != Verbosity::Quiet && total > 1 && std::io::stderr().is_terminal())
            .then(|| {
                let style = ProgressStyle::with_template(
                    "{spinner} [{bar:30}] {pos}/{len} {elapsed_precise} {wide_msg}",
                )
                .expect("a fixed template")
                .progress_chars("=> ");
                let bar = ProgressBar::new(total as u64).with_style(style);
                bar.enable_steady_tick(Duration::from_millis(120));
                bar
            });
        Progress {
            bar,
            verbosity,
            timings,
        }
    }

    /// Prints a line above the bar (or plainly).
    pub fn line(&self, text: &str) {
        match &self.bar {
            Some(bar) => bar.println(text),
            None => say(text),
        }
    }

    /// A file was started.
    pub fn started(&self, job: &Job) {
        if let Some(bar) = &self.bar {
            bar.set_message(job.input.display().to_string());
        }
    }

    /// A file was finished.
    pub fn finished(&self, job: &Job, outcome: &Outcome) {
        if let Some(bar) = &self.bar {
            bar.inc(1);
        }
        if let Some(error) = &outcome.error {
            self.line(&format!("g2tess: error: {error}"));
        }
        if let (true, Some(report)) = (self.timings, &outcome.report) {
            self.line(&format!(
                "g2tess: {}: {}",
                job.input.display(),
                report.times
            ));
        }
        let quiet_lines = self.bar.is_some() && self.verbosity < Verbosity::Verbose;
        if self.verbosity == Verbosity::Quiet || quiet_lines {
            return;
        }
        let input = job.input.display();
        let output = job.output.display();
        match (outcome.status, &outcome.report) {
            (Status::Done, Some(r)) => {
                let warnings = r.warnings().count();
                let note = match warnings {
                    0 => String::new(),
                    1 => ", 1 warning".to_string(),
                    n => format!(", {n} warnings"),
                };
                self.line(&format!(
                    "g2tess: {input} -> {output}: {} primitives, {} -> {} triangles, {:.2} s{note}",
                    r.primitives, r.triangles_in, r.triangles_out, outcome.seconds
                ));
            }
            (Status::Skipped, _) if self.verbosity == Verbosity::Verbose => {
                self.line(&format!("g2tess: {input} -> {output}: up to date, skipped"));
            }
            (Status::Unchanged, _) if self.verbosity == Verbosity::Verbose => {
                self.line(&format!("g2tess: {output}: up to date"));
            }
            _ => {}
        }
        if self.verbosity == Verbosity::Verbose {
            for w in outcome.report.iter().flat_map(|r| r.warnings()) {
                self.line(&format!("g2tess: warning: {input}: {w}"));
            }
        }
    }

    /// Removes the bar and prints the summary line if `show`.
    pub fn finish(&self, summary: &Summary, check: bool, show: bool) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
        if self.verbosity == Verbosity::Quiet || !show {
            return;
        }
        say(&format!("g2tess: {}", summary_line(summary, check)));
    }
}

/// Prints a line on stderr. A stderr that cannot be written to (a closed pipe: `2>&1 | head`)
/// ends what is printed, never the run: the files still get processed and the exit status
/// still tells how it went.
pub fn say(text: &str) {
    let _ = writeln!(std::io::stderr().lock(), "{text}");
}

/// `12 done, 30 skipped, 1 failed; 1234 -> 19744 triangles; 1.2 MB -> 5.6 MB; 1.23 s`.
pub fn summary_line(s: &Summary, check: bool) -> String {
    let counts: Vec<String> = if check {
        vec![
            format!("{} up to date", s.unchanged),
            format!("{} out of date", s.changed),
        ]
    } else {
        vec![format!("{} done", s.done), format!("{} skipped", s.skipped)]
    };
    let mut counts = counts;
    counts.push(format!("{} failed", s.failed));
    if s.cancelled > 0 {
        counts.push(format!("{} not started", s.cancelled));
    }
    format!(
        "{}{}; {} -> {} triangles; {} -> {}; {:.2} s",
        if check { "check: " } else { "" },
        counts.join(", "),
        s.triangles_in,
        s.triangles_out,
        bytes(s.bytes_in),
        bytes(s.bytes_out),
        s.seconds
    )
}

fn bytes(n: u64) -> String {
    match n {
        n if n >= 1 << 30 => format!("{:.1} GiB", n as f64 / (1u64 << 30) as f64),
        n if n >= 1 << 20 => format!("{:.1} MiB", n as f64 / (1u64 << 20) as f64),
        n if n >= 1 << 10 => format!("{:.1} KiB", n as f64 / (1u64 << 10) as f64),
        n => format!("{n} B"),
    }
}
