//! KHR_mesh_quantization for a whole document: positions as unsigned 16-bit integers under a
//! dequantizing node transform, normals and tangents as normalized signed bytes (octahedral when
//! the output will also be meshopt-compressed), texture coordinates in [0, 1] as normalized
//! unsigned shorts, morph position deltas as 16-bit integers in the positions' units.
//!
//! It deliberately keeps as floats what it cannot quantize without changing how the asset looks:
//! positions of skinned meshes (the spec ignores a skinned mesh's node transform, so the
//! dequantization would have nowhere to go), of instanced meshes and of meshes no node uses;
//! texture coordinates outside [0, 1]; morph normal and tangent deltas (they span [-2, 2]);
//! colors, weights and custom attributes. It writes no files: [`super::dequantize_nodes`] puts
//! the recorded transforms on nodes when the document is written.

use std::collections::{BTreeMap, BTreeSet};

use gltf_json::accessor::ComponentType;
use gltf_json::buffer::Target;
use serde_json::{json, Value};

use super::accessor;
use super::bounds::float_bounds;
use super::document::{Document, ReadOptions};
use super::error::{Error, Result};
use super::primitive::{collect_accessor_refs, push_accessor};

/// Default position precision: 14 bits per axis of the mesh's largest extent (gltfpack's default;
/// 1/16383 of the mesh's size, below a texel of most bakes).
pub const DEFAULT_POSITION_BITS: u32 = 14;
/// Default texture coordinate precision: 12 bits (a 4096² texture addressed to the texel).
pub const DEFAULT_TEXCOORD_BITS: u32 = 12;
/// Default normal and tangent precision: 8 bits per component (worst angle error ≈ 0.5°).
pub const DEFAULT_NORMAL_BITS: u32 = 8;

/// How to quantize.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct Quantization {
    /// Bits per position component, 1 to 16. Default: [`DEFAULT_POSITION_BITS`].
    pub position_bits: u32,
    /// Bits per texture coordinate component, 1 to 16. Default: [`DEFAULT_TEXCOORD_BITS`].
    pub texcoord_bits: u32,
    /// Bits per normal/tangent component, 2 to 16; up to 8 are stored in bytes, more in shorts.
    /// Default: [`DEFAULT_NORMAL_BITS`].
    pub normal_bits: u32,
    /// Encode normals and tangents octahedrally (EXT_meshopt_compression's OCTAHEDRAL filter),
    /// which compresses better; only useful when the output is compressed. Default: `false`.
    pub octahedral: bool,
}

impl Default for Quantization {
    fn default() -> Self {
        Self {
            position_bits: DEFAULT_POSITION_BITS,
            texcoord_bits: DEFAULT_TEXCOORD_BITS,
            normal_bits: DEFAULT_NORMAL_BITS,
            octahedral: false,
        }
    }
}

impl Quantization {
    /// These settings with octahedral normals switched on or off.
    pub fn with_octahedral(mut self, octahedral: bool) -> Self {
        self.octahedral = octahedral;
        self
    }

    fn check(&self) -> Result<()> {
        let ranges = [
            ("position_bits", self.position_bits, 1..=16),
            ("texcoord_bits", self.texcoord_bits, 1..=16),
            ("normal_bits", self.normal_bits, 2..=16),
        ];
        for (name, bits, range) in ranges {
            if !range.contains(&bits) {
                return Err(Error::invalid(
                    format!("quantization.{name}"),
                    format!("is {bits} (expected {} to {})", range.start(), range.end()),
                ));
            }
        }
        Ok(())
    }
}

/// The transform that maps a mesh's integer positions back to its own space:
/// `p = offset + scale · q`. The scale is uniform so that normals need no correction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dequantize {
    /// The corner of the mesh's bounding box (the position of `q = 0`).
    pub offset: [f32; 3],
    /// The size of one quantization step, in the mesh's units.
    pub scale: f32,
}

