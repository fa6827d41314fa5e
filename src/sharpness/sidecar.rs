//! Reads the sidecar TOML (`robot.g2tess.toml` beside `robot.glb`, or `--sidecar FILE`) into
//! [`Block`]s located by line. It deliberately does not check mesh names against an asset
//! (see [`super::AssetSharpness::new`]) nor match edges against a mesh.

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::DVec3;
use serde::Deserialize;
use toml::Spanned;

use super::entries::{
    at, check_crease_angle, check_h, check_level, Block, EdgeEntry, Located, RawEdgeFields,
};
use super::error::{Location, Problem, SharpnessError};

/// The suffix that turns an asset's stem into its sidecar's file name.
pub const SIDECAR_SUFFIX: &str = ".g2tess.toml";

/// A parsed, range-checked sidecar file.
#[derive(Debug, Clone, PartialEq)]
pub struct Sidecar {
    pub(crate) file: PathBuf,
    pub(crate) asset: Block,
    /// How finely the asset's meshes are tessellated (`level`, tolerances, budget, cap).
    pub(crate) density: DensityKeys,
    pub(crate) meshes: Vec<MeshSection>,
}

/// The density keys of one sidecar block (the top level or a mesh section), each range-checked
/// by the rule of its flag ([`crate::options::Options::validate`]; `level` as `--level`).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DensityKeys {
    pub level: Option<u32>,
    pub tolerance: Option<f64>,
    pub relative_tolerance: Option<f64>,
    pub triangle_budget: Option<u64>,
    pub max_segments: Option<u32>,
}

impl DensityKeys {
    /// `options` with this block applied. A block that sets any of `level`, `tolerance`,
    /// `relative_tolerance` and `triangle_budget` decides the density of its scope alone: the
    /// ones it leaves out are off (`level` keeps its value, unused once a tolerance is set), so
    /// `level = 8` in a mesh section gives that mesh level 8 under an asset tolerance.
    /// `max_segments` applies on its own.
    pub fn apply(&self, mut options: crate::options::Options) -> crate::options::Options {
        let decides = self.level.is_some()
            || self.tolerance.is_some()
            || self.relative_tolerance.is_some()
            || self.triangle_budget.is_some();
        if decides {
            options.level = self.level.unwrap_or(options.level);
            options.tolerance = self.tolerance.unwrap_or(0.0);
            options.relative_tolerance = self.relative_tolerance.unwrap_or(0.0);
            options.triangle_budget = self.triangle_budget.unwrap_or(0);
        }
        if let Some(cap) = self.max_segments {
            options.max_segments = cap;
        }
        options
    }
}

/// One `[mesh."Name"]` or `[mesh.3]` section.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct MeshSection {
    pub key: MeshKey,
    /// The line of the section's key, for errors about the section as a whole.
    pub line: usize,
    pub block: Block,
    /// The section's density keys, over the top level's.
    pub density: DensityKeys,
}

/// How a section names its mesh. A key made only of ASCII digits is an index.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum MeshKey {
    Name(String),
    Index(usize),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a sidecar table")]
struct RawSidecar {
    h: Option<Spanned<f64>>,
    crease_angle: Option<Spanned<f64>>,
    level: Option<Spanned<i64>>,
    tolerance: Option<Spanned<f64>>,
    relative_tolerance: Option<Spanned<f64>>,
    triangle_budget: Option<Spanned<i64>>,
    max_segments: Option<Spanned<i64>>,
    #[serde(default)]
    mesh: BTreeMap<Spanned<String>, RawMesh>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a mesh section")]
struct RawMesh {
    h: Option<Spanned<f64>>,
    crease_angle: Option<Spanned<f64>>,
    level: Option<Spanned<i64>>,
    tolerance: Option<Spanned<f64>>,
    relative_tolerance: Option<Spanned<f64>>,
    triangle_budget: Option<Spanned<i64>>,
    max_segments: Option<Spanned<i64>>,
    #[serde(default)]
    edges: Vec<Spanned<RawEdge>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "an edge entry")]
