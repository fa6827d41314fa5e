//! KHR_draco_mesh_compression: a compressed triangle primitive decoded into the same plain
//! arrays an uncompressed one gives, so that the rest of the tool never sees the difference.
//!
//! The primitive's own accessors describe the decoded data (count, type, component type,
//! `normalized`) but hold no bytes; the extension names the buffer view of the Draco stream and,
//! per attribute, its id in the stream. The decoder is draco-oxide (pure Rust, bitstream 2.2,
//! interoperable with Google's Draco). The smoothed primitive is written uncompressed, and the
//! extension is dropped from it.

use draco_oxide_decoder as draco;
use gltf_json::accessor::ComponentType;
use gltf_json::validation::Checked;
use serde_json::{Map, Value};

use super::accessor::type_components;
use super::document::Document;
use super::error::{Error, Result};
use super::primitive::{Attribute, Values};

/// The extension's name.
pub const EXTENSION: &str = "KHR_draco_mesh_compression";

/// Decodes the Draco stream of the primitive `prim` (found at JSON path `at`, its extension
/// object `ext`): every attribute of the stream the primitive lists, with the format its
/// accessor declares, and the triangle list.
pub(super) fn read(doc: &Document, prim: &Value, ext: &Value, at: &str) -> Result<Decoded> {
    let ext_at = format!("{at}.extensions.{EXTENSION}");
    let view = ext
        .get("bufferView")
        .and_then(Value::as_u64)
        .ok_or_else(|| {
            Error::invalid(
                format!("{ext_at}.bufferView"),
                "is missing (expected the index of the buffer view holding the Draco stream)",
            )
        })?;
    let stream = doc.view_bytes(view as usize)?;
    // The decoder is a pre-release: some malformed streams make it panic instead of returning
    // an error. Either way the file is refused with an error naming the primitive.
    let decoded = quietly(|| draco::decode_mesh(stream));
    let mesh = match decoded {
        Ok(Ok(mesh)) => mesh,
        Ok(Err(e)) => {
            return Err(Error::invalid(
                &ext_at,
                format!(
                    "the Draco stream cannot be decoded: {e} (expected a Draco 2.2 mesh stream)"
                ),
            ))
        }
        Err(_) => {
            return Err(Error::invalid(
                &ext_at,
                "the Draco stream cannot be decoded: the decoder gave up on it (expected a valid Draco 2.2 mesh stream)",
            ))
        }
    };
    let ids = ext
        .get("attributes")
        .and_then(Value::as_object)
        .ok_or_else(|| {
            Error::invalid(
                format!("{ext_at}.attributes"),
                "is missing (expected an object of Draco attribute ids)",
            )
        })?;
    let empty = Map::new();
    let listed = prim
        .get("attributes")
        .and_then(Value::as_object)
        .unwrap_or(&empty);
    let points = mesh.attributes.first().map_or(0, |a| a.len());
    let mut attributes = Vec::with_capacity(listed.len());
    for (name, accessor) in listed {
        let here = format!("{ext_at}.attributes.{name}");
        let Some(id) = ids.get(name).and_then(Value::as_u64) else {
            // Stored outside the stream, in its own accessor (one value per decoded point).
            attributes.push(Slot::Accessor(name.clone()));
            continue;
        };
        let source = mesh
            .attributes
            .iter()
            .find(|a| a.get_id().as_usize() as u64 == id)
            .ok_or_else(|| {
                Error::invalid(&here, format!("the Draco stream has no attribute {id}"))
            })?;
        let declared = accessor
            .as_u64()
            .and_then(|i| doc.root.accessors.get(i as usize))
            .ok_or_else(|| {
                Error::invalid(
                    format!("{at}.attributes.{name}"),
                    "is not an accessor index",
                )
            })?;
        let components = match &declared.type_ {
            Checked::Valid(t) => type_components(*t),
            Checked::Invalid => 0,
        };
        let component_type = match &declared.component_type {
            Checked::Valid(c) => c.0,
            Checked::Invalid => ComponentType::F32,
        };
        // The decoded point count is authoritative (as in every Draco loader): an encoder may
        // split vertices, so it can exceed the accessor's count.
        if source.get_num_components() != components {
            return Err(Error::invalid(
                format!("{at}.attributes.{name}"),
                format!(
                    "has {components} components, the Draco stream's attribute {id} has {} (expected the same)",
                    source.get_num_components()
                ),
            ));
        }
        let values = per_point(source, points);
        let integer = !declared.normalized
            && matches!(
                component_type,
                ComponentType::U8 | ComponentType::U16 | ComponentType::U32
            )
            && (name.starts_with("JOINTS_") || name.starts_with('_'));
        let values = match (integer, declared.normalized) {
            (true, _) => Values::Uint(values.iter().map(|v| *v as u32).collect()),
            (false, true) => {
                let max = match component_type {
                    ComponentType::U8 => 255.0,
                    ComponentType::U16 => 65535.0,
                    ComponentType::I8 => 127.0,
                    ComponentType::I16 => 32767.0,
                    _ => 1.0,
                };
                Values::Float(
                    values
                        .iter()
                        .map(|v| ((v / max) as f32).max(-1.0))
                        .collect(),
                )
            }
            (false, false) => Values::Float(values.iter().map(|v| *v as f32).collect()),
        };
        if let Values::Float(v) = &values {
            if let Some(k) = v.iter().position(|x| !x.is_finite()) {
                return Err(Error::invalid(
                    &here,
                    format!(
                        "element {} decodes to {} (expected finite numbers)",
                        k / components.max(1),
                        v[k]
                    ),
                ));
            }
        }
        attributes.push(Slot::Decoded(Attribute {
            name: name.clone(),
            components,
            values,
            component_type,
            normalized: declared.normalized,
        }));
    }
    let indices: Vec<u32> = mesh
        .faces
        .iter()
        .flatten()
        .map(|&p| usize::from(p) as u32)
        .collect();
    if let Some(bad) = indices.iter().find(|&&i| i as usize >= points) {
        return Err(Error::invalid(
            &ext_at,
            format!("the Draco stream's face index {bad} is not below its {points} points"),
        ));
    }
    Ok(Decoded {
        attributes,
        indices,
        points,
    })
}

