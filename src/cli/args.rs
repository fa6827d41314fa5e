//! The command line as clap sees it: [`Args`], parsed once and turned into [`Options`].
//!
//! It deliberately holds no defaults of its own: every unset flag falls back to the config file,
//! then to the `DEFAULT_*` constants of [`g2tess::options`].

use std::path::PathBuf;

use clap::{Parser, ValueEnum};
use g2tess::options::{self, ConfigError, ConfigFile, Options};

/// Turns low-poly glTF meshes into dense, watertight G²-smooth meshes with exact normals.
///
/// Inputs are files and folders; folders are searched (sorted) for .gltf and .glb files, and
/// their outputs mirror the folder tree under -o. A g2tess.toml in a folder sets the defaults
/// of the assets below it (the nearest one wins; flags still override it).
///
/// Exit status: 0 every input done, 1 some input failed (the others were still processed),
/// 2 usage or configuration error.
#[derive(Debug, Parser)]
#[command(name = "g2tess", version, about, long_about = None, after_help = EXIT_HELP)]
pub struct Args {
    /// Input .gltf or .glb files, or folders to search for them
    #[arg(required = true, value_name = "INPUT")]
    pub inputs: Vec<PathBuf>,

    /// Output file (one input file), or folder (several inputs, or a folder input: outputs mirror
    /// the input folders below it) [default: INPUT's name with .smooth before the extension,
    /// beside it; a folder input needs -o]
    #[arg(short, long, value_name = "PATH")]
    pub output: Option<PathBuf>,

    /// Settings file in the format of config/default.toml; flags override it
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,

    /// Segments per input edge, 1 to 64 [default: 4]
    #[arg(long, help_heading = "Surface")]
    pub level: Option<u32>,

    /// Tessellate to this chord error in world units instead of --level: each edge gets its own
    /// segment count, flat parts stay coarse [default: off]
    #[arg(long, value_name = "E", help_heading = "Surface")]
    pub tolerance: Option<f64>,

    /// Chord error as a fraction of each mesh's bounding-box diagonal (e.g. 0.001) [default: off]
    #[arg(long, value_name = "F", help_heading = "Surface")]
    pub relative_tolerance: Option<f64>,

    /// Output triangles per mesh: the finest tolerance that fits [default: none]
    #[arg(long, value_name = "N", help_heading = "Surface")]
    pub triangle_budget: Option<u64>,

    /// Cap on segments per edge with a tolerance or budget, 1 to 64 [default: 64]
    #[arg(long, value_name = "N", help_heading = "Surface")]
    pub max_segments: Option<u32>,

