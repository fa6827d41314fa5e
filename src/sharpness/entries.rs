//! The parsed, range-checked content of one `g2tess` block (extras or sidecar section), common to
//! both formats. It deliberately knows neither JSON nor TOML, nor the mesh the entries refer to.

use std::sync::Arc;

use glam::DVec3;

use super::error::{Location, Problem, SharpnessError};

/// A value together with where it was written, so precedence winners can be explained.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Located<T> {
    pub value: T,
    pub at: Arc<Location>,
}

/// One block of settings: an extras `g2tess` object or a sidecar section.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Block {
    pub h: Option<Located<f64>>,
    pub crease_angle: Option<Located<f64>>,
    pub edges: Vec<EdgeEntry>,
}

/// One entry of an `edges` list, not yet matched against the mesh.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct EdgeEntry {
    pub name: EdgeName,
    pub h: f64,
    /// The entry itself (`...edges[3]`): errors about the edge and explain rows point here.
    pub at: Arc<Location>,
}

/// The two ways to name an edge.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum EdgeName {
    /// Vertex indices of a primitive; `primitive` is `None` when implied or left to default.
    Indices {
        primitive: Option<usize>,
        a: u64,
        b: u64,
    },
    /// End positions, matched against welded vertices within a tolerance.
    Positions { from: DVec3, to: DVec3 },
}

/// The raw fields of an edge entry, before the form check shared by both formats.
#[derive(Debug, Default)]
pub(crate) struct RawEdgeFields {
    pub primitive: Option<usize>,
    pub a: Option<u64>,
    pub b: Option<u64>,
    pub from: Option<DVec3>,
    pub to: Option<DVec3>,
}

impl RawEdgeFields {
    /// Accepts exactly one complete form: `a` and `b` (optionally `primitive`) or `from` and `to`.
    pub fn into_name(self) -> Result<EdgeName, Problem> {
        let by_index = self.a.is_some() || self.b.is_some();
        let by_position = self.from.is_some() || self.to.is_some();
        match (by_index, by_position) {
            (true, true) => Err(Problem::EdgeForm { found: "not both" }),
            (false, false) => Err(Problem::EdgeForm {
                found: "found neither",
            }),
            (true, false) => match (self.a, self.b) {
                (Some(a), Some(b)) => Ok(EdgeName::Indices {
                    primitive: self.primitive,
                    a,
                    b,
                }),
                (None, _) => Err(Problem::MissingKey { key: "a" }),
                (_, None) => Err(Problem::MissingKey { key: "b" }),
            },
            (false, true) => {
                if self.primitive.is_some() {
                    return Err(Problem::PrimitiveWithPositions);
                }
                match (self.from, self.to) {
                    (Some(from), Some(to)) => Ok(EdgeName::Positions { from, to }),
                    (None, _) => Err(Problem::MissingKey { key: "from" }),
                    (_, None) => Err(Problem::MissingKey { key: "to" }),
                }
            }
        }
    }
}

/// h is a length in the paper's reference triangle, so its range is fixed: out of range is a
/// mistake to report, never a value to clamp silently. The range is the options' one
/// ([`crate::options::H`]); the printed bound 0.3536 is accepted and becomes √2/4.
pub(crate) fn check_h(h: f64) -> Result<f64, Problem> {
    match crate::options::H.check(h) {
        Ok(h) => Ok(crate::options::clamp_h(h)),
        Err(_) => Err(Problem::HOutOfRange { got: h }),
    }
}

/// The crease angle is the angle between two face normals, so it lives in [0, 180] degrees
/// ([`crate::options::CREASE_ANGLE`]).
pub(crate) fn check_crease_angle(degrees: f64) -> Result<f64, Problem> {
    crate::options::CREASE_ANGLE
        .check(degrees)
        .map_err(|_| Problem::CreaseAngleOutOfRange { got: degrees })
}

/// A sidecar's `level` follows the same rule as `--level` ([`crate::options::LEVEL`]).
pub(crate) fn check_level(level: i64) -> Result<u32, Problem> {
    match crate::options::LEVEL.check(level as f64) {
        Ok(_) => Ok(level as u32),
        Err(_) => Err(Problem::LevelOutOfRange { got: level }),
    }
}

/// Shorthand for an error at a location.
pub(crate) fn at(location: &Location, problem: Problem) -> SharpnessError {
    SharpnessError::new(location.clone(), problem)
}

/// Formats a point the way users write it: `[0, 1, 0.5]`.
pub(crate) fn fmt_point(p: DVec3) -> String {
    format!("[{}, {}, {}]", p.x, p.y, p.z)
}
