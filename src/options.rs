//! The one resolved settings struct, [`Options`], with every default as a `DEFAULT_*` constant,
//! and the overlay of a TOML configuration file onto it.
//!
//! `config/default.toml` states the same defaults for users; a test keeps the two equal. This
//! module deliberately knows nothing of the command line: the binary turns its arguments into an
//! [`Options`].

use serde::{Deserialize, Serialize};

use crate::surface::SchemeParams;

/// Default tessellation level: every input edge is split into this many segments.
pub const DEFAULT_LEVEL: u32 = 4;
/// Largest accepted level (level² triangles per input triangle).
pub const MAX_LEVEL: u32 = 64;
/// Default chord tolerance in world units: 0, off (the level decides).
pub const DEFAULT_TOLERANCE: f64 = 0.0;
/// Default chord tolerance as a fraction of each mesh's bounding-box diagonal: 0, off.
pub const DEFAULT_RELATIVE_TOLERANCE: f64 = 0.0;
/// Default triangle budget per mesh: 0, none.
pub const DEFAULT_TRIANGLE_BUDGET: u64 = 0;
/// Default cap on segments per edge (and inner level) under a tolerance or budget.
pub const DEFAULT_MAX_SEGMENTS: u32 = MAX_LEVEL;
/// Most levels in a LOD chain (`--lod`, `--lod-relative`, `--lod-budget`).
pub const MAX_LOD_LEVELS: usize = 8;
/// Default blend width `h`, in the paper's reference triangle (0.6 of the maximum).
pub const DEFAULT_H: f64 = 0.212;
/// Largest blend width: √2/4, a quarter of the reference triangle's side (the surface's one
/// definition, [`crate::surface::H_MAX`]). Values up to [`MAX_H_SHOWN`] are accepted and
/// clamped to it.
pub const MAX_H: f64 = crate::surface::H_MAX;
/// [`MAX_H`] as every message and document prints it, rounded up to four decimals: the printed
/// bound is itself accepted (and clamped to √2/4), so a user who copies it is never refused.
pub const MAX_H_SHOWN: f64 = 0.3536;
// The printed bound is √2/4 rounded up, so it admits √2/4 and nothing a tenth of a digit more.
const _: () = assert!(MAX_H < MAX_H_SHOWN && MAX_H_SHOWN - MAX_H < 1e-4);
/// Default crease angle in degrees: edges whose faces meet more sharply get `h = 0`.
pub const DEFAULT_CREASE_ANGLE: f64 = 60.0;
/// Default blend profile.
pub const DEFAULT_PROFILE: Profile = Profile::C2;
/// Default surface scheme.
pub const DEFAULT_SCHEME: Scheme = Scheme::G2;
/// Default control nets under the `g2` and `pn` schemes: circle-following edges and a
/// side-vertex centre.
pub const DEFAULT_NETS: Nets = Nets::Round;
/// Default cap on output triangles per input file, so a typo in `level` cannot fill the disk or
/// the memory: at the measured peak of about 32 bytes per output triangle for positions and
/// normals, about 370 with regenerated tangents (plus about 240 per input triangle; the upper
/// end is rounded up to [`crate::pipeline::PEAK_BYTES_PER_OUTPUT_TRIANGLE`]), 20 million
/// triangles need 0.6 to 7 GiB, which leaves room for a desktop session and a second job on a
/// 24 GiB machine.
pub const DEFAULT_MAX_OUTPUT_TRIANGLES: u64 = 20_000_000;
/// Default: `uri`s may not leave the asset's folder.
pub const DEFAULT_ALLOW_OUTSIDE_URIS: bool = false;
/// Default: never overwrite an input file (or a buffer or image file it refers to).
pub const DEFAULT_OVERWRITE_INPUT: bool = false;
/// Default: hard edges of the input (split normals) are not forced sharp: the surface closes
/// them smoothly unless the crease-angle rule or an explicit h makes them creases.
pub const DEFAULT_KEEP_HARD_EDGES: bool = false;
/// Default: no overdraw ordering (it costs time and helps only some materials).
pub const DEFAULT_OVERDRAW: bool = false;
/// Default Coons shape parameter λ (Szilvási-Nagy and Szabó's Coons-type blending), in
/// [0.05, 0.95].
pub const DEFAULT_COONS_LAMBDA: f64 = SchemeParams::DEFAULT_LAMBDA;
/// Default: Coons uses the fixed λ rather than thin-plate fairing per triangle.
pub const DEFAULT_COONS_FAIR: bool = false;
/// Default: write float attributes (no KHR_mesh_quantization).
pub const DEFAULT_QUANTIZE: bool = false;
/// Default: write uncompressed buffers (no EXT_meshopt_compression).
pub const DEFAULT_COMPRESS: bool = false;
/// Default: a compressed output carries no uncompressed copy (its fallback buffer is a
/// placeholder, and EXT_meshopt_compression is required to load it).
pub const DEFAULT_COMPRESS_FALLBACK: bool = false;

