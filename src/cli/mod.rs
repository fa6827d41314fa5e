//! The binary's edge: parses [`args::Args`] once, resolves [`g2tess::options::Options`], runs
//! the pipeline on every input, prints errors and chooses the exit status.
//!
//! It deliberately keeps going after a failed input (the failure shows in the exit status), like
//! any batch tool.

mod args;

use std::path::{Path, PathBuf};

use clap::Parser;

/// Every input processed.
pub const EXIT_OK: i32 = 0;
/// At least one input failed; the others were processed.
pub const EXIT_SOME_FAILED: i32 = 1;
/// The command line or the configuration is wrong; nothing was processed.
pub const EXIT_USAGE: i32 = 2;

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
    let options = match args.options() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("g2tess: error: {e}");
            return EXIT_USAGE;
        }
    };
    let outputs = match output_paths(&args.inputs, args.output.as_deref()) {
        Ok(o) => o,
        Err(msg) => {
            eprintln!("g2tess: error: {msg}");
            return EXIT_USAGE;
        }
    };
    let mut status = EXIT_OK;
    for (input, output) in args.inputs.iter().zip(&outputs) {
        match g2tess::pipeline::process_file(input, output, &options) {
            Ok(r) => {
                eprintln!(
                    "g2tess: {} -> {}: {} primitives, {} -> {} triangles",
                    input.display(),
                    output.display(),
                    r.primitives,
                    r.triangles_in,
                    r.triangles_out
                );
                if args.timings {
                    eprintln!("g2tess: {}: {}", input.display(), r.times);
                }
            }
            Err(e) => {
                eprintln!("g2tess: error: {e}");
                status = EXIT_SOME_FAILED;
            }
        }
    }
    status
}

/// `name.glb` → `name.smooth.glb`.
fn smooth_name(input: &Path) -> PathBuf {
    let stem = input.file_stem().unwrap_or_default().to_string_lossy();
    let ext = input
        .extension()
        .map_or("glb".into(), |e| e.to_string_lossy());
    input.with_file_name(format!("{stem}.smooth.{ext}"))
}

/// Where each input's output goes: `-o` as a file (one input) or a folder (any number).
fn output_paths(inputs: &[PathBuf], output: Option<&Path>) -> Result<Vec<PathBuf>, String> {
    match output {
        None => Ok(inputs.iter().map(|i| smooth_name(i)).collect()),
        Some(dir) if dir.is_dir() => Ok(inputs
            .iter()
            .map(|i| dir.join(i.file_name().unwrap_or_default()))
            .collect()),
        Some(file) if inputs.len() == 1 => Ok(vec![file.to_path_buf()]),
        Some(file) => Err(format!(
            "{}: -o with {} inputs must be an existing folder (expected e.g. -o out/)",
            file.display(),
            inputs.len()
        )),
    }
}
