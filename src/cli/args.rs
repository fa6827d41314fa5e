//! The command line as clap sees it: [`Args`], parsed once and turned into [`Options`].
//!
//! It deliberately holds no defaults of its own: every unset flag falls back to the config file,
//! then to the `DEFAULT_*` constants of [`g2tess::options`].

use std::path::PathBuf;

use clap::{Parser, ValueEnum};
use g2tess::options::{self, ConfigError, ConfigFile, Options};

/// Turns low-poly glTF meshes into dense, watertight G²-smooth meshes with exact normals.
///
/// Exit status: 0 every input done, 1 some input failed (the others were still processed),
/// 2 usage or configuration error.
#[derive(Debug, Parser)]
#[command(name = "g2tess", version, about, long_about = None, after_help = EXIT_HELP)]
pub struct Args {
    /// Input .gltf or .glb files
    #[arg(required = true, value_name = "INPUT")]
    pub inputs: Vec<PathBuf>,

    /// Output file (.glb or .gltf), or a folder when there are several inputs
    /// [default: INPUT's name with .smooth before the extension, beside it]
    #[arg(short, long, value_name = "PATH")]
    pub output: Option<PathBuf>,

    /// Settings file in the format of config/default.toml; flags override it
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,

    /// Segments per input edge, 1 to 64 [default: 4]
    #[arg(long, help_heading = "Surface")]
    pub level: Option<u32>,

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

    /// Coons shape parameter λ of seed 002, 0.05 to 0.95 [default: 0.5]
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

    /// Write a JSON report (counts, timings, continuity, warnings per file) to FILE
    #[arg(long, value_name = "FILE", help_heading = "Output")]
    pub report: Option<PathBuf>,

    /// Print the seconds spent in each stage for every file
    #[arg(long, help_heading = "Output")]
    pub timings: bool,

    /// Keep the tessellator's triangle and vertex order (skip meshoptimizer's ordering)
    #[arg(long, help_heading = "Output")]
    pub no_optimize: bool,

    /// Also order triangles to reduce overdraw
    #[arg(long, help_heading = "Output")]
    pub overdraw: bool,

    /// Refuse outputs with more triangles than this per file [default: 50000000]
    #[arg(long, value_name = "N", help_heading = "Output")]
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

    /// Allow overwriting an input file
    #[arg(long, help_heading = "Safety")]
    pub force: bool,

    /// Allow uris that leave the asset's folder (.., absolute paths); network uris are never read
    #[arg(long, help_heading = "Safety")]
    pub allow_outside_uris: bool,
}

const EXIT_HELP: &str = "Exit status: 0 every input done, 1 some input failed (the others were still processed), 2 usage or configuration error.";

/// `--profile` values.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum ProfileArg {
    /// As published (C¹ where its pieces meet)
    Paper,
    /// C² everywhere
    C2,
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

impl Args {
    /// Resolves defaults ← config file ← flags into one checked [`Options`].
    pub fn options(&self) -> Result<Options, ConfigError> {
        let mut opts = Options::default();
        if let Some(path) = &self.config {
            let shown = path.display().to_string();
            let text = std::fs::read_to_string(path).map_err(|e| ConfigError {
                at: shown.clone(),
                what: e.to_string().to_lowercase(),
            })?;
            let file = ConfigFile::parse(&text, &shown)?;
            opts = opts.overlay(&file);
            opts.validate(&shown)?;
        }
        let flags = ConfigFile {
            level: self.level,
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
            max_output_triangles: self.max_triangles,
            allow_outside_uris: self.allow_outside_uris.then_some(true),
            force: self.force.then_some(true),
            coons_lambda: self.coons_lambda,
            coons_fair: self.coons_fair.then_some(true),
            keep_hard_edges: self.keep_hard_edges.then_some(true),
            optimize: self.no_optimize.then_some(false),
            overdraw: self.overdraw.then_some(true),
            quantize: self.quantize.then_some(true),
            compress: self.compress.then_some(true),
            compress_fallback: self.compress_fallback.then_some(true),
        };
        let mut opts = opts.overlay(&flags);
        opts.sidecar = self.sidecar.clone();
        opts.validate("command line")?;
        Ok(opts)
    }
}