pub use crate::surface::{Nets, Profile, Scheme};

/// The range of a numeric setting: the one rule every source of it is checked by (the flag,
/// `--config`, a folder `g2tess.toml`, a sidecar, glTF `extras`), and the one text `--help`,
/// `config/default.toml` and the README print for it (tests compare them).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Setting {
    /// The key in TOML files (the flag is `--` and the key with `-` for `_`).
    pub key: &'static str,
    /// The default, as written in every document.
    pub default: f64,
    /// Smallest accepted value.
    pub min: f64,
    /// Largest accepted value.
    pub max: f64,
    /// Whole numbers only.
    pub integer: bool,
    /// Unit after the range in messages (`" degrees"`), or empty.
    pub unit: &'static str,
}

/// `level`: segments per input edge.
pub const LEVEL: Setting = Setting {
    key: "level",
    default: DEFAULT_LEVEL as f64,
    min: 1.0,
    max: MAX_LEVEL as f64,
    integer: true,
    unit: "",
};
/// `h`: blend width in the reference triangle; up to [`MAX_H_SHOWN`], clamped to [`MAX_H`].
pub const H: Setting = Setting {
    key: "h",
    default: DEFAULT_H,
    min: 0.0,
    max: MAX_H_SHOWN,
    integer: false,
    unit: "",
};
/// `crease_angle`: degrees between face normals.
pub const CREASE_ANGLE: Setting = Setting {
    key: "crease_angle",
    default: DEFAULT_CREASE_ANGLE,
    min: 0.0,
    max: 180.0,
    integer: false,
    unit: " degrees",
};
/// `coons_lambda`: the Coons scheme's shape parameter.
pub const COONS_LAMBDA: Setting = Setting {
    key: "coons_lambda",
    default: DEFAULT_COONS_LAMBDA,
    min: 0.05,
    max: 0.95,
    integer: false,
    unit: "",
};
/// Every numeric setting with a range.
pub const RANGED_SETTINGS: [Setting; 4] = [LEVEL, H, CREASE_ANGLE, COONS_LAMBDA];

impl Setting {
    /// `"0 to 0.3536"`: the range as every message and document prints it.
    pub fn range_text(&self) -> String {
        format!("{} to {}", self.min, self.max)
    }

    /// Whether `value` is in range (NaN never is).
    pub fn contains(&self, value: f64) -> bool {
        (self.min..=self.max).contains(&value) && (!self.integer || value.fract() == 0.0)
    }

    /// `value` if in range, else `"is 65 (expected 1 to 64)"`.
    pub fn check(&self, value: f64) -> Result<f64, String> {
        if self.contains(value) {
            Ok(value)
        } else {
            Err(format!(
                "is {value} (expected {}{})",
                self.range_text(),
                self.unit
            ))
        }
    }
}

/// `h` as the surface uses it: in range values above √2/4 (up to the printed [`MAX_H_SHOWN`])
/// become √2/4.
pub fn clamp_h(h: f64) -> f64 {
    h.min(MAX_H)
}