    /// Write a LOD chain: one level of detail per chord tolerance in world units, comma-separated
    /// (e.g. 0.001,0.004,0.016), sharing one surface set-up; coarser levels are listed on each
    /// node with MSFT_lod (loaders without it show the finest) [default: off]
    #[arg(
        long,
        value_name = "E,E,..",
        value_delimiter = ',',
        help_heading = "Level of detail"
    )]
    pub lod: Vec<f64>,

    /// A LOD chain from tolerances relative to each mesh's bounding-box diagonal (e.g.
    /// 0.0005,0.002,0.008)
    #[arg(
        long,
        value_name = "F,F,..",
        value_delimiter = ',',
        help_heading = "Level of detail"
    )]
    pub lod_relative: Vec<f64>,

    /// A LOD chain from triangle budgets per mesh (e.g. 20000,5000,1200)
    #[arg(
        long,
        value_name = "N,N,..",
        value_delimiter = ',',
        help_heading = "Level of detail"
    )]
    pub lod_budget: Vec<u64>,

    /// Write each LOD level to its own file, OUTPUT's stem with _LOD0, _LOD1 ... (the LOD slot
    /// each is imported into, e.g. Unreal's Import LOD Level), instead of one file with MSFT_lod
    #[arg(long, help_heading = "Level of detail")]
    pub lod_files: bool,

    /// Blend width h of edges without their own, 0 to 0.3536 [default: 0.212]
    #[arg(long, help_heading = "Surface")]
    pub h: Option<f64>,

    /// Edges sharper than this many degrees get h = 0, 0 to 180 [default: 60]
    #[arg(long, help_heading = "Surface")]
    pub crease_angle: Option<f64>,

    /// Blend profile [default: c2]
    #[arg(long, value_enum, help_heading = "Surface")]
    pub profile: Option<ProfileArg>,

    /// Surface scheme [default: g2]
    #[arg(long, value_enum, help_heading = "Surface")]
    pub scheme: Option<SchemeArg>,

    /// Control nets under g2 and pn: round (circle-following) or paper (PN as published)
    /// [default: round]
    #[arg(long, value_enum, help_heading = "Surface")]
    pub nets: Option<NetsArg>,

    /// Coons shape parameter λ (Szilvási-Nagy and Szabó's Coons-type blending), 0.05 to 0.95
    /// [default: 0.5]
    #[arg(long, value_name = "L", help_heading = "Surface")]
    pub coons_lambda: Option<f64>,

    /// Coons: choose λ per triangle by thin-plate fairing instead of --coons-lambda
    #[arg(long, help_heading = "Surface")]
    pub coons_fair: bool,

    /// Give hard edges of the input (split normals) h = 0
    #[arg(long, help_heading = "Surface")]
    pub keep_hard_edges: bool,

    /// Sidecar with per-mesh and per-edge h, instead of <asset>.g2tess.toml beside each asset
    #[arg(long, value_name = "FILE", help_heading = "Surface")]
    pub sidecar: Option<PathBuf>,

    /// Print, for mesh N (index or name), which source set each edge's h, and exit
    #[arg(long, value_name = "MESH", help_heading = "Surface")]
    pub explain_h: Option<String>,

    /// Write a JSON report to FILE: one record per input (status, error, counts, sizes, times,
    /// continuity), field names as in the README
    #[arg(long, value_name = "FILE", help_heading = "Output")]
    pub report: Option<PathBuf>,

    /// Print the seconds spent in each stage for every file
    #[arg(long, help_heading = "Output")]
    pub timings: bool,

    /// Order triangles to reduce overdraw (meshoptimizer; the tessellator's own order is already cache-friendly)
    #[arg(long, help_heading = "Output")]
    pub overdraw: bool,

    /// Refuse outputs with more triangles than this per file (memory: about 32 bytes each, up to
    /// 400 with UVs and generated tangents, plus about 240 per input triangle)
    /// [default: 20000000]
    #[arg(
        long,
        visible_alias = "max-output-triangles",
        value_name = "N",
        help_heading = "Output"
    )]
    pub max_triangles: Option<u64>,

    /// Store attributes quantized (KHR_mesh_quantization): positions 14 bits, normals and
    /// tangents 8 bits, UVs in [0, 1] 12 bits; skinned positions and other UVs stay float
    #[arg(long, help_heading = "Output")]
    pub quantize: bool,

    /// Compress buffers (EXT_meshopt_compression; loaders then require it)
    #[arg(long, help_heading = "Output")]
    pub compress: bool,

    /// With --compress, also write the uncompressed data to OUTPUT.fallback.bin
    #[arg(long, help_heading = "Output", requires = "compress")]
    pub compress_fallback: bool,

    /// Allow an output to replace an input file (or a buffer or image file it refers to)
    #[arg(long, help_heading = "Safety")]
    pub overwrite_input: bool,

    /// Allow uris that leave the asset's folder (.., absolute paths); network uris are never read
    #[arg(long, help_heading = "Safety")]
    pub allow_outside_uris: bool,

    /// Files processed at once, and threads for the work inside a file; each file in flight
    /// holds its document in memory [default: RAYON_NUM_THREADS if set, else the number of CPUs]
    #[arg(short, long, value_name = "N", help_heading = "Batch")]
    pub jobs: Option<usize>,

    /// Only take assets found in folders whose path below the folder matches GLOB (`*.glb`,
    /// `props/**`); a GLOB without `/` matches the file name. Repeatable
    #[arg(long, value_name = "GLOB", help_heading = "Batch")]
    pub include: Vec<String>,

    /// Skip assets and folders whose path below the searched folder matches GLOB; wins over
    /// --include. Repeatable
    #[arg(long, value_name = "GLOB", help_heading = "Batch")]
    pub exclude: Vec<String>,

    /// Process every input again, even when its output is up to date
    #[arg(long, help_heading = "Batch")]
    pub force: bool,

    /// Write nothing; exit 1 if any output is missing or differs from what a run would write
    #[arg(long, help_heading = "Batch", conflicts_with_all = ["watch", "force"])]
    pub check: bool,

    /// Stop at the first failed input (files already started still finish)
    #[arg(long, help_heading = "Batch")]
    pub fail_fast: bool,

    /// Print errors only
    #[arg(short, long, help_heading = "Batch", conflicts_with = "verbose")]
    pub quiet: bool,

    /// Also print skipped files and every warning
    #[arg(short, long, help_heading = "Batch")]
    pub verbose: bool,

    /// After the first run, keep watching the inputs and process what changes (Ctrl-C stops)
    #[arg(long, help_heading = "Watch")]
    pub watch: bool,

    /// With --watch: delete the outputs of deleted inputs
    #[arg(long, help_heading = "Watch", requires = "watch")]
    pub delete: bool,

    /// With --watch: poll instead of using the file system's notifications (network drives,
    /// some containers); reads every watched file at each scan, so suits modest trees
    #[arg(long, help_heading = "Watch", requires = "watch")]
    pub poll: bool,

    /// With --watch: wait until files have been quiet this many milliseconds [default: 200]
    #[arg(long, value_name = "MS", help_heading = "Watch", requires = "watch")]
    pub debounce: Option<u64>,

    /// Print every file a run would read (assets, their buffers and images, sidecars, folder
    /// configs, --config) and exit without processing: one per line, or with `json` one record
    /// per input with what it reads, could read once created, and writes
    #[arg(long, value_name = "FORMAT", value_enum, num_args = 0..=1, require_equals = true,
        default_missing_value = "lines", help_heading = "Build systems",
        conflicts_with_all = ["watch", "check", "merge_reports"])]
    pub print_inputs: Option<InputsFormat>,

    /// Write a Makefile-style depfile OUTPUT.d beside each output, listing the files it was made
    /// from (the format of gcc -MD, read by Make and Ninja's `depfile`)
    #[arg(long, help_heading = "Build systems", conflicts_with = "check")]
    pub depfile: bool,

    /// Process only shard K of N (1-based): an input belongs to the shard given by a hash of its
    /// path, so every input is in exactly one shard whatever else the tree holds
    #[arg(long, value_name = "K/N", value_parser = super::shard::Shard::parse,
        help_heading = "Build systems", conflicts_with = "watch")]
    pub shard: Option<super::shard::Shard>,

    /// Merge the JSON reports given as INPUTs (e.g. one per shard) into FILE and exit with the
    /// merged exit status
    #[arg(long, value_name = "FILE", help_heading = "Build systems")]
    pub merge_reports: Option<PathBuf>,
    /// Draw the INPUTs side by side (one camera, same scale) into the PNG -o names, and exit
    /// without processing [default: the first INPUT's name with .png]
    #[arg(long, help_heading = "Pictures", conflicts_with_all = ["watch", "check", "explain_h"])]
    pub render: bool,

    /// Write a PNG per processed asset into DIR (named after its output, with .png added):
    /// input and output side by side
    #[arg(long, value_name = "DIR", help_heading = "Pictures")]
    pub previews: Option<PathBuf>,

    /// Write an HTML report to FILE: a table of every input (status, triangles, sizes, times,
    /// warnings, errors) and per asset its pictures (embedded) and continuity figures
    #[arg(long, value_name = "FILE", help_heading = "Pictures")]
    pub html_report: Option<PathBuf>,

    /// Picture rows, comma-separated: shaded (the normals lit), zebra (reflection lines),
    /// flat (the triangles), h (the input's edges: blue blended, darker for larger h; red
    /// crease; orange open; magenta non-manifold) [default: shaded,zebra,h]
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        value_name = "MODES",
        help_heading = "Pictures"
    )]
    pub render_modes: Vec<RenderModeArg>,

    /// Picture views, comma-separated: front, side, top, iso [default: front,side,top,iso]
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        value_name = "VIEWS",
        help_heading = "Pictures"
    )]
    pub render_views: Vec<RenderViewArg>,

    /// Side of each picture panel in pixels, 16 to 4096 [default: 320]
    #[arg(long, value_name = "PX", help_heading = "Pictures", value_parser = clap::value_parser!(u32).range(16..=4096))]
    pub render_size: Option<u32>,
}