struct RawEdge {
    primitive: Option<Spanned<i64>>,
    a: Option<Spanned<i64>>,
    b: Option<Spanned<i64>>,
    from: Option<Spanned<[f64; 3]>>,
    to: Option<Spanned<[f64; 3]>>,
    h: Spanned<f64>,
}

/// The sidecar path for an asset: `dir/robot.glb` → `dir/robot.g2tess.toml`.
pub fn sidecar_path_for(asset: &Path) -> PathBuf {
    let stem = asset.file_stem().unwrap_or_default().to_string_lossy();
    asset.with_file_name(format!("{stem}{SIDECAR_SUFFIX}"))
}

impl Sidecar {
    /// Finds and parses the sidecar of `asset`: `explicit` (`--sidecar`) must exist; the one
    /// beside the asset is optional, so its absence is `Ok(None)`.
    pub fn discover(
        asset: &Path,
        explicit: Option<&Path>,
    ) -> Result<Option<Sidecar>, SharpnessError> {
        match explicit {
            Some(file) => Sidecar::load(file).map(Some),
            None => {
                let file = sidecar_path_for(asset);
                if file.is_file() {
                    Sidecar::load(&file).map(Some)
                } else {
                    Ok(None)
                }
            }
        }
    }

    /// Reads and parses one sidecar file.
    pub fn load(file: &Path) -> Result<Sidecar, SharpnessError> {
        let text = std::fs::read_to_string(file).map_err(|e| {
            SharpnessError::new(
                Location::File {
                    file: file.to_path_buf(),
                },
                Problem::Read {
                    message: e.to_string(),
                },
            )
        })?;
        Sidecar::parse(file, &text)
    }

    /// Parses sidecar text; `file` only names it in messages and explain rows.
    pub fn parse(file: &Path, text: &str) -> Result<Sidecar, SharpnessError> {
        let lines = LineIndex::new(text);
        let loc = |span: Range<usize>, path: &str| Location::Toml {
            file: file.to_path_buf(),
            line: lines.line_of(span.start),
            path: path.to_string(),
        };
        let raw: RawSidecar = toml::from_str(text).map_err(|e| {
            let line = e.span().map_or(1, |s| lines.line_of(s.start));
            SharpnessError::new(
                Location::Toml {
                    file: file.to_path_buf(),
                    line,
                    path: String::new(),
                },
                Problem::Toml {
                    message: e.message().trim_end().trim_end_matches('.').to_string(),
                },
            )
        })?;

        let asset = Block {
            h: located_h(raw.h.as_ref(), "h", &loc)?,
            crease_angle: located_crease(raw.crease_angle.as_ref(), "crease_angle", &loc)?,
            edges: Vec::new(),
        };
        let density = density_keys(
            RawDensity {
                level: raw.level.as_ref(),
                tolerance: raw.tolerance.as_ref(),
                relative_tolerance: raw.relative_tolerance.as_ref(),
                triangle_budget: raw.triangle_budget.as_ref(),
                max_segments: raw.max_segments.as_ref(),
            },
            &loc,
        )?;
        let mut meshes = Vec::with_capacity(raw.mesh.len());
        for (key, section) in raw.mesh {
            let line = lines.line_of(key.span().start);
            let key = parse_mesh_key(key.get_ref());
            let mut block = Block {
                h: located_h(section.h.as_ref(), "h", &loc)?,
                crease_angle: located_crease(section.crease_angle.as_ref(), "crease_angle", &loc)?,
                edges: Vec::with_capacity(section.edges.len()),
            };
            for (i, edge) in section.edges.iter().enumerate() {
                block.edges.push(parse_edge(i, edge, &loc)?);
            }
            let density = density_keys(
                RawDensity {
                    level: section.level.as_ref(),
                    tolerance: section.tolerance.as_ref(),
                    relative_tolerance: section.relative_tolerance.as_ref(),
                    triangle_budget: section.triangle_budget.as_ref(),
                    max_segments: section.max_segments.as_ref(),
                },
                &loc,
            )?;
            meshes.push(MeshSection {
                key,
                line,
                block,
                density,
            });
        }
        // Sections in file order, so errors come out in the order the user reads them.
        meshes.sort_by_key(|m| m.line);
        Ok(Sidecar {
            file: file.to_path_buf(),
            asset,
            density,
            meshes,
        })
    }

