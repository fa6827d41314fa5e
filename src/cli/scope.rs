//! Which assets a run covers and where each one's output goes: folders walked in sorted order
//! for `.gltf`/`.glb`, `--include`/`--exclude` globs, outputs mirrored under `-o`.
//!
//! It deliberately reads no asset and writes nothing: it only looks at names, so the plan is
//! the same at any thread count and can be made again for a single path when watching.

use std::collections::HashMap;
use std::path::{Component, Path, PathBuf};

use globset::{Glob, GlobBuilder, GlobSet, GlobSetBuilder};

use super::manifest::{written_files, MANIFEST_NAME};

/// One asset to process.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Job {
    /// The asset, as the user named it or as found below a folder they named.
    pub input: PathBuf,
    /// Where its output goes (`.glb`, or `.gltf` with a `.bin` beside it).
    pub output: PathBuf,
    /// The highest folder searched for a `g2tess.toml`: the folder input it was found in, or a
    /// file input's own folder.
    pub config_root: PathBuf,
    /// The output folder whose manifest records this output; none for a named output file or
    /// one beside its input (the caller's build system decides when to run those again).
    pub manifest_dir: Option<PathBuf>,
    /// The output's name in that manifest (a relative path with `/`).
    pub key: String,
}

/// Where outputs go.
#[derive(Debug, Clone)]
enum Target {
    /// `NAME.smooth.EXT` beside each input (file inputs only).
    Beside,
    /// One input file, one named output file.
    File(PathBuf),
    /// A folder that mirrors the inputs' folders.
    Folder(PathBuf),
}

/// The inputs, the filters and the output target of a run.
#[derive(Debug)]
pub struct Scope {
    roots: Vec<Root>,
    target: Target,
    include: Option<GlobSet>,
    exclude: GlobSet,
}

#[derive(Debug)]
struct Root {
    path: PathBuf,
    is_dir: bool,
    /// The output folder's path relative to this folder input, when it lies inside it: the walk
    /// skips it, so outputs are never taken for inputs.
    output_inside: Option<PathBuf>,
}

impl Scope {
    /// Checks the command line's inputs and `-o` together; the message is a usage error.
    pub fn new(
        inputs: &[PathBuf],
        output: Option<&Path>,
        include: &[String],
        exclude: &[String],
    ) -> Result<Scope, String> {
        let any_dir = inputs.iter().any(|i| i.is_dir());
        let target = match output {
            None if any_dir => {
                let dir = inputs.iter().find(|i| i.is_dir()).expect("any_dir");
                return Err(format!(
                    "{}: a folder input needs an output folder (expected e.g. -o {})",
                    dir.display(),
                    Path::new("build")
                        .join(dir.file_name().unwrap_or_default())
                        .display()
                ));
            }
            None => Target::Beside,
            Some(o) if o.is_dir() || any_dir || inputs.len() > 1 || ends_with_separator(o) => {
                if is_asset_name(o) && !o.is_dir() {
                    return Err(format!(
                        "{}: -o names a file, but there are {} (expected an output folder)",
                        o.display(),
                        if any_dir {
                            "folder inputs"
                        } else {
                            "several inputs"
                        }
                    ));
                }
                Target::Folder(o.to_path_buf())
            }
            Some(o) if !is_asset_name(o) => {
                return Err(format!(
                    "{}: -o names neither a .glb nor a .gltf file (expected e.g. -o {})",
                    o.display(),
                    o.with_extension("glb").display()
                ))
            }
            Some(o) => Target::File(o.to_path_buf()),
        };
        let out_abs = match &target {
            Target::Folder(o) => Some(absolute(o)),
            _ => None,
        };
        let mut roots = Vec::with_capacity(inputs.len());
        for input in inputs {
            let is_dir = input.is_dir();
            let mut output_inside = None;
            if let (true, Some(out)) = (is_dir, &out_abs) {
                let abs = absolute(input);
                if *out == abs {
                    return Err(format!(
                        "{}: the output folder is the input folder (expected another folder, e.g. -o {})",
                        input.display(),
                        input.join("smooth").display()
                    ));
                }
                if abs.starts_with(out) {
                    // Every input would count as an output of the run (and a later run would
                    // take the outputs for inputs).
                    return Err(format!(
                        "{}: the output folder {} contains the input folder (expected an output folder outside it, e.g. -o {})",
                        input.display(),
                        output.unwrap_or(Path::new(".")).display(),
                        Path::new("build")
                            .join(input.file_name().unwrap_or_default())
                            .display()
                    ));
                }
                output_inside = out.strip_prefix(&abs).ok().map(Path::to_path_buf);
            }
            roots.push(Root {
                path: input.clone(),
                is_dir,
                output_inside,
            });
        }
        Ok(Scope {
            roots,
            target,
            include: (!include.is_empty())
                .then(|| glob_set(include, "--include"))
                .transpose()?,
            exclude: glob_set(exclude, "--exclude")?,
        })
    }