/// A post-decompression filter of EXT_meshopt_compression.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Filter {
    /// Unit vectors stored as octahedral coordinates.
    Octahedral,
}

impl Filter {
    /// The name the extension uses.
    pub(crate) fn name(self) -> &'static str {
        match self {
            Filter::Octahedral => "OCTAHEDRAL",
        }
    }
}

/// A buffer view whose bytes are what `filter` decodes `encoded` to.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Filtered {
    pub filter: Filter,
    pub encoded: Vec<u8>,
}

/// Why a mesh's positions stayed float.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FloatPositions {
    /// A skinned node uses it; the spec ignores that node's transform.
    Skinned,
    /// An instanced node (EXT_mesh_gpu_instancing) uses it: instance transforms apply before
    /// the node's, so a dequantizing child node would apply in the wrong order.
    Instanced,
    /// No node uses it, so no node can carry the dequantization.
    Unused,
    /// One of its primitives is Draco-compressed (its positions are not ours to re-encode).
    Draco,
    /// It has morph targets and the asset animates through KHR_animation_pointer, whose
    /// pointers to the node's `weights` would not follow the mesh to a child node.
    AnimationPointer,
    /// A position is not finite.
    NotFinite,
}

/// What [`quantize`] did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Summary {
    /// Meshes whose positions are now integers under a dequantizing node.
    pub quantized_positions: Vec<usize>,
    /// Meshes whose positions stayed float, and why.
    pub float_positions: Vec<(usize, FloatPositions)>,
}

/// What an attribute accessor holds, for the encoder.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Kind {
    Position,
    PositionDelta,
    Normal,
    Tangent,
    Texcoord,
}