/// Every setting, resolved. Defaults are the `DEFAULT_*` constants of this module.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Options {
    /// Segments per input edge. Default: [`DEFAULT_LEVEL`]; range 1..=[`MAX_LEVEL`].
    pub level: u32,
    /// Chord tolerance in world units; 0 is off. With it (or the relative one, or a budget)
    /// each edge gets its own segment count and `level` is not used. Default:
    /// [`DEFAULT_TOLERANCE`]; at least 0.
    pub tolerance: f64,
    /// Chord tolerance as a fraction of each mesh's bounding-box diagonal; 0 is off. With both
    /// tolerances set, the smaller applies. Default: [`DEFAULT_RELATIVE_TOLERANCE`]; 0 to 1.
    pub relative_tolerance: f64,
    /// Output triangles per mesh; 0 is none. Wins over the tolerances: the largest tolerance
    /// whose counts fit. Default: [`DEFAULT_TRIANGLE_BUDGET`].
    pub triangle_budget: u64,
    /// Cap on segments per edge under a tolerance or budget. Default: [`DEFAULT_MAX_SEGMENTS`];
    /// range 1..=[`MAX_LEVEL`].
    pub max_segments: u32,
    /// A LOD chain: one level of detail per chord tolerance in world units (any order; the
    /// finest is written where the mesh was). Empty is off. At most one of `lod`,
    /// `lod_relative`, `lod_budget`; with one, `level`, the tolerances and the budget are not
    /// used. Default: none.
    pub lod: Vec<f64>,
    /// A LOD chain from tolerances relative to each mesh's bounding-box diagonal. Default: none.
    pub lod_relative: Vec<f64>,
    /// A LOD chain from triangle budgets per mesh. Default: none.
    pub lod_budget: Vec<u64>,
    /// Write the LOD chain as one file per level (`<output stem>_LOD<k>.<ext>`) instead of one
    /// file with `MSFT_lod`. Default: `false`.
    pub lod_files: bool,
    /// Blend width for edges with no other source. Default: [`DEFAULT_H`]; range 0..=[`MAX_H`].
    pub h: f64,
    /// Crease angle in degrees. Default: [`DEFAULT_CREASE_ANGLE`]; range 0..=180.
    pub crease_angle: f64,
    /// Blend profile. Default: [`DEFAULT_PROFILE`].
    pub profile: Profile,
    /// Surface scheme. Default: [`DEFAULT_SCHEME`].
    pub scheme: Scheme,
    /// Control nets of the `g2` and `pn` schemes. Default: [`DEFAULT_NETS`].
    pub nets: Nets,
    /// Output triangle cap per file. Default: [`DEFAULT_MAX_OUTPUT_TRIANGLES`]; at least 1.
    pub max_output_triangles: u64,
    /// Allow `uri`s outside the asset's folder. Default: [`DEFAULT_ALLOW_OUTSIDE_URIS`].
    pub allow_outside_uris: bool,
    /// Allow the output to overwrite an input. Default: [`DEFAULT_OVERWRITE_INPUT`].
    pub overwrite_input: bool,
    /// Coons shape parameter λ. Default: [`DEFAULT_COONS_LAMBDA`]; range 0.05..=0.95.
    pub coons_lambda: f64,
    /// Coons: choose λ per triangle by thin-plate fairing. Default: [`DEFAULT_COONS_FAIR`].
    pub coons_fair: bool,
    /// Give hard edges of the input h = 0. Default: [`DEFAULT_KEEP_HARD_EDGES`].
    pub keep_hard_edges: bool,
    /// meshoptimizer overdraw ordering, then vertex fetch order. Default: [`DEFAULT_OVERDRAW`].
    pub overdraw: bool,
    /// A sidecar to use instead of `<asset>.g2tess.toml` beside each asset. Default: none.
    pub sidecar: Option<std::path::PathBuf>,
    /// Quantize output attributes. Default: [`DEFAULT_QUANTIZE`].
    pub quantize: bool,
    /// Compress output buffers. Default: [`DEFAULT_COMPRESS`].
    pub compress: bool,
    /// With `compress`, also write the uncompressed data to `<output>.fallback.bin`.
    /// Default: [`DEFAULT_COMPRESS_FALLBACK`].
    pub compress_fallback: bool,
    /// Compute the figures only a report shows: the surface's continuity across every edge
    /// ([`crate::pipeline::MeshReport::edges`], six extra surface evaluations per edge, up to a
    /// tenth of a run at low levels) and meshoptimizer's vertex cache figures of each output
    /// primitive ([`crate::pipeline::PrimitiveReport::cache`], a sequential pass over the index
    /// buffer), and, at a uniform level 1 on the flat surface, the edge counts (there they are
    /// the only reader of each edge's h). It changes the report, never the output. Default:
    /// `false`.
    pub report_figures: bool,
    /// A flag the caller sets to stop the work early (the CLI's Ctrl-C and SIGTERM): polled
    /// between stages of every mesh, it fails the file with [`crate::pipeline::Error::Cancelled`]
    /// instead of finishing it. Default: none (never cancelled).
    pub cancel: Cancel,
}