    /// The folder inputs and the folders of file inputs, for watching.
    pub fn watched(&self) -> Vec<(PathBuf, bool)> {
        self.roots
            .iter()
            .map(|r| match r.is_dir {
                true => (r.path.clone(), true),
                false => (parent_dir(&r.path).to_path_buf(), false),
            })
            .collect()
    }

    /// A path as notify reports it (below a watched folder, canonical) in the form the inputs
    /// were given in, or `None` when it is outside every watched folder.
    pub fn given_form(&self, reported: &Path) -> Option<PathBuf> {
        self.watched().into_iter().find_map(|(dir, _)| {
            let rest = reported.strip_prefix(super::watch::canonical(&dir)).ok()?;
            Some(match dir == Path::new(".") {
                true => rest.to_path_buf(),
                false => dir.join(rest),
            })
        })
    }

    /// Every job of the run, in input order and sorted within each folder, and what the walk
    /// could not read. The message is a usage error (two inputs that would write one output).
    pub fn jobs(&self) -> Result<(Vec<Job>, Vec<Problem>), String> {
        let (mut jobs, mut problems) = (Vec::new(), Vec::new());
        for (i, root) in self.roots.iter().enumerate() {
            if root.is_dir {
                let (found, issues) = self.walk(i, &root.path);
                jobs.extend(found);
                problems.extend(issues);
            } else {
                jobs.push(self.job(i, &root.path));
            }
        }
        Ok((dedupe(jobs)?, problems))
    }

    /// The jobs of the assets at or below `path` (a file or a folder) that this run covers.
    pub fn jobs_at(&self, path: &Path) -> Vec<Job> {
        let mut jobs = Vec::new();
        for (i, root) in self.roots.iter().enumerate() {
            if !root.is_dir {
                let (file, at) = (absolute(&root.path), absolute(path));
                if file == at || (path.is_dir() && file.starts_with(&at)) {
                    jobs.push(self.job(i, &root.path));
                }
                continue;
            }
            if path.is_dir() {
                if path.starts_with(&root.path) && self.admits_dir(i, path) {
                    let (found, problems) = self.walk(i, path);
                    jobs.extend(found);
                    for p in problems {
                        super::progress::say(&p.to_string());
                    }
                }
            } else if path.starts_with(&root.path) && self.admits_file(i, path) {
                jobs.push(self.job(i, path));
            }
        }
        dedupe(jobs).unwrap_or_default()
    }

    /// The job a path would have if it were an asset this run covers, whether or not it exists
    /// (for deleted inputs).
    pub fn job_for(&self, path: &Path) -> Option<Job> {
        self.roots.iter().enumerate().find_map(|(i, root)| {
            let covered = match root.is_dir {
                true => path.starts_with(&root.path) && self.admits_file(i, path),
                false => absolute(&root.path) == absolute(path),
            };
            covered.then(|| self.job(i, path))
        })
    }

    /// Whether `path` is an output, a temporary file or a manifest of this run: never an input.
    pub fn is_own(&self, path: &Path) -> bool {
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        if name.starts_with(".g2tess-") || name == MANIFEST_NAME {
            return true;
        }
        match &self.target {
            Target::Folder(o) => absolute(path).starts_with(absolute(o)),
            Target::File(o) => written_files(o)
                .iter()
                .any(|f| absolute(f) == absolute(path)),
            Target::Beside => self.roots.iter().any(|r| {
                written_files(&smooth_name(&r.path))
                    .iter()
                    .any(|f| absolute(f) == absolute(path))
            }),
        }
    }

    /// The jobs below `dir`, and what could not be read. Links are followed (a linked asset
    /// or folder counts as if it were there); a link back to a folder above it is not.
    fn walk(&self, root: usize, dir: &Path) -> (Vec<Job>, Vec<Problem>) {
        let walk = walkdir::WalkDir::new(dir)
            .follow_links(true)
            .sort_by_file_name()
            .into_iter()
            .filter_entry(|e| !e.file_type().is_dir() || self.admits_dir(root, e.path()))
            .map(|entry| {
                entry
                    .map(|e| (e.file_type().is_file(), e.into_path()))
                    .map_err(|e| WalkIssue::from(&e))
            });
        self.sort_walk(root, walk)
    }

