//! Reads the `"g2tess"` key of a mesh's or primitive's glTF `extras` into a [`Block`], with every
//! mistake located by its JSON path. It deliberately does not match edges against the mesh.

use std::path::Path;
use std::sync::Arc;

use glam::DVec3;
use serde_json::{Map, Value};

use super::entries::{at, check_crease_angle, check_h, Block, EdgeEntry, Located, RawEdgeFields};
use super::error::{Location, Problem, SharpnessError};

/// The key under `extras` that holds our settings; everything else in `extras` belongs to others.
pub const EXTRAS_KEY: &str = "g2tess";

/// Whose `extras` a block came from: on a primitive, an edge's `primitive` is implied.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Owner {
    Mesh,
    Primitive,
}

const BLOCK_KEYS: &str = "`h`, `crease_angle`, `edges`";
const MESH_EDGE_KEYS: &str = "`primitive`, `a`, `b`, `from`, `to`, `h`";
const PRIMITIVE_EDGE_KEYS: &str = "`a`, `b`, `from`, `to`, `h`";

/// Parses `extras.g2tess` of the object at `base` (`meshes[2]` or `meshes[2].primitives[0]`).
///
/// `extras` that is not an object, or has no `g2tess` key, is someone else's: `Ok(None)`.
pub(crate) fn parse_block(
    file: &Path,
    base: &str,
    extras: Option<&Value>,
    owner: Owner,
) -> Result<Option<Block>, SharpnessError> {
    let Some(value) = extras
        .and_then(Value::as_object)
        .and_then(|o| o.get(EXTRAS_KEY))
    else {
        return Ok(None);
    };
    let path = format!("{base}.extras.{EXTRAS_KEY}");
    let loc = |p: &str| Location::Json {
        file: file.to_path_buf(),
        path: p.to_string(),
    };
    let object = as_object(value).map_err(|e| at(&loc(&path), e))?;
    let mut block = Block::default();
    for (key, value) in object {
        let key_path = format!("{path}.{key}");
        let here = loc(&key_path);
        match key.as_str() {
            "h" => {
                let h = number(value).and_then(check_h).map_err(|e| at(&here, e))?;
                block.h = Some(Located {
                    value: h,
                    at: Arc::new(here),
                });
            }
            "crease_angle" => {
                let angle = number(value)
                    .and_then(check_crease_angle)
                    .map_err(|e| at(&here, e))?;
                block.crease_angle = Some(Located {
                    value: angle,
                    at: Arc::new(here),
                });
            }
            "edges" => {
                let list = value
                    .as_array()
                    .ok_or_else(|| at(&here, wrong_type("an array of edge entries", value)))?;
                for (i, entry) in list.iter().enumerate() {
                    let entry_path = format!("{key_path}[{i}]");
                    block
                        .edges
                        .push(parse_edge(file, &entry_path, entry, owner)?);
                }
            }
            _ => {
                return Err(at(
                    &here,
                    Problem::UnknownKey {
                        key: key.clone(),
                        expected: BLOCK_KEYS,
                    },
                ))
            }
        }
    }
    Ok(Some(block))
}

fn parse_edge(
    file: &Path,
    path: &str,
    value: &Value,
    owner: Owner,
) -> Result<EdgeEntry, SharpnessError> {
    let loc = |p: String| Location::Json {
        file: file.to_path_buf(),
        path: p,
    };
    let entry_loc = loc(path.to_string());
    let object = as_object(value).map_err(|e| at(&entry_loc, e))?;
    let mut fields = RawEdgeFields::default();
    let mut h = None;
    for (key, value) in object {
        let here = loc(format!("{path}.{key}"));
        let fail = |e| at(&here, e);
        match (key.as_str(), owner) {
            ("primitive", Owner::Mesh) => {
                fields.primitive = Some(index(value).map_err(fail)? as usize)
            }
            ("primitive", Owner::Primitive) => return Err(fail(Problem::PrimitiveImplied)),
            ("a", _) => fields.a = Some(index(value).map_err(fail)?),
            ("b", _) => fields.b = Some(index(value).map_err(fail)?),
            ("from", _) => fields.from = Some(point(value).map_err(fail)?),
            ("to", _) => fields.to = Some(point(value).map_err(fail)?),
            ("h", _) => h = Some(number(value).and_then(check_h).map_err(fail)?),
            _ => {
                let expected = match owner {
                    Owner::Mesh => MESH_EDGE_KEYS,
                    Owner::Primitive => PRIMITIVE_EDGE_KEYS,
                };
                return Err(fail(Problem::UnknownKey {
                    key: key.clone(),
                    expected,
                }));
            }
        }
    }
    let h = h.ok_or_else(|| at(&entry_loc, Problem::MissingKey { key: "h" }))?;
    let name = fields.into_name().map_err(|e| at(&entry_loc, e))?;
    Ok(EdgeEntry {
        name,
        h,
        at: Arc::new(entry_loc),
    })
}

fn as_object(value: &Value) -> Result<&Map<String, Value>, Problem> {
    value
        .as_object()
        .ok_or_else(|| wrong_type("an object", value))
}

fn number(value: &Value) -> Result<f64, Problem> {
    value.as_f64().ok_or_else(|| wrong_type("a number", value))
}

fn index(value: &Value) -> Result<u64, Problem> {
    value
        .as_u64()
        .ok_or_else(|| wrong_type("a non-negative integer", value))
}

fn point(value: &Value) -> Result<DVec3, Problem> {
    let expected = "a position [x, y, z]";
    match value.as_array().map(Vec::as_slice) {
        Some([x, y, z]) => match (x.as_f64(), y.as_f64(), z.as_f64()) {
            (Some(x), Some(y), Some(z)) => Ok(DVec3::new(x, y, z)),
            _ => Err(wrong_type(expected, value)),
        },
        _ => Err(wrong_type(expected, value)),
    }
}

/// Names what the user wrote, shortened, so a wrong type is recognisable in the message.
fn wrong_type(expected: &'static str, value: &Value) -> Problem {
    let got = match value {
        Value::Null => "null".to_string(),
        Value::Bool(b) => b.to_string(),
        Value::Number(n) => n.to_string(),
        Value::String(s) => format!("the string {s:?}"),
        Value::Array(a) => format!("an array of {} elements", a.len()),
        Value::Object(_) => "an object".to_string(),
    };
    Problem::WrongType { expected, got }
}
