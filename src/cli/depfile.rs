//! `--depfile`: a Makefile-style dependency file `OUTPUT.d` beside each output, in the format of
//! gcc's `-MD -MP`, which Make includes and Ninja reads with `depfile = $out.d`.
//!
//! It lists the files of [`super::declared_inputs`] that exist when the output is made: Make
//! and Ninja treat a listed file that is absent as always out of date, so files that would
//! only be read once created (a new sidecar, a nearer `g2tess.toml`) cannot be listed. Like
//! gcc's `-MP`, every file but the asset also gets an empty rule, so that deleting a sidecar or
//! folder config rebuilds the asset instead of stopping Make with "no rule to make target".
//! The target is the output exactly as the command line named it, which is what Ninja checks.

use std::path::{Path, PathBuf};

use g2tess::options::Options;

use super::batch::{Outcome, Status};
use super::declared_inputs::Reads;
use super::scope::Job;

/// `out.glb` → `out.glb.d`.
pub fn path_for(output: &Path) -> PathBuf {
    let mut name = output.as_os_str().to_owned();
    name.push(".d");
    PathBuf::from(name)
}

/// Writes the depfile of every job that now has a current output (processed or up to date).
/// A depfile that cannot be written fails its job: a build system without it would not know
/// when to run it again.
pub fn write_all(
    jobs: &[Job],
    options: &[Result<Options, String>],
    outcomes: &mut [Outcome],
    config: Option<&Path>,
) {
    for ((job, options), outcome) in jobs.iter().zip(options).zip(outcomes) {
        let (Status::Done | Status::Skipped, Ok(options)) = (outcome.status, options) else {
            continue;
        };
        if let Err(e) = write_one(job, options, config) {
            eprintln!("g2tess: error: {e}");
            outcome.status = Status::Failed;
            outcome.error = Some(e);
        }
    }
}

fn write_one(job: &Job, options: &Options, config: Option<&Path>) -> Result<(), String> {
    let file = path_for(&job.output);
    let reads = Reads::of(job, options, config)?;
    let present: Vec<&Path> = reads
        .reads
        .iter()
        .map(PathBuf::as_path)
        .filter(|p| p.exists())
        .collect();
    // With `--lod-files` the level files are what is made, and what Make and Ninja check.
    let levels = options.lod_levels().len();
    let targets: Vec<PathBuf> = if options.lod_files && levels > 0 {
        (0..levels)
            .map(|k| g2tess::pipeline::lod::level_path(&job.output, k))
            .collect()
    } else {
        vec![job.output.clone()]
    };
    let targets: Vec<&Path> = targets.iter().map(PathBuf::as_path).collect();
    let text = render(&targets, &present)
        .map_err(|e| format!("{}: cannot write the depfile: {e}", file.display()))?;
    g2tess::gltf_io::write::atomic_write(&file, text.as_bytes()).map_err(|e| e.to_string())
}

/// The depfile text: `target…: dep…` with one dependency per continued line, then an empty
/// rule per dependency after the first.
pub fn render(targets: &[&Path], deps: &[&Path]) -> Result<String, String> {
    let mut text = targets
        .iter()
        .map(|t| escape(t))
        .collect::<Result<Vec<_>, _>>()?
        .join(" ");
    text.push(':');
    for dep in deps {
        text.push_str(" \\\n  ");
        text.push_str(&escape(dep)?);
    }
    text.push('\n');
    for dep in deps.iter().skip(1) {
        text.push('\n');
        text.push_str(&escape(dep)?);
        text.push_str(":\n");
    }
    Ok(text)
}

/// Escapes a path as gcc writes it and Make and Ninja read it: a space or `#` gets a backslash
/// (and the backslashes just before it are doubled), `$` is doubled. A line break or tab has no
/// escape that both read, so such a name is refused.
fn escape(path: &Path) -> Result<String, String> {
    let text = path.to_str().ok_or_else(|| {
        format!(
            "{}: the name is not UTF-8 (expected a name Make and Ninja can read)",
            path.display()
        )
    })?;
    let mut out = String::with_capacity(text.len() + 8);
    let mut backslashes = 0;
    for c in text.chars() {
        match c {
            '\n' | '\r' | '\t' => {
                return Err(format!(
                    "{text:?}: a line break or tab in a file name (expected a name Make and Ninja can read)"
                ))
            }
            ' ' | '#' => {
                out.extend(std::iter::repeat_n('\\', backslashes + 1));
                out.push(c);
            }
            '$' => out.push_str("$$"),
            _ => out.push(c),
        }
        backslashes = if c == '\\' { backslashes + 1 } else { 0 };
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spaces_hashes_and_dollars_are_escaped_as_gcc_does() {
        let e = |s: &str| escape(Path::new(s)).unwrap();
        assert_eq!(e("my props/a b.glb"), r"my\ props/a\ b.glb");
        assert_eq!(e("take#2.glb"), r"take\#2.glb");
        assert_eq!(e("$HOME.glb"), "$$HOME.glb");
        // A backslash before a space is doubled so that it stays a backslash.
        assert_eq!(e(r"a\ b.glb"), r"a\\\ b.glb");
        assert_eq!(e(r"a\b.glb"), r"a\b.glb");
    }

    #[test]
    fn line_breaks_are_refused() {
        assert!(escape(Path::new("a\nb.glb")).is_err());
        assert!(escape(Path::new("a\tb.glb")).is_err());
    }

    #[test]
    fn the_target_lists_every_file_and_the_others_get_empty_rules() {
        let deps = [
            Path::new("a.gltf"),
            Path::new("a.bin"),
            Path::new("a.g2tess.toml"),
        ];
        let text = render(&[Path::new("out/a.gltf")], &deps).unwrap();
        assert_eq!(
            text,
            "out/a.gltf: \\\n  a.gltf \\\n  a.bin \\\n  a.g2tess.toml\n\na.bin:\n\na.g2tess.toml:\n"
        );
    }

    #[test]
    fn the_depfile_is_the_output_name_with_d() {
        assert_eq!(
            path_for(Path::new("o/a.smooth.glb")),
            Path::new("o/a.smooth.glb.d")
        );
    }
}