/// Default of `--render-size`: four views of input and output fit a wide screen.
const DEFAULT_RENDER_SIZE: u32 = 320;

const EXIT_HELP: &str = "Exit status: 0 every input done (or up to date), 1 some input failed or, with --check, some output is not current (the others were still processed), 2 usage or configuration error, 130 stopped by Ctrl-C before the end (the files in flight were finished; --watch ends with 0).";

/// `--print-inputs` formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum InputsFormat {
    /// Every file once, one per line, in the order first read
    Lines,
    /// One JSON document with a record per input
    Json,
}

/// `--profile` values.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum ProfileArg {
    /// As published (C¹ where its pieces meet)
    Paper,
    /// C² everywhere
    C2,
}

/// `--nets` values.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum NetsArg {
    /// Edge curves that follow circular arcs, centre by a side-vertex rule
    Round,
    /// PN triangles as published (Vlachos et al., seed 000 Eq. 2)
    Paper,
}

/// `--scheme` values.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum SchemeArg {
    /// G²-blended PN triangles
    G2,
    /// Plain PN triangles
    Pn,
    /// Mann–Davidchuk parametric hybrid patches (G¹)
    Hybrid,
    /// Szilvási-Nagy–Szabó C¹ Coons-type blending (G¹)
    Coons,
}