    /// The file this sidecar was read from.
    pub fn file(&self) -> &Path {
        &self.file
    }

    /// The per-asset tessellation level, if the sidecar sets one (in the range of `--level`).
    pub fn level(&self) -> Option<u32> {
        self.density.level
    }

    /// The density keys of the top level (they apply to every mesh of the asset).
    pub fn density(&self) -> DensityKeys {
        self.density
    }
}

/// One block's density keys as read, before checking.
struct RawDensity<'a> {
    level: Option<&'a Spanned<i64>>,
    tolerance: Option<&'a Spanned<f64>>,
    relative_tolerance: Option<&'a Spanned<f64>>,
    triangle_budget: Option<&'a Spanned<i64>>,
    max_segments: Option<&'a Spanned<i64>>,
}

/// Checks each density key by the rule its flag is checked by: the options' own
/// [`crate::options::Options::validate`] on that one value, so the range and its wording are
/// the same in every source.
fn density_keys(
    raw: RawDensity<'_>,
    loc: &impl Fn(Range<usize>, &str) -> Location,
) -> Result<DensityKeys, SharpnessError> {
    use crate::options::Options;
    let check = |span: Range<usize>, key: &'static str, options: Options| {
        options.validate(key).map_err(|e| {
            at(
                &loc(span, key),
                Problem::Setting {
                    what: e.what.clone(),
                },
            )
        })
    };
    let whole = |v: &Spanned<i64>, key: &'static str| -> Result<u64, SharpnessError> {
        u64::try_from(*v.get_ref()).map_err(|_| {
            at(
                &loc(v.span(), key),
                Problem::WrongType {
                    expected: "a non-negative integer",
                    got: v.get_ref().to_string(),
                },
            )
        })
    };
    let mut keys = DensityKeys::default();
    if let Some(level) = raw.level {
        keys.level =
            Some(check_level(*level.get_ref()).map_err(|p| at(&loc(level.span(), "level"), p))?);
    }
    if let Some(v) = raw.tolerance {
        let tolerance = *v.get_ref();
        check(
            v.span(),
            "tolerance",
            Options {
                tolerance,
                ..Options::default()
            },
        )?;
        keys.tolerance = Some(tolerance);
    }
    if let Some(v) = raw.relative_tolerance {
        let relative_tolerance = *v.get_ref();
        check(
            v.span(),
            "relative_tolerance",
            Options {
                relative_tolerance,
                ..Options::default()
            },
        )?;
        keys.relative_tolerance = Some(relative_tolerance);
    }
    if let Some(v) = raw.triangle_budget {
        keys.triangle_budget = Some(whole(v, "triangle_budget")?);
    }
    if let Some(v) = raw.max_segments {
        let max_segments = u32::try_from(whole(v, "max_segments")?).unwrap_or(u32::MAX);
        check(
            v.span(),
            "max_segments",
            Options {
                max_segments,
                ..Options::default()
            },
        )?;
        keys.max_segments = Some(max_segments);
    }
    Ok(keys)
}

fn parse_mesh_key(key: &str) -> MeshKey {
    if !key.is_empty() && key.bytes().all(|b| b.is_ascii_digit()) {
        if let Ok(index) = key.parse() {
            return MeshKey::Index(index);
        }
    }
    MeshKey::Name(key.to_string())
}