/// Quantizes every mesh of `doc` (see the module documentation for what stays float).
/// Accessors shared between primitives of a mesh are quantized once.
pub fn quantize(doc: &mut Document, q: &Quantization) -> Result<Summary> {
    q.check()?;
    let max = ReadOptions::DEFAULT_MAX_BYTES.max(doc.buffers.iter().map(|b| b.len() as u64).sum());
    let blockers = node_blockers(doc);
    let mut summary = Summary::default();
    for mesh in 0..doc.root.meshes.len() {
        let prims = (0..doc.root.meshes[mesh].primitives.len())
            .map(|p| {
                doc.primitive_json(mesh, p).cloned().ok_or_else(|| {
                    Error::invalid(format!("meshes[{mesh}].primitives[{p}]"), "does not exist")
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let draco = |p: &Value| {
            p.pointer("/extensions/KHR_draco_mesh_compression")
                .is_some()
        };
        let blocker = if prims.iter().any(draco) {
            Some(FloatPositions::Draco)
        } else {
            blockers.get(&mesh).copied()
        };
        // A mesh quantized before keeps its integer positions and its transform.
        let domain = if doc.dequantize.contains_key(&mesh) {
            None
        } else if let Some(b) = blocker {
            summary.float_positions.push((mesh, b));
            None
        } else {
            let d = position_domain(doc, &prims, q.position_bits, max)?;
            if d.is_none() {
                summary
                    .float_positions
                    .push((mesh, FloatPositions::NotFinite));
            }
            d
        };
        let mut encoder = Encoder {
            q,
            domain,
            max,
            cache: BTreeMap::new(),
        };
        for (p, mut json) in prims.into_iter().enumerate() {
            if draco(&json) {
                continue;
            }
            let mut old = BTreeSet::new();
            collect_accessor_refs(&json, &mut old);
            let mut changed = false;
            if let Some(attrs) = json.get_mut("attributes").and_then(Value::as_object_mut) {
                for (name, index) in attrs.iter_mut() {
                    let kind = match name.as_str() {
                        "POSITION" => Kind::Position,
                        "NORMAL" => Kind::Normal,
                        "TANGENT" => Kind::Tangent,
                        n if n.starts_with("TEXCOORD_") => Kind::Texcoord,
                        _ => continue,
                    };
                    if let Some(new) = encoder.encode(doc, index, kind)? {
                        *index = json!(new);
                        changed = true;
                    }
                }
            }
            for target in json
                .get_mut("targets")
                .and_then(Value::as_array_mut)
                .into_iter()
                .flatten()
            {
                if let Some(index) = target.get_mut("POSITION") {
                    if let Some(new) = encoder.encode(doc, index, Kind::PositionDelta)? {
                        *index = json!(new);
                        changed = true;
                    }
                }
            }
            if changed {
                let at = format!("meshes[{mesh}].primitives[{p}]");
                let typed: gltf_json::mesh::Primitive = serde_json::from_value(json.clone())
                    .map_err(|e| Error::invalid(&at, e.to_string()))?;
                doc.root.meshes[mesh].primitives[p] = typed;
                doc.replaced_accessors.extend(old);
                doc.replaced.insert((mesh, p), json);
            }
        }
        if let Some(d) = encoder.domain {
            doc.dequantize.insert(mesh, d);
            summary.quantized_positions.push(mesh);
        }
    }
    Ok(summary)
}

/// Per mesh, the first reason found in the node graph to keep its positions float.
fn node_blockers(doc: &Document) -> BTreeMap<usize, FloatPositions> {
    let nodes = doc.raw.get("nodes").and_then(Value::as_array);
    let mut used = BTreeSet::new();
    let mut out = BTreeMap::new();
    for node in nodes.into_iter().flatten() {
        let Some(mesh) = node.get("mesh").and_then(Value::as_u64) else {
            continue;
        };
        let mesh = mesh as usize;
        used.insert(mesh);
        if node.get("skin").is_some() {
            out.insert(mesh, FloatPositions::Skinned);
        } else if node
            .pointer("/extensions/EXT_mesh_gpu_instancing")
            .is_some()
        {
            out.entry(mesh).or_insert(FloatPositions::Instanced);
        }
    }
    let pointer_animation = doc
        .raw
        .get("extensionsUsed")
        .and_then(Value::as_array)
        .is_some_and(|l| l.iter().any(|e| e == "KHR_animation_pointer"));
    for (m, mesh) in doc.root.meshes.iter().enumerate() {
        if !used.contains(&m) {
            out.insert(m, FloatPositions::Unused);
        } else if pointer_animation && mesh.primitives.iter().any(|p| p.targets.is_some()) {
            out.entry(m).or_insert(FloatPositions::AnimationPointer);
        }
    }
    out
}

/// The quantization grid of a mesh: the corner of the bounding box of every primitive's
/// positions, and a uniform step that spans its largest extent in `bits` bits. `None` when a
/// position is not finite (or the mesh has none).
fn position_domain(
    doc: &Document,
    prims: &[Value],
    bits: u32,
    max: u64,
) -> Result<Option<Dequantize>> {
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    let mut seen = BTreeSet::new();
    for p in prims {
        let Some(i) = p.pointer("/attributes/POSITION").and_then(Value::as_u64) else {
            continue;
        };
        if !seen.insert(i) {
            continue;
        }
        let acc = accessor::read(doc, i as usize, max)?;
        if acc.components != 3 {
            return Ok(None);
        }
        for c in acc.to_f32().chunks_exact(3) {
            for k in 0..3 {
                if !c[k].is_finite() {
                    return Ok(None);
                }
                lo[k] = lo[k].min(c[k]);
                hi[k] = hi[k].max(c[k]);
            }
        }
    }
    if !lo[0].is_finite() {
        return Ok(None);
    }
    let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0f32, f32::max);
    let steps = ((1u32 << bits) - 1) as f32;
    let scale = if extent > 0.0 { extent / steps } else { 1.0 };
    Ok(Some(Dequantize { offset: lo, scale }))
}

/// Encodes the accessors of one mesh, each at most once.
struct Encoder<'a> {
    q: &'a Quantization,
    domain: Option<Dequantize>,
    max: u64,
    cache: BTreeMap<(u64, Kind), Option<usize>>,
}

impl Encoder<'_> {
    /// The quantized accessor replacing the accessor `index` refers to, or `None` to keep it.
    fn encode(&mut self, doc: &mut Document, index: &Value, kind: Kind) -> Result<Option<usize>> {
        let Some(i) = index.as_u64() else {
            return Ok(None);
        };
        if let Some(done) = self.cache.get(&(i, kind)) {
            return Ok(*done);
        }
        let acc = accessor::read(doc, i as usize, self.max)?;
        let (components, v) = (acc.components, acc.to_f32());
        let q = self.q;
        let out = match (kind, components, self.domain) {
            (Kind::Position, 3, Some(d)) => {
                let values = positions(&v, d, q.position_bits);
                Some(push(
                    doc,
                    &Encoded::ints(values, 3, ComponentType::U16, false, true),
                ))
            }
            (Kind::PositionDelta, 3, Some(d)) => Some(push(doc, &deltas(&v, d))),
            (Kind::Normal | Kind::Tangent, n @ (3 | 4), _)
                if (kind == Kind::Tangent) == (n == 4) && v.iter().all(|x| x.is_finite()) =>
            {
                let (encoded, filtered) = unit_vectors(&v, n, q.normal_bits, q.octahedral);
                let accessor = push(doc, &encoded);
                if let Some(f) = filtered {
                    // `push` made exactly one view, the last.
                    doc.filtered.insert(doc.root.buffer_views.len() - 1, f);
                }
                Some(accessor)
            }
            (Kind::Texcoord, 2, _) if v.iter().all(|x| (0.0..=1.0).contains(x)) => {
                let values = texcoords(&v, q.texcoord_bits);
                Some(push(
                    doc,
                    &Encoded::ints(values, 2, ComponentType::U16, true, false),
                ))
            }
            _ => None,
        };
        self.cache.insert((i, kind), out);
        Ok(out)
    }
}

/// An attribute ready to be stored: its components in the stored type, widened to `i64` (or
/// `f32` bit patterns for the float fallback of morph deltas).
struct Encoded {
    values: Vec<i64>,
    floats: Option<Vec<f32>>,
    components: usize,
    ct: ComponentType,
    normalized: bool,
    bounds: bool,
}

impl Encoded {
    fn ints(
        values: Vec<i64>,
        components: usize,
        ct: ComponentType,
        normalized: bool,
        bounds: bool,
    ) -> Self {
        Self {
            values,
            floats: None,
            components,
            ct,
            normalized,
            bounds,
        }
    }
}

/// Stores an encoded attribute as a new view and accessor (elements padded to 4 bytes, as
/// vertex attributes must be); returns the accessor.
fn push(doc: &mut Document, e: &Encoded) -> usize {
    let n = e.components;
    let size = accessor::component_size(e.ct);
    let elem = n * size;
    let stride = elem.div_ceil(4) * 4;
    let count = e.values.len().max(e.floats.as_ref().map_or(0, Vec::len)) / n;
    let mut bytes = Vec::with_capacity(count * stride);
    for k in 0..count {
        for c in 0..n {
            let i = k * n + c;
            match (&e.floats, e.ct) {
                (Some(f), _) => bytes.extend_from_slice(&f[i].to_le_bytes()),
                (None, ComponentType::I8 | ComponentType::U8) => bytes.push(e.values[i] as u8),
                (None, _) => bytes.extend_from_slice(&(e.values[i] as u16).to_le_bytes()),
            }
        }
        bytes.resize(bytes.len() + stride - elem, 0);
    }
    let (min, max) = if !e.bounds || count == 0 {
        (None, None)
    } else if let Some(f) = &e.floats {
        let (lo, hi) = float_bounds(f, n);
        (Some(json!(lo)), Some(json!(hi)))
    } else {
        let (lo, hi) = integer_bounds(&e.values, n);
        (Some(json!(lo)), Some(json!(hi)))
    };
    let view = doc.push_view(
        &bytes,
        (stride != elem).then_some(stride),
        Some(Target::ArrayBuffer),
    );
    push_accessor(
        doc,
        view,
        count,
        e.ct,
        accessor::vector_type(n),
        e.normalized,
        min,
        max,
    )
}

/// Per-component minimum and maximum of the integers `values` (`n ≥ 1` components per element,
/// at least one element); the float ones are [`float_bounds`]'s, as every accessor's.
fn integer_bounds(values: &[i64], n: usize) -> (Vec<i64>, Vec<i64>) {
    let (mut lo, mut hi) = (values[..n].to_vec(), values[..n].to_vec());
    for element in values.chunks_exact(n) {
        for (k, &x) in element.iter().enumerate() {
            lo[k] = lo[k].min(x);
            hi[k] = hi[k].max(x);
        }
    }
    (lo, hi)
}

/// `v` in [0, 1] as an unsigned `bits`-bit integer, rounded to nearest.
pub(crate) fn unorm(v: f32, bits: u32) -> u32 {
    let steps = ((1u32 << bits) - 1) as f32;
    (v.clamp(0.0, 1.0) * steps + 0.5) as u32
}

/// `v` in [-1, 1] as a signed `bits`-bit integer, rounded to nearest.
pub(crate) fn snorm(v: f32, bits: u32) -> i32 {
    let steps = ((1i32 << (bits - 1)) - 1) as f32;
    (v.clamp(-1.0, 1.0) * steps).round() as i32
}

/// A `bits`-bit unsigned normalized integer widened to 16 bits by repeating its bits, so that
/// `q / (2^bits − 1)` and the result `/ 65535` agree to 16-bit precision (the usual exact
/// expansion of a unorm value; the low bits add no entropy).
pub(crate) fn widen_unorm(q: u32, bits: u32) -> u16 {
    let (mut out, mut filled) = (0u64, 0);
    while filled < 16 {
        out = (out << bits) | u64::from(q);
        filled += bits;
    }
    (out >> (filled - 16)) as u16
}

/// Positions on the mesh's grid: `q = round((p − offset) / scale)`, clamped to `bits` bits.
fn positions(v: &[f32], d: Dequantize, bits: u32) -> Vec<i64> {
    let top = (1i64 << bits) - 1;
    v.chunks_exact(3)
        .flat_map(|p| {
            (0..3).map(move |k| (((p[k] - d.offset[k]) / d.scale).round() as i64).clamp(0, top))
        })
        .collect()
}

/// Morph position deltas in units of the positions' step (the node's scale applies to them
/// too): 16-bit integers when they fit, otherwise floats in the same units.
fn deltas(v: &[f32], d: Dequantize) -> Encoded {
    let scaled: Vec<f32> = v.iter().map(|x| x / d.scale).collect();
    let fits = scaled
        .iter()
        .all(|x| x.is_finite() && x.abs() <= i16::MAX as f32);
    if fits {
        let values = scaled.iter().map(|x| x.round() as i64).collect();
        Encoded::ints(values, 3, ComponentType::I16, false, true)
    } else {
        Encoded {
            values: Vec::new(),
            floats: Some(scaled),
            components: 3,
            ct: ComponentType::F32,
            normalized: false,
            bounds: true,
        }
    }
}

/// Texture coordinates in [0, 1] at `bits` bits, widened to normalized 16-bit.
fn texcoords(v: &[f32], bits: u32) -> Vec<i64> {
    v.iter()
        .map(|x| i64::from(widen_unorm(unorm(*x, bits), bits)))
        .collect()
}

/// Unit vectors (`n` = 3 for normals, 4 for tangents with the handedness in w) as normalized
/// signed bytes (`bits` ≤ 8) or shorts. Octahedral: the stored vectors are what the OCTAHEDRAL
/// filter decodes, and the filter's input is returned beside them for the compressor.
fn unit_vectors(v: &[f32], n: usize, bits: u32, octahedral: bool) -> (Encoded, Option<Filtered>) {
    let wide = bits > 8;
    let ct = if wide {
        ComponentType::I16
    } else {
        ComponentType::I8
    };
    let vectors: Vec<[f32; 4]> = v
        .chunks_exact(n)
        .map(|c| {
            let len = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
            let s = if len > 0.0 { 1.0 / len } else { 0.0 };
            let w = if n == 4 && c[3] < 0.0 { -1.0 } else { 1.0 };
            [c[0] * s, c[1] * s, c[2] * s, if n == 4 { w } else { 0.0 }]
        })
        .collect();
    if !octahedral {
        let storage = if wide { 16 } else { 8 };
        let values = vectors
            .iter()
            .flat_map(|c| c[..n].iter().map(|x| i64::from(snorm(*x, storage))))
            .collect();
        return (Encoded::ints(values, n, ct, true, false), None);
    }
    // The filter always stores four components; a normal's fourth is padding.
    let (decoded, encoded): (Vec<i64>, Vec<u8>) = if wide {
        let enc = meshopt::encode_filter_oct::<i16>(&vectors, bits as i32);
        let mut dec = enc.clone();
        meshopt::decode_filter_oct(&mut dec);
        (
            dec.iter()
                .flat_map(|c| c[..n].iter().map(|x| i64::from(*x)))
                .collect(),
            enc.iter().flatten().flat_map(|x| x.to_le_bytes()).collect(),
        )
    } else {
        let enc = meshopt::encode_filter_oct::<i8>(&vectors, bits as i32);
        let mut dec = enc.clone();
        meshopt::decode_filter_oct(&mut dec);
        (
            dec.iter()
                .flat_map(|c| c[..n].iter().map(|x| i64::from(*x)))
                .collect(),
            enc.iter().flatten().map(|x| *x as u8).collect(),
        )
    };
    // A normal's fourth component encodes as 0, which is what `push` pads with: the view's
    // bytes are exactly what the filter decodes.
    (
        Encoded::ints(decoded, n, ct, true, false),
        Some(Filtered {
            filter: Filter::Octahedral,
            encoded,
        }),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widening_keeps_the_extremes_and_the_value() {
        assert_eq!(widen_unorm(0, 12), 0);
        assert_eq!(widen_unorm(4095, 12), 65535);
        for q in [1u32, 100, 2048, 4000] {
            let exact = q as f64 / 4095.0;
            let wide = widen_unorm(q, 12) as f64 / 65535.0;
            assert!(
                (exact - wide).abs() < 1.0 / 65535.0,
                "{q}: {exact} vs {wide}"
            );
        }
    }

    #[test]
    fn positions_land_on_the_grid_within_half_a_step() {
        let v = [0.0, -1.0, 2.0, 0.3, 0.7, -0.2, 1.0, 1.0, 1.0];
        let d = Dequantize {
            offset: [0.0, -1.0, -0.2],
            scale: 2.2 / 16383.0,
        };
        let q = positions(&v, d, 14);
        for (k, x) in v.iter().enumerate() {
            let back = d.offset[k % 3] + d.scale * q[k] as f32;
            assert!(
                (back - x).abs() <= d.scale * 0.5 + 1e-6,
                "{k}: {x} vs {back}"
            );
        }
    }

    #[test]
    fn octahedral_normals_decode_to_unit_bytes() {
        let v = [0.0, 0.0, 1.0, 0.6, -0.8, 0.0, -0.577, -0.577, -0.577];
        let (stored, filtered) = unit_vectors(&v, 3, 8, true);
        assert!(filtered.is_some());
        for (c, x) in stored.values.chunks(3).zip(v.chunks(3)) {
            let dot: f32 = (0..3).map(|k| c[k] as f32 / 127.0 * x[k]).sum::<f32>()
                / (x.iter().map(|a| a * a).sum::<f32>()).sqrt();
            assert!(dot > 0.999, "{c:?} vs {x:?}");
        }
    }
}