/// `--render-modes` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RenderModeArg {
    /// Lambert with the mesh's normals
    Shaded,
    /// Reflection-line stripes
    Zebra,
    /// Lambert with face normals
    Flat,
    /// The first input's edges coloured by resolved h
    H,
}

/// `--render-views` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RenderViewArg {
    /// From +Z
    Front,
    /// From +X
    Side,
    /// From +Y
    Top,
    /// From (1, 1, 1)
    Iso,
}

impl Args {
    /// The picture settings of `--render-modes`, `--render-views` and `--render-size`.
    pub fn picture_settings(&self) -> g2tess::render::Settings {
        use g2tess::render::{Mode, View};
        let modes = match self.render_modes.is_empty() {
            true => vec![Mode::Shaded, Mode::Zebra, Mode::H],
            false => self
                .render_modes
                .iter()
                .map(|m| match m {
                    RenderModeArg::Shaded => Mode::Shaded,
                    RenderModeArg::Zebra => Mode::Zebra,
                    RenderModeArg::Flat => Mode::Flat,
                    RenderModeArg::H => Mode::H,
                })
                .collect(),
        };
        let views = match self.render_views.is_empty() {
            true => View::ALL.to_vec(),
            false => self
                .render_views
                .iter()
                .map(|v| match v {
                    RenderViewArg::Front => View::Front,
                    RenderViewArg::Side => View::Side,
                    RenderViewArg::Top => View::Top,
                    RenderViewArg::Iso => View::Iso,
                })
                .collect(),
        };
        g2tess::render::Settings {
            modes,
            views,
            size: self.render_size.unwrap_or(DEFAULT_RENDER_SIZE),
        }
    }

