//! Errors of per-edge h resolution: where the mistake is (file plus JSON path or TOML line) and
//! what was expected. It deliberately holds no parsing or resolution logic and never prints.

use std::fmt;
use std::path::PathBuf;

/// Where a value or a mistake sits: shown in front of every error message and in explain rows.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Location {
    /// A JSON path inside the asset, e.g. `meshes[2].extras.g2tess.edges[5].h`.
    Json { file: PathBuf, path: String },
    /// A line of the sidecar, with the key path inside its section when that helps (`edges[1]`).
    Toml {
        file: PathBuf,
        line: usize,
        path: String,
    },
    /// A file as a whole (it could not be read).
    File { file: PathBuf },
    /// The resolved options (`--h`, `--crease-angle`, or `config/default.toml`).
    Options,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Json { file, path } => write!(f, "{}: {path}", file.display()),
            Location::Toml { file, line, path } if path.is_empty() => {
                write!(f, "{}:{line}", file.display())
            }
            Location::Toml { file, line, path } => write!(f, "{}:{line}: {path}", file.display()),
            Location::File { file } => write!(f, "{}", file.display()),
            Location::Options => f.write_str("options"),
        }
    }
}

/// A user mistake in one of the h sources, located precisely.
///
/// Displays as `robot.glb: meshes[2].extras.g2tess.edges[5].h: h must be in [0, 0.3536], got 1.7`
/// or `robot.g2tess.toml:12: edges[1]: edge (12, 40) does not exist in primitive 0 of mesh "Body"`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}: {}", .0.location, .0.problem)]
pub struct SharpnessError(Box<Located>);

/// Boxed so that `Result<_, SharpnessError>` stays one pointer wide on the happy path.
#[derive(Debug, Clone, PartialEq)]
struct Located {
    location: Location,
    problem: Problem,
}

/// What is wrong, independent of where. `mesh` fields hold a ready label (`mesh "Body"`, `mesh 3`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Problem {
    #[error("h must be in [{}, {}], got {got}", crate::options::H.min, crate::options::H.max)]
    HOutOfRange { got: f64 },
    #[error("crease_angle must be in [{}, {}] degrees, got {got}", crate::options::CREASE_ANGLE.min, crate::options::CREASE_ANGLE.max)]
    CreaseAngleOutOfRange { got: f64 },
    #[error("level must be in [{}, {}], got {got}", crate::options::LEVEL.min, crate::options::LEVEL.max)]
    LevelOutOfRange { got: i64 },
    /// A density key out of the range its flag has, in the options' words
    /// (`is -1 (expected 0 or more world units)`).
    #[error("{what}")]
    Setting { what: String },
    #[error("expected {expected}, got {got}")]
    WrongType { expected: &'static str, got: String },
    #[error("unknown key `{key}`, expected one of {expected}")]
    UnknownKey { key: String, expected: &'static str },
    #[error("missing key `{key}`")]
    MissingKey { key: &'static str },
    /// A TOML syntax or type error, in the parser's words.
    #[error("{message}")]
    Toml { message: String },
    #[error("an edge is named either by `a` and `b` or by `from` and `to`, {found}")]
    EdgeForm { found: &'static str },
    #[error("`primitive` is implied in a primitive's extras, remove it")]
    PrimitiveImplied,
    #[error(
        "`primitive` only applies to `a` and `b`; `from` and `to` are matched over the whole mesh"
    )]
    PrimitiveWithPositions,
    #[error("`primitive` is required: {mesh} has {count} primitives")]
    PrimitiveRequired { mesh: String, count: usize },
    #[error("{mesh} has no triangle primitive {primitive} (triangle primitives: {known})")]
    NoSuchPrimitive {
        primitive: usize,
        mesh: String,
        known: String,
    },
    #[error(
        "vertex {index} is out of range: primitive {primitive} of {mesh} has {count} vertices"
    )]
    VertexOutOfRange {
        index: u64,
        primitive: usize,
        mesh: String,
        count: u32,
    },
    #[error("edge ({a}, {b}) does not exist in primitive {primitive} of {mesh}")]
    NoSuchEdge {
        a: u64,
        b: u64,
        primitive: usize,
        mesh: String,
    },
    #[error("no edge between {from} and {to} in {mesh}")]
    NoEdgeBetween {
        from: String,
        to: String,
        mesh: String,
    },
    #[error("both ends of the edge are the same point of {mesh}")]
    DegenerateEdge { mesh: String },
    #[error("no vertex of {mesh} within {tolerance:.3e} of {at}")]
    NoVertexAt {
        at: String,
        tolerance: f64,
        mesh: String,
    },
    #[error("{count} vertices of {mesh} lie within {tolerance:.3e} of {at}, the edge is ambiguous; use `a` and `b`")]
    AmbiguousVertex {
        at: String,
        count: usize,
        tolerance: f64,
        mesh: String,
    },
    #[error("edge {edge} has two entries with different h: {h} here, {other_h} at {other}")]
    Conflict {
        edge: String,
        h: f64,
        other_h: f64,
        other: String,
    },
    #[error("no mesh named \"{name}\" (meshes: {known})")]
    NoSuchMeshName { name: String, known: String },
    #[error("no mesh {index} (mesh count: {count})")]
    NoSuchMeshIndex { index: usize, count: usize },
    #[error("mesh name \"{name}\" is shared by meshes {indices}; name the section by index, e.g. [mesh.{first}]")]
    AmbiguousMeshName {
        name: String,
        indices: String,
        first: usize,
    },
    #[error("{mesh} already has a section at line {other_line}")]
    DuplicateMeshSection { mesh: String, other_line: usize },
    #[error("cannot read: {message}")]
    Read { message: String },
    /// The caller passed inconsistent data; a bug in the pipeline, not a user mistake.
    #[error("internal error, please report: {message}")]
    Internal { message: String },
}

impl SharpnessError {
    pub(crate) fn new(location: Location, problem: Problem) -> Self {
        SharpnessError(Box::new(Located { location, problem }))
    }

    /// Where the mistake is.
    pub fn location(&self) -> &Location {
        &self.0.location
    }

    /// What is wrong.
    pub fn problem(&self) -> &Problem {
        &self.0.problem
    }
}