    /// Splits a walk into the jobs of its admitted files and its problems.
    fn sort_walk(
        &self,
        root: usize,
        entries: impl Iterator<Item = Result<(bool, PathBuf), WalkIssue>>,
    ) -> (Vec<Job>, Vec<Problem>) {
        let (mut jobs, mut problems) = (Vec::new(), Vec::new());
        for entry in entries {
            match entry {
                Ok((true, path)) if self.admits_file(root, &path) => {
                    jobs.push(self.job(root, &path))
                }
                Ok(_) => {}
                Err(issue) => problems.extend(issue.problem()),
            }
        }
        (jobs, problems)
    }

    /// Whether the walk enters `dir` (below folder input `root`): not the output folder, not
    /// excluded, and neither is any folder above it.
    fn admits_dir(&self, root: usize, dir: &Path) -> bool {
        let r = &self.roots[root];
        let Ok(rel) = dir.strip_prefix(&r.path) else {
            return false;
        };
        rel.ancestors()
            .filter(|a| !a.as_os_str().is_empty())
            .all(|a| r.output_inside.as_deref() != Some(a) && !self.exclude.is_match(a))
    }

    fn admits_file(&self, root: usize, file: &Path) -> bool {
        let r = &self.roots[root];
        let Ok(rel) = file.strip_prefix(&r.path) else {
            return false;
        };
        is_asset_name(file)
            && !self.is_own(file)
            && self.admits_dir(root, parent_dir(file))
            && !self.exclude.is_match(rel)
            && self.include.as_ref().is_none_or(|inc| inc.is_match(rel))
    }

    fn job(&self, root: usize, input: &Path) -> Job {
        let r = &self.roots[root];
        let (output, manifest_dir) = match &self.target {
            Target::Beside => (smooth_name(input), None),
            Target::File(o) => (o.clone(), None),
            Target::Folder(o) => {
                let rel = match r.is_dir {
                    true => input.strip_prefix(&r.path).unwrap_or(input),
                    false => Path::new(input.file_name().unwrap_or_default()),
                };
                (o.join(rel), Some(o.clone()))
            }
        };
        let key = manifest_dir
            .as_deref()
            .and_then(|m| output.strip_prefix(m).ok())
            .unwrap_or(&output)
            .components()
            .map(|c| c.as_os_str().to_string_lossy())
            .collect::<Vec<_>>()
            .join("/");
        Job {
            input: input.to_path_buf(),
            config_root: match r.is_dir {
                true => r.path.clone(),
                false => parent_dir(input).to_path_buf(),
            },
            output,
            manifest_dir,
            key,
        }
    }
}

/// Something a folder walk could not read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Problem {
    /// The message, naming the path.
    pub message: String,
    /// An error (the run's status is at least 1), or only a warning.
    pub is_error: bool,
}

impl std::fmt::Display for Problem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let kind = if self.is_error { "error" } else { "warning" };
        write!(f, "g2tess: {kind}: {}", self.message)
    }
}

/// A failed step of a folder walk, in the terms that decide what to do about it.
#[derive(Debug, Clone)]
struct WalkIssue {
    path: Option<PathBuf>,
    /// The folder a link loops back to.
    loop_to: Option<PathBuf>,
    kind: Option<std::io::ErrorKind>,
    what: String,
}

impl From<&walkdir::Error> for WalkIssue {
    fn from(e: &walkdir::Error) -> Self {
        WalkIssue {
            path: e.path().map(Path::to_path_buf),
            loop_to: e.loop_ancestor().map(Path::to_path_buf),
            kind: e.io_error().map(std::io::Error::kind),
            what: e
                .io_error()
                .map_or_else(|| e.to_string(), ToString::to_string)
                .to_lowercase(),
        }
    }
}

impl WalkIssue {
    /// A folder that cannot be read is an error (its assets would be missing silently); a
    /// link loop is a warning (the folder it leads to is walked anyway); a dangling link is an
    /// error only when it is named like an asset.
    fn problem(&self) -> Option<Problem> {
        let shown = self
            .path
            .as_deref()
            .map_or_else(|| "?".into(), |p| p.display().to_string());
        if let Some(to) = &self.loop_to {
            return Some(Problem {
                message: format!("{shown}: a link back to {}, not followed", to.display()),
                is_error: false,
            });
        }
        let dangling = self.kind == Some(std::io::ErrorKind::NotFound);
        if dangling && !self.path.as_deref().is_some_and(is_asset_name) {
            return None;
        }
        Some(Problem {
            message: match dangling {
                true => format!("{shown}: a link to a missing file (expected an asset)"),
                false => format!("{shown}: cannot read: {}", self.what),
            },
            is_error: true,
        })
    }
}