    /// The settings in their layers, so that a folder's `g2tess.toml` can slot in between the
    /// `--config` file and the flags.
    pub fn layers(&self) -> Result<Layers, ConfigError> {
        let mut base = Options::default();
        if let Some(path) = &self.config {
            let shown = path.display().to_string();
            let text = std::fs::read_to_string(path).map_err(|e| ConfigError {
                at: shown.clone(),
                what: e.to_string().to_lowercase(),
            })?;
            let file = ConfigFile::parse(&text, &shown)?;
            base = base.overlay(&file);
            base.validate(&shown)?;
        }
        let layers = Layers {
            base,
            flags: self.flag_settings(),
            sidecar: self.sidecar.clone(),
            report_figures: self.report.is_some() || self.html_report.is_some(),
        };
        layers.resolve(None)?;
        Ok(layers)
    }

    fn flag_settings(&self) -> ConfigFile {
        ConfigFile {
            level: self.level,
            tolerance: self.tolerance,
            relative_tolerance: self.relative_tolerance,
            triangle_budget: self.triangle_budget,
            max_segments: self.max_segments,
            lod: (!self.lod.is_empty()).then(|| self.lod.clone()),
            lod_relative: (!self.lod_relative.is_empty()).then(|| self.lod_relative.clone()),
            lod_budget: (!self.lod_budget.is_empty()).then(|| self.lod_budget.clone()),
            lod_files: self.lod_files.then_some(true),
            h: self.h,
            crease_angle: self.crease_angle,
            profile: self.profile.map(|p| match p {
                ProfileArg::Paper => options::Profile::Paper,
                ProfileArg::C2 => options::Profile::C2,
            }),
            scheme: self.scheme.map(|s| match s {
                SchemeArg::G2 => options::Scheme::G2,
                SchemeArg::Pn => options::Scheme::Pn,
                SchemeArg::Hybrid => options::Scheme::Hybrid,
                SchemeArg::Coons => options::Scheme::Coons,
            }),
            nets: self.nets.map(|n| match n {
                NetsArg::Round => options::Nets::Round,
                NetsArg::Paper => options::Nets::Paper,
            }),
            max_output_triangles: self.max_triangles,
            allow_outside_uris: self.allow_outside_uris.then_some(true),
            coons_lambda: self.coons_lambda,
            coons_fair: self.coons_fair.then_some(true),
            overwrite_input: self.overwrite_input.then_some(true),
            keep_hard_edges: self.keep_hard_edges.then_some(true),
            overdraw: self.overdraw.then_some(true),
            quantize: self.quantize.then_some(true),
            compress: self.compress.then_some(true),
            compress_fallback: self.compress_fallback.then_some(true),
        }
    }
}

/// Settings before a folder's `g2tess.toml` is known: defaults with `--config` applied, and the
/// flags that override everything.
#[derive(Debug, Clone)]
pub struct Layers {
    base: Options,
    flags: ConfigFile,
    sidecar: Option<PathBuf>,
    /// A report will be written: compute the figures only it shows.
    report_figures: bool,
}

impl Layers {
    /// The options of an asset under the folder config `dir` (its parsed text and its file name
    /// for messages): base ← folder config ← flags.
    pub fn resolve(&self, dir: Option<(&ConfigFile, &str)>) -> Result<Options, ConfigError> {
        let mut opts = self.base.clone();
        if let Some((file, origin)) = dir {
            opts = opts.overlay(file);
            opts.validate(origin)?;
        }
        let mut opts = opts.overlay(&self.flags);
        opts.sidecar = self.sidecar.clone();
        opts.report_figures = self.report_figures;
        // Ctrl-C and SIGTERM stop the file in flight between its stages, not after it.
        opts.cancel = options::Cancel::on(super::interrupt::flag());
        opts.validate("command line")?;
        Ok(opts)
    }
}