/// One attribute of a Draco primitive, in the order the primitive lists them.
pub(super) enum Slot {
    /// Decoded from the stream.
    Decoded(Attribute),
    /// Not in the stream: read from its accessor by the caller.
    Accessor(String),
}

/// A decoded Draco primitive.
pub(super) struct Decoded {
    pub attributes: Vec<Slot>,
    /// The triangle list over the decoded points.
    pub indices: Vec<u32>,
    /// The decoded point count (every attribute has one value per point).
    pub points: usize,
}

thread_local! {
    /// Set while this thread runs the decoder: its panics are expected and reported as errors.
    static DECODING: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Runs `decode`, turning a panic into `Err(())` without printing it: the panic hook in place
/// (the default one prints a message) is wrapped once so that it stays silent for a panic on a
/// thread inside `decode` and is called as before for every other panic.
fn quietly<T>(decode: impl FnOnce() -> T) -> std::result::Result<T, ()> {
    static WRAP: std::sync::Once = std::sync::Once::new();
    WRAP.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !DECODING.with(std::cell::Cell::get) {
                previous(info);
            }
        }));
    });
    DECODING.with(|d| d.set(true));
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(decode));
    DECODING.with(|d| d.set(false));
    result.map_err(|_| ())
}

/// The values of a decoded attribute per point (Draco stores each distinct value once and maps
/// points to values), as f64 whatever the stored component type.
fn per_point(attribute: &draco_oxide_core::attribute::Attribute, points: usize) -> Vec<f64> {
    use draco_oxide_core::attribute::ComponentDataType as C;
    let n = attribute.get_num_components();
    let ty = attribute.get_component_type();
    let size = ty.size();
    let bytes = attribute.get_data_as_bytes();
    let read = |at: usize| -> f64 {
        let b = &bytes[at..at + size];
        match ty {
            C::I8 => f64::from(b[0] as i8),
            C::U8 => f64::from(b[0]),
            C::I16 => f64::from(i16::from_ne_bytes([b[0], b[1]])),
            C::U16 => f64::from(u16::from_ne_bytes([b[0], b[1]])),
            C::I32 => f64::from(i32::from_ne_bytes([b[0], b[1], b[2], b[3]])),
            C::U32 => f64::from(u32::from_ne_bytes([b[0], b[1], b[2], b[3]])),
            C::F32 => f64::from(f32::from_ne_bytes([b[0], b[1], b[2], b[3]])),
            _ => f64::NAN,
        }
    };
    let mut out = Vec::with_capacity(points * n);
    for p in 0..points {
        let value = usize::from(attribute.get_unique_val_idx(p.into()));
        for c in 0..n {
            out.push(read((value * n + c) * size));
        }
    }
    out
}
