//! `--report FILE.json`: one record per input, for a CI system to gate on.
//!
//! Field names are an interface (documented in the README, section "The JSON report"): add
//! fields freely, rename or remove none without bumping `format`. Warnings keep their sentences
//! under `warnings` and add their typed form under `warning_details`: a reader of either
//! format-1 report keeps working.

use std::path::Path;

use g2tess::pipeline::{FileReport, Warnings};
use serde::Serialize;

use super::batch::{Outcome, Status, Summary};
use super::scope::Job;

/// Bumped when a field is renamed or removed.
const FORMAT: u32 = 1;

#[derive(Serialize)]
struct Report<'a> {
    format: u32,
    version: &'static str,
    /// `"write"` or `"check"`.
    mode: &'static str,
    /// The exit status of the run.
    exit_status: i32,
    summary: &'a Summary,
    files: Vec<Record<'a>>,
}

#[derive(Serialize)]
struct Record<'a> {
    input: String,
    output: String,
    status: Status,
    error: Option<&'a str>,
    seconds: f64,
    /// Every warning of every mesh, also found per mesh under `meshes`: the sentences as
    /// `warnings`, and as `warning_details` objects with their kind and location.
    #[serde(flatten)]
    warnings: Warnings,
    /// Counts, sizes, stage times and per-mesh continuity of a processed or checked file.
    #[serde(flatten)]
    result: Option<&'a FileReport>,
}

/// Writes the report atomically; the error is a message naming the file.
pub fn write(
    file: &Path,
    jobs: &[Job],
    outcomes: &[Outcome],
    summary: &Summary,
    check: bool,
    exit_status: i32,
) -> Result<(), String> {
    let files = jobs
        .iter()
        .zip(outcomes)
        .map(|(job, o)| Record {
            input: job.input.display().to_string(),
            output: job.output.display().to_string(),
            status: o.status,
            error: o.error.as_deref(),
            seconds: o.seconds,
            warnings: Warnings(
                o.report
                    .iter()
                    .flat_map(|r| r.warnings())
                    .cloned()
                    .collect(),
            ),
            result: o.report.as_ref(),
        })
        .collect();
    let report = Report {
        format: FORMAT,
        version: env!("CARGO_PKG_VERSION"),
        mode: if check { "check" } else { "write" },
        exit_status,
        summary,
        files,
    };
    let mut text = serde_json::to_vec_pretty(&report).map_err(|e| e.to_string())?;
    text.push(b'\n');
    g2tess::gltf_io::write::atomic_write(file, &text).map_err(|e| e.to_string())
}