/// An optional stop flag; it never takes part in comparing options (two runs that differ only
/// in how they can be stopped make the same output).
#[derive(Debug, Clone, Copy, Default)]
pub struct Cancel(Option<&'static std::sync::atomic::AtomicBool>);

impl Cancel {
    /// Cancelled once `flag` is set.
    pub fn on(flag: &'static std::sync::atomic::AtomicBool) -> Self {
        Cancel(Some(flag))
    }

    /// Whether the work should stop.
    pub fn requested(&self) -> bool {
        self.0
            .is_some_and(|f| f.load(std::sync::atomic::Ordering::Relaxed))
    }
}

impl PartialEq for Cancel {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl Default for Options {
    fn default() -> Self {
        Self {
            level: DEFAULT_LEVEL,
            tolerance: DEFAULT_TOLERANCE,
            relative_tolerance: DEFAULT_RELATIVE_TOLERANCE,
            triangle_budget: DEFAULT_TRIANGLE_BUDGET,
            max_segments: DEFAULT_MAX_SEGMENTS,
            lod: Vec::new(),
            lod_relative: Vec::new(),
            lod_budget: Vec::new(),
            lod_files: false,
            h: DEFAULT_H,
            crease_angle: DEFAULT_CREASE_ANGLE,
            profile: DEFAULT_PROFILE,
            scheme: DEFAULT_SCHEME,
            nets: DEFAULT_NETS,
            max_output_triangles: DEFAULT_MAX_OUTPUT_TRIANGLES,
            allow_outside_uris: DEFAULT_ALLOW_OUTSIDE_URIS,
            overwrite_input: DEFAULT_OVERWRITE_INPUT,
            coons_lambda: DEFAULT_COONS_LAMBDA,
            coons_fair: DEFAULT_COONS_FAIR,
            keep_hard_edges: DEFAULT_KEEP_HARD_EDGES,
            overdraw: DEFAULT_OVERDRAW,
            sidecar: None,
            quantize: DEFAULT_QUANTIZE,
            compress: DEFAULT_COMPRESS,
            compress_fallback: DEFAULT_COMPRESS_FALLBACK,
            report_figures: false,
            cancel: Cancel::default(),
        }
    }
}

/// A configuration file: every key optional; unknown keys are an error (a typo must not be
/// silently ignored).
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ConfigFile {
    pub level: Option<u32>,
    pub tolerance: Option<f64>,
    pub relative_tolerance: Option<f64>,
    pub triangle_budget: Option<u64>,
    pub max_segments: Option<u32>,
    pub lod: Option<Vec<f64>>,
    pub lod_relative: Option<Vec<f64>>,
    pub lod_budget: Option<Vec<u64>>,
    pub lod_files: Option<bool>,
    pub h: Option<f64>,
    pub crease_angle: Option<f64>,
    pub profile: Option<Profile>,
    pub scheme: Option<Scheme>,
    pub nets: Option<Nets>,
    pub max_output_triangles: Option<u64>,
    pub allow_outside_uris: Option<bool>,
    pub overwrite_input: Option<bool>,
    pub coons_lambda: Option<f64>,
    pub coons_fair: Option<bool>,
    pub keep_hard_edges: Option<bool>,
    pub overdraw: Option<bool>,
    pub quantize: Option<bool>,
    pub compress: Option<bool>,
    pub compress_fallback: Option<bool>,
}

/// A configuration problem: `<where>: <what> (expected …)`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{at}: {what}")]
pub struct ConfigError {
    /// File and line, or the option's name.
    pub at: String,
    /// What is wrong.
    pub what: String,
}

impl ConfigFile {
    /// Parses TOML text; `origin` names it in errors (`file.toml:12: …`).
    pub fn parse(text: &str, origin: &str) -> Result<Self, ConfigError> {
        toml::from_str(text).map_err(|e: toml::de::Error| {
            let line = e.span().map(|s| text[..s.start].matches('\n').count() + 1);
            ConfigError {
                at: line.map_or(origin.to_string(), |l| format!("{origin}:{l}")),
                what: e.message().to_lowercase(),
            }
        })
    }
}

impl Options {
    /// These options with every key `config` sets replaced.
    pub fn overlay(mut self, config: &ConfigFile) -> Self {
        // The LOD lists are one setting: a layer that sets any of them replaces all three, so
        // that `--lod` overrides a folder's `lod_budget` instead of clashing with it.
        if config.lod.is_some() || config.lod_relative.is_some() || config.lod_budget.is_some() {
            self.lod.clear();
            self.lod_relative.clear();
            self.lod_budget.clear();
        }
        macro_rules! take {
            ($($f:ident),*) => { $( if let Some(v) = &config.$f { self.$f = v.clone(); } )* };
        }
        take!(
            level,
            tolerance,
            relative_tolerance,
            triangle_budget,
            max_segments,
            lod,
            lod_relative,
            lod_budget,
            lod_files,
            h,
            crease_angle,
            profile,
            scheme,
            nets,
            max_output_triangles,
            allow_outside_uris,
            overwrite_input,
            coons_lambda,
            coons_fair,
            keep_hard_edges,
            overdraw,
            quantize,
            compress,
            compress_fallback
        );
        self
    }

    /// Checks every range; `origin` names where the values came from.
    pub fn validate(&self, origin: &str) -> Result<(), ConfigError> {
        let err = |key: &str, what: String| {
            Err(ConfigError {
                at: format!("{origin}: {key}"),
                what,
            })
        };
        for (setting, value) in [
            (LEVEL, f64::from(self.level)),
            (H, self.h),
            (CREASE_ANGLE, self.crease_angle),
            (COONS_LAMBDA, self.coons_lambda),
        ] {
            if let Err(what) = setting.check(value) {
                return err(setting.key, what);
            }
        }
        if !(self.tolerance >= 0.0 && self.tolerance.is_finite()) {
            return err(
                "tolerance",
                format!("is {} (expected 0 or more world units)", self.tolerance),
            );
        }
        if !(0.0..=1.0).contains(&self.relative_tolerance) {
            return err(
                "relative_tolerance",
                format!(
                    "is {} (expected 0 to 1, a fraction of the bounding-box diagonal)",
                    self.relative_tolerance
                ),
            );
        }
        if !(1..=MAX_LEVEL).contains(&self.max_segments) {
            return err(
                "max_segments",
                format!("is {} (expected 1 to {MAX_LEVEL})", self.max_segments),
            );
        }
        self.validate_lod().or_else(|(key, what)| err(key, what))?;
        if self.max_output_triangles == 0 {
            return err("max_output_triangles", "is 0 (expected at least 1)".into());
        }
        Ok(())
    }

    /// The LOD lists' rules: one list at most, each value in the range of its single-level
    /// setting (and non-zero: a level that is off is no level), no value twice, at most
    /// [`MAX_LOD_LEVELS`] levels.
    fn validate_lod(&self) -> Result<(), (&'static str, String)> {
        let lists = [
            ("lod", self.lod.len()),
            ("lod_relative", self.lod_relative.len()),
            ("lod_budget", self.lod_budget.len()),
        ];
        let set: Vec<&str> = lists.iter().filter(|l| l.1 > 0).map(|l| l.0).collect();
        if let [first, second, ..] = set.as_slice() {
            return Err((
                second,
                format!("is set with {first} (expected one LOD list: tolerances, relative tolerances or budgets)"),
            ));
        }
        if let Some(&(key, n)) = lists.iter().find(|l| l.1 > MAX_LOD_LEVELS) {
            return Err((
                key,
                format!("has {n} levels (expected 1 to {MAX_LOD_LEVELS})"),
            ));
        }
        let values: Vec<f64> = self
            .lod
            .iter()
            .chain(&self.lod_relative)
            .copied()
            .chain(self.lod_budget.iter().map(|&b| b as f64))
            .collect();
        if self.lod_files && set.is_empty() {
            return Err((
                "lod_files",
                "is set without a LOD list (expected lod, lod_relative or lod_budget too)".into(),
            ));
        }
        let key = set.first().copied().unwrap_or("lod");
        for (i, &v) in values.iter().enumerate() {
            let ok = match key {
                "lod" => v > 0.0 && v.is_finite(),
                "lod_relative" => v > 0.0 && v <= 1.0,
                _ => v >= 1.0,
            };
            if !ok {
                let expected = match key {
                    "lod" => "more than 0 world units",
                    "lod_relative" => {
                        "more than 0 and at most 1, a fraction of the bounding-box diagonal"
                    }
                    _ => "at least 1 triangle",
                };
                return Err((key, format!("level {i} is {v} (expected {expected})")));
            }
            if values[..i].contains(&v) {
                return Err((
                    key,
                    format!("lists {v} twice (expected one value per level)"),
                ));
            }
        }
        Ok(())
    }

    /// The options of each level of the LOD chain, finest first (tolerances ascending, budgets
    /// descending): these options with the level's tolerance or budget and no other. Empty
    /// without a LOD list.
    pub fn lod_levels(&self) -> Vec<Options> {
        let level = |tolerance: f64, relative_tolerance: f64, triangle_budget: u64| Options {
            tolerance,
            relative_tolerance,
            triangle_budget,
            lod: Vec::new(),
            lod_relative: Vec::new(),
            lod_budget: Vec::new(),
            ..self.clone()
        };
        let ascending = |list: &[f64]| {
            let mut v = list.to_vec();
            v.sort_by(f64::total_cmp);
            v
        };
        let mut budgets = self.lod_budget.clone();
        budgets.sort_unstable_by(|a, b| b.cmp(a));
        ascending(&self.lod)
            .into_iter()
            .map(|t| level(t, 0.0, 0))
            .chain(
                ascending(&self.lod_relative)
                    .into_iter()
                    .map(|r| level(0.0, r, 0)),
            )
            .chain(budgets.into_iter().map(|b| level(0.0, 0.0, b)))
            .collect()
    }

    /// Whether each edge gets its own segment count (a tolerance or a budget is set).
    pub fn adaptive(&self) -> bool {
        self.tolerance > 0.0 || self.relative_tolerance > 0.0 || self.triangle_budget > 0
    }

    /// The surface parameters these options imply.
    pub fn scheme_params(&self) -> SchemeParams {
        SchemeParams {
            profile: self.profile,
            lambda: self.coons_lambda,
            fair: self.coons_fair,
            nets: self.nets,
            ..SchemeParams::default()
        }
    }

    /// The quantization these options ask for (octahedral normals when also compressing, since
    /// only a compressed output can carry the filter).
    pub fn quantization(&self) -> Option<crate::gltf_io::Quantization> {
        self.quantize
            .then(|| crate::gltf_io::Quantization::default().with_octahedral(self.compress))
    }

    /// The compression these options ask for.
    pub fn compression(&self) -> Option<crate::gltf_io::Compression> {
        self.compress
            .then(|| crate::gltf_io::Compression::new(self.compress_fallback))
    }

    /// The reader settings these options imply.
    pub fn read_options(&self) -> crate::gltf_io::ReadOptions {
        crate::gltf_io::ReadOptions {
            allow_outside_uris: self.allow_outside_uris,
            ..Default::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_keys_are_errors_with_a_line() {
        let e = ConfigFile::parse("level = 2\nlevle = 3\n", "x.toml").unwrap_err();
        assert_eq!(e.at, "x.toml:2");
    }

    #[test]
    fn out_of_range_h_is_refused() {
        let o = Options::default().overlay(&ConfigFile {
            h: Some(1.7),
            ..Default::default()
        });
        assert!(o
            .validate("--h")
            .unwrap_err()
            .what
            .contains("expected 0 to 0.3536"));
    }

    /// The printed bound of h is accepted (and clamped to √2/4 where used); just above it is
    /// not. Level, crease angle and λ refuse just past either end.
    #[test]
    fn ranges_accept_their_printed_ends() {
        for setting in RANGED_SETTINGS {
            assert!(setting.check(setting.min).is_ok(), "{}", setting.key);
            assert!(setting.check(setting.max).is_ok(), "{}", setting.key);
            let past = if setting.integer { 1.0 } else { 1e-4 };
            for bad in [setting.min - past, setting.max + past, f64::NAN] {
                let what = setting.check(bad).unwrap_err();
                assert!(what.contains(&setting.range_text()), "{what}");
            }
        }
        assert_eq!(H.max, 0.3536);
        assert_eq!(clamp_h(0.3536), MAX_H);
        assert_eq!(clamp_h(0.2), 0.2);
        let o = Options {
            h: 0.3536,
            ..Options::default()
        };
        assert!(o.validate("--h").is_ok());
    }
}