fn parse_edge(
    i: usize,
    edge: &Spanned<RawEdge>,
    loc: &impl Fn(Range<usize>, &str) -> Location,
) -> Result<EdgeEntry, SharpnessError> {
    let path = format!("edges[{i}]");
    let entry_loc = loc(edge.span(), &path);
    let raw = edge.get_ref();
    let index = |v: &Option<Spanned<i64>>, key: &str| -> Result<Option<u64>, SharpnessError> {
        match v {
            None => Ok(None),
            Some(v) => u64::try_from(*v.get_ref()).map(Some).map_err(|_| {
                at(
                    &loc(v.span(), &format!("{path}.{key}")),
                    Problem::WrongType {
                        expected: "a non-negative integer",
                        got: v.get_ref().to_string(),
                    },
                )
            }),
        }
    };
    let point = |v: &Option<Spanned<[f64; 3]>>| v.as_ref().map(|p| DVec3::from_array(*p.get_ref()));
    let fields = RawEdgeFields {
        primitive: index(&raw.primitive, "primitive")?.map(|p| p as usize),
        a: index(&raw.a, "a")?,
        b: index(&raw.b, "b")?,
        from: point(&raw.from),
        to: point(&raw.to),
    };
    let h =
        check_h(*raw.h.get_ref()).map_err(|e| at(&loc(raw.h.span(), &format!("{path}.h")), e))?;
    let name = fields.into_name().map_err(|e| at(&entry_loc, e))?;
    Ok(EdgeEntry {
        name,
        h,
        at: Arc::new(entry_loc),
    })
}

fn located_h(
    v: Option<&Spanned<f64>>,
    path: &str,
    loc: &impl Fn(Range<usize>, &str) -> Location,
) -> Result<Option<Located<f64>>, SharpnessError> {
    located(v, path, loc, check_h)
}

fn located_crease(
    v: Option<&Spanned<f64>>,
    path: &str,
    loc: &impl Fn(Range<usize>, &str) -> Location,
) -> Result<Option<Located<f64>>, SharpnessError> {
    located(v, path, loc, check_crease_angle)
}

fn located(
    v: Option<&Spanned<f64>>,
    path: &str,
    loc: &impl Fn(Range<usize>, &str) -> Location,
    check: fn(f64) -> Result<f64, Problem>,
) -> Result<Option<Located<f64>>, SharpnessError> {
    let Some(v) = v else { return Ok(None) };
    let here = loc(v.span(), path);
    let value = check(*v.get_ref()).map_err(|e| at(&here, e))?;
    Ok(Some(Located {
        value,
        at: Arc::new(here),
    }))
}

/// Byte offset → 1-based line number, for messages in the `file.toml:12:` form.
struct LineIndex {
    starts: Vec<usize>,
}

impl LineIndex {
    fn new(text: &str) -> Self {
        let starts = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        LineIndex { starts }
    }

    fn line_of(&self, offset: usize) -> usize {
        self.starts.partition_point(|&s| s <= offset)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::options::Options;

    /// A block that sets any density key decides its scope alone; `max_segments` goes on its
    /// own; a block with none changes nothing.
    #[test]
    fn density_blocks_replace_the_density_they_set() {
        let text = "tolerance = 0.01\nmax_segments = 8\n[mesh.0]\nlevel = 3\n[mesh.1]\nh = 0.1\n";
        let sc = Sidecar::parse(Path::new("s.toml"), text).unwrap();
        let flags = Options {
            relative_tolerance: 0.5,
            triangle_budget: 100,
            ..Options::default()
        };
        let asset = sc.density.apply(flags.clone());
        assert_eq!(
            (
                asset.tolerance,
                asset.relative_tolerance,
                asset.triangle_budget
            ),
            (0.01, 0.0, 0)
        );
        assert_eq!(asset.max_segments, 8);
        let uniform = sc.meshes[0].density.apply(asset.clone());
        assert_eq!(uniform.level, 3);
        assert!(!uniform.adaptive());
        assert_eq!(uniform.max_segments, 8);
        assert_eq!(sc.meshes[1].density.apply(asset.clone()), asset);
    }
}