/// Drops a job listed twice (a file named on its own and found in a folder too); refuses two
/// inputs with one output.
fn dedupe(jobs: Vec<Job>) -> Result<Vec<Job>, String> {
    let mut seen: HashMap<PathBuf, PathBuf> = HashMap::new();
    let mut out = Vec::with_capacity(jobs.len());
    for job in jobs {
        if let Some(first) = seen.get(&job.output) {
            if same_file(first, &job.input) {
                continue;
            }
            return Err(format!(
                "{}: is the output of both {} and {} (expected inputs with distinct names below -o)",
                job.output.display(),
                first.display(),
                job.input.display()
            ));
        }
        seen.insert(job.output.clone(), job.input.clone());
        out.push(job);
    }
    Ok(out)
}

fn same_file(a: &Path, b: &Path) -> bool {
    a == b || matches!((a.canonicalize(), b.canonicalize()), (Ok(x), Ok(y)) if x == y)
}

/// Globs match the path below the searched folder; one without `/` matches a name at any depth
/// (as in `.gitignore`).
fn glob_set(patterns: &[String], flag: &str) -> Result<GlobSet, String> {
    let mut set = GlobSetBuilder::new();
    for p in patterns {
        let full = match p.contains('/') {
            true => p.trim_start_matches("./").to_string(),
            false => format!("**/{p}"),
        };
        let glob: Glob = GlobBuilder::new(&full)
            .literal_separator(true)
            .build()
            .map_err(|e| {
                format!(
                    "{flag} {p}: {} (expected a glob such as '*.glb' or 'props/**')",
                    e.kind()
                )
            })?;
        set.add(glob);
    }
    set.build().map_err(|e| format!("{flag}: {e}"))
}

/// `.gltf` or `.glb`, in any case.
pub fn is_asset_name(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

/// `name.glb` → `name.smooth.glb`.
pub fn smooth_name(input: &Path) -> PathBuf {
    let stem = input.file_stem().unwrap_or_default().to_string_lossy();
    let ext = input
        .extension()
        .map_or("glb".into(), |e| e.to_string_lossy());
    input.with_file_name(format!("{stem}.smooth.{ext}"))
}

/// The folder a file is in, `.` for a bare name.
pub fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

fn ends_with_separator(path: &Path) -> bool {
    path.as_os_str()
        .to_string_lossy()
        .ends_with(std::path::is_separator)
}

/// `path` made absolute and free of `.` and `..` without touching the disk (the output folder
/// may not exist yet).
pub fn absolute(path: &Path) -> PathBuf {
    let abs = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut out = PathBuf::new();
    for c in abs.components() {
        match c {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set(p: &[&str]) -> GlobSet {
        glob_set(&p.iter().map(|s| s.to_string()).collect::<Vec<_>>(), "--x").unwrap()
    }

    #[test]
    fn a_glob_without_slash_matches_the_name_at_any_depth() {
        let s = set(&["*.glb"]);
        assert!(s.is_match("a.glb") && s.is_match("x/y/a.glb"));
        assert!(!s.is_match("a.gltf"));
    }

    #[test]
    fn a_glob_with_slash_is_anchored_at_the_folder() {
        let s = set(&["props/**"]);
        assert!(s.is_match("props/a.glb") && !s.is_match("x/props/a.glb"));
        assert!(!set(&["props/*.glb"]).is_match("props/sub/a.glb"));
    }

    #[test]
    fn an_unreadable_folder_is_an_error_naming_it_and_the_walk_goes_on() {
        let scope = Scope::new(&["in".into()], Some(Path::new("out/")), &[], &[]).unwrap();
        let denied = WalkIssue {
            path: Some("in/locked".into()),
            loop_to: None,
            kind: Some(std::io::ErrorKind::PermissionDenied),
            what: "permission denied (os error 13)".into(),
        };
        let looped = WalkIssue {
            path: Some("in/sub/up".into()),
            loop_to: Some("in".into()),
            kind: None,
            what: String::new(),
        };
        let entries = vec![
            Err(denied),
            Ok((true, PathBuf::from("in/a.glb"))),
            Err(looped),
        ];
        let (jobs, problems) = scope.sort_walk(0, entries.into_iter());
        assert_eq!(jobs.len(), 1);
        assert_eq!(
            problems.iter().map(ToString::to_string).collect::<Vec<_>>(),
            [
                "g2tess: error: in/locked: cannot read: permission denied (os error 13)",
                "g2tess: warning: in/sub/up: a link back to in, not followed"
            ]
        );
    }

    #[test]
    fn a_bad_glob_names_the_flag() {
        let e = glob_set(&["a[".to_string()], "--include").unwrap_err();
        assert!(e.starts_with("--include a[: "), "{e}");
    }
}
