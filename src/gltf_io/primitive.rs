//! A mesh primitive as plain arrays ([`PrimitiveData`]): reading one out of a [`Document`]
//! (strips and fans turned into triangle lists, non-indexed primitives given indices) and putting
//! one back as new accessors.
//!
//! It deliberately keeps everything about the primitive it does not understand (material,
//! extensions, extras). A Draco-compressed primitive is decoded from its stream
//! ([`super::draco_decode`]), never from its placeholder accessors, which hold no data.

use gltf_json::accessor::{ComponentType, GenericComponentType, Type};
use gltf_json::mesh::Mode;
use gltf_json::validation::{Checked, USize64};
use serde_json::{json, Map, Value};

use super::accessor::{self, component_size, vector_type};
use super::bounds;
use super::buffer_data::BufferData;
use super::document::{Document, ReadOptions};
use super::draco_decode;
use super::error::{Error, Result};
use super::validate::is_triangle_mode;

/// The values of one vertex attribute.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    /// Float-valued data (positions, normals, UVs, colors, weights; quantized data dequantized).
    Float(Vec<f32>),
    /// Integer data that must not be interpolated (joint indices, unsigned `_` IDs).
    Uint(Vec<u32>),
}

impl Values {
    /// Number of components stored.
    pub fn len(&self) -> usize {
        match self {
            Values::Float(v) => v.len(),
            Values::Uint(v) => v.len(),
        }
    }

    /// Whether no components are stored.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// One named vertex attribute, decoded, with the format it was stored in.
#[derive(Debug, Clone, PartialEq)]
pub struct Attribute {
    /// The glTF semantic, e.g. `POSITION`, `TEXCOORD_0`, `_FEATURE_ID_0`.
    pub name: String,
    /// Components per vertex (1 to 4).
    pub components: usize,
    /// The values, `components` per vertex.
    pub values: Values,
    /// The component type it was stored with (integer attributes are written back in it).
    pub component_type: ComponentType,
    /// Whether it was stored normalized.
    pub normalized: bool,
}

impl Attribute {
    /// Number of vertices.
    pub fn count(&self) -> usize {
        self.values.len() / self.components.max(1)
    }

    /// A new float attribute, written as 32-bit floats.
    pub fn float(name: &str, components: usize, values: Vec<f32>) -> Attribute {
        Attribute {
            name: name.to_string(),
            components,
            values: Values::Float(values),
            component_type: ComponentType::F32,
            normalized: false,
        }
    }

    /// The values of a float attribute of any component count (integer ones are `None`).
    pub fn floats(&self) -> Option<&[f32]> {
        match &self.values {
            Values::Float(v) => Some(v),
            _ => None,
        }
    }

    /// The values of a three-component float attribute (positions, normals, morph deltas).
    pub fn vec3(&self) -> Option<&[f32]> {
        match &self.values {
            Values::Float(v) if self.components == 3 => Some(v),
            _ => None,
        }
    }
}

/// The glTF attribute names the tool gives a meaning to, and the rules that pair attributes:
/// the only place outside reading and writing that spells them.
pub mod semantic {
    /// Vertex positions.
    pub const POSITION: &str = "POSITION";
    /// Vertex normals.
    pub const NORMAL: &str = "NORMAL";
    /// Vertex tangents (xyz and the handedness w).
    pub const TANGENT: &str = "TANGENT";

    /// The texture coordinate set `set`.
    pub fn texcoord(set: u32) -> String {
        format!("TEXCOORD_{set}")
    }

    /// The skin weights paired with the joint indices `joints` (`JOINTS_n` → `WEIGHTS_n`).
    pub fn weights_of(joints: &str) -> Option<String> {
        joints
            .strip_prefix("JOINTS_")
            .map(|set| format!("WEIGHTS_{set}"))
    }

    /// The joint indices paired with the skin weights `weights` (`WEIGHTS_n` → `JOINTS_n`).
    pub fn joints_of(weights: &str) -> Option<String> {
        weights
            .strip_prefix("WEIGHTS_")
            .map(|set| format!("JOINTS_{set}"))
    }
}

/// One morph target's displacements of the core arrays.
#[derive(Debug, Clone, Copy, Default)]
pub struct MorphDeltas<'a> {
    /// Position deltas, 3 per vertex.
    pub positions: Option<&'a [f32]>,
    /// Normal deltas, 3 per vertex.
    pub normals: Option<&'a [f32]>,
}

impl<'a> MorphDeltas<'a> {
    /// The position and normal deltas of morph target `target` (other attributes ignored).
    pub fn of(target: &'a [Attribute]) -> Self {
        let find = |name: &str| {
            target
                .iter()
                .find(|a| a.name == name)
                .and_then(Attribute::vec3)
        };
        MorphDeltas {
            positions: find(semantic::POSITION),
            normals: find(semantic::NORMAL),
        }
    }
}

/// A triangle primitive as arrays: attributes, a triangle list, morph targets.
#[derive(Debug, Clone, PartialEq)]
pub struct PrimitiveData {
    /// Vertex attributes in the order the file lists them.
    pub attributes: Vec<Attribute>,
    /// Three vertex indices per triangle, in the primitive's winding.
    pub indices: Vec<u32>,
    /// Morph targets: per target, its displacement attributes.
    pub targets: Vec<Vec<Attribute>>,
}

impl PrimitiveData {
    /// The attribute named `name`, if present.
    pub fn attribute(&self, name: &str) -> Option<&Attribute> {
        self.attributes.iter().find(|a| a.name == name)
    }

    /// Number of vertices (of POSITION).
    pub fn vertex_count(&self) -> usize {
        self.attribute(semantic::POSITION)
            .map_or(0, Attribute::count)
    }

    /// The positions, 3 floats per vertex, all finite; the error names the primitive at JSON
    /// path `at`.
    pub fn positions(&self, at: &str) -> Result<&[f32]> {
        let positions = match self.attribute(semantic::POSITION) {
            Some(a) if a.components == 3 => match &a.values {
                Values::Float(v) => v,
                Values::Uint(_) => unreachable!("positions are decoded as floats"),
            },
            Some(a) => {
                return Err(Error::invalid(
                    format!("{at}.attributes.POSITION"),
                    format!("has {} components (expected 3)", a.components),
                ))
            }
            None => {
                return Err(Error::invalid(
                    format!("{at}.attributes"),
                    "has no POSITION (expected a triangle primitive with positions)",
                ))
            }
        };
        if let Some(i) = accessor::first_in_blocks(positions, |x| !x.is_finite()) {
            return Err(Error::invalid(
                format!("{at}.attributes.POSITION"),
                format!("vertex {} is not finite (expected finite numbers)", i / 3),
            ));
        }
        Ok(positions)
    }

    /// The normals, 3 floats per vertex, if the primitive has float normals.
    pub fn normals(&self) -> Option<&[f32]> {
        self.attribute(semantic::NORMAL).and_then(Attribute::vec3)
    }

    /// The tangents, if the primitive has them.
    pub fn tangents(&self) -> Option<&Attribute> {
        self.attribute(semantic::TANGENT)
    }

    /// The skin weights paired with the joint indices `joints`, when the pair is what skinning
    /// reads (4 integer joints, 4 float weights, one each per vertex).
    pub fn skin_weights(&self, joints: &Attribute) -> Option<&Attribute> {
        let weights = self.attribute(&semantic::weights_of(&joints.name)?)?;
        let paired = matches!(joints.values, Values::Uint(_))
            && matches!(weights.values, Values::Float(_))
            && joints.components == 4
            && weights.values.len() == joints.values.len();
        paired.then_some(weights)
    }

    /// Whether `weights` is paired with joint indices (see [`PrimitiveData::skin_weights`]
    /// for the rule: checked from the joints' side).
    pub fn is_paired_weights(&self, weights: &str) -> bool {
        semantic::joints_of(weights)
            .and_then(|j| self.attribute(&j))
            .is_some_and(|j| matches!(j.values, Values::Uint(_)) && j.components == 4)
    }
}

/// A primitive's size as declared, before decoding: see [`Document::primitive_size`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PrimitiveSize {
    /// Vertices (elements of POSITION).
    pub vertices: u64,
    /// Triangles after strips and fans become a list.
    pub triangles: u64,
    /// Bytes the decoded arrays take (every component widened to 4 bytes; a generous bound,
    /// since accessors decode to the size of their declaration).
    pub decoded_bytes: u64,
}

fn index_of(v: &Value, at: &str) -> Result<usize> {
    v.as_u64()
        .map(|i| i as usize)
        .ok_or_else(|| Error::invalid(at, "is not an index"))
}

impl Document {
    /// The JSON of a primitive as it will be written (replaced or as read).
    pub(crate) fn primitive_json(&self, mesh: usize, prim: usize) -> Option<&Value> {
        self.replaced.get(&(mesh, prim)).or_else(|| {
            self.raw
                .get("meshes")?
                .get(mesh)?
                .get("primitives")?
                .get(prim)
        })
    }

    /// The `extras` of mesh `mesh` as plain JSON, if any.
    pub fn mesh_extras(&self, mesh: usize) -> Option<Value> {
        self.raw.pointer(&format!("/meshes/{mesh}/extras")).cloned()
    }

    /// The `extras` of primitive `prim` of mesh `mesh` as plain JSON, if any.
    pub fn primitive_extras(&self, mesh: usize, prim: usize) -> Option<Value> {
        self.raw
            .pointer(&format!("/meshes/{mesh}/primitives/{prim}/extras"))
            .cloned()
    }

    /// The texture coordinate set of the normal texture of primitive `prim` of mesh `mesh`'s
    /// material, if it has one.
    pub fn normal_texture_set(&self, mesh: usize, prim: usize) -> Option<u32> {
        self.root.meshes[mesh].primitives[prim]
            .material
            .and_then(|m| self.root.materials.get(m.value()))
            .and_then(|m| m.normal_texture.as_ref())
            .map(|t| t.tex_coord)
    }

    /// Every (mesh, primitive) whose mode is a triangle list, strip or fan, in file order.
    pub fn triangle_primitives(&self) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        for (m, mesh) in self.root.meshes.iter().enumerate() {
            for (p, prim) in mesh.primitives.iter().enumerate() {
                if is_triangle_mode(&prim.mode) {
                    out.push((m, p));
                }
            }
        }
        out
    }

    /// What decoding primitive `prim` of mesh `mesh` would give, from the declared counts alone
    /// (nothing is read), so that callers can refuse work before allocating it.
    pub fn primitive_size(&self, mesh: usize, prim: usize) -> PrimitiveSize {
        let Some(json) = self.primitive_json(mesh, prim) else {
            return PrimitiveSize::default();
        };
        let accessor = |v: &Value| v.as_u64().and_then(|i| self.root.accessors.get(i as usize));
        let elements = |v: &Value| accessor(v).map_or(0, |a| a.count.0);
        let floats = |obj: Option<&Value>| -> u64 {
            obj.and_then(Value::as_object)
                .into_iter()
                .flat_map(|o| o.values())
                .filter_map(accessor)
                .map(|a| accessor::decoded_size(a).saturating_mul(4))
                .fold(0, u64::saturating_add)
        };
        let attributes = json.get("attributes");
        let vertices = attributes
            .and_then(|a| a.get("POSITION"))
            .map_or(0, elements);
        let list = json.get("indices").map_or(vertices, elements);
        let triangles = match json.get("mode").and_then(Value::as_u64).unwrap_or(4) {
            5 | 6 => list.saturating_sub(2),
            _ => list / 3,
        };
        let targets = json
            .get("targets")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
            .map(|t| floats(Some(t)))
            .fold(0, u64::saturating_add);
        PrimitiveSize {
            vertices,
            triangles,
            decoded_bytes: floats(attributes)
                .saturating_add(targets)
                .saturating_add(list.saturating_mul(4))
                .saturating_add(triangles.saturating_mul(12)),
        }
    }

    /// Decodes primitive `prim` of mesh `mesh`: every attribute, a triangle list, morph targets.
    pub fn read_primitive(&self, mesh: usize, prim: usize) -> Result<PrimitiveData> {
        let at = format!("meshes[{mesh}].primitives[{prim}]");
        let json = self
            .primitive_json(mesh, prim)
            .ok_or_else(|| Error::invalid(&at, "does not exist"))?;
        let max =
            ReadOptions::DEFAULT_MAX_BYTES.max(self.buffers.iter().map(|b| b.len() as u64).sum());
        let draco = json.pointer(&format!("/extensions/{}", draco_decode::EXTENSION));
        let (attributes, list) = match draco {
            Some(ext) => {
                let decoded = draco_decode::read(self, json, ext, &at)?;
                let mut attributes = Vec::with_capacity(decoded.attributes.len());
                for slot in decoded.attributes {
                    let a = match slot {
                        draco_decode::Slot::Decoded(a) => a,
                        draco_decode::Slot::Accessor(name) => {
                            let one = json.get("attributes").and_then(|a| a.get(&name));
                            let single = one.map(|i| json!({ name.clone(): i }));
                            let mut read = read_attributes(
                                self,
                                single.as_ref(),
                                &format!("{at}.attributes"),
                                false,
                                max,
                            )?;
                            let a = read.pop().expect("one attribute read");
                            if a.count() != decoded.points {
                                return Err(Error::invalid(
                                    format!("{at}.attributes.{name}"),
                                    format!(
                                        "has {} elements, the Draco stream {} points (expected one per point)",
                                        a.count(),
                                        decoded.points
                                    ),
                                ));
                            }
                            a
                        }
                    };
                    attributes.push(a);
                }
                (attributes, decoded.indices)
            }
            None => {
                let attributes = read_attributes(
                    self,
                    json.get("attributes"),
                    &format!("{at}.attributes"),
                    false,
                    max,
                )?;
                let vertices = attributes.first().map_or(0, Attribute::count);
                let list: Vec<u32> = match json.get("indices") {
                    Some(i) => {
                        accessor::read(self, index_of(i, &format!("{at}.indices"))?, max)?.to_u32()
                    }
                    None => (0..vertices as u32).collect(),
                };
                (attributes, list)
            }
        };
        // A Draco stream holds its faces as a triangle list whatever the mode says.
        let mode = match draco {
            Some(_) => 4,
            None => json.get("mode").and_then(Value::as_u64).unwrap_or(4),
        };
        let indices = match mode {
            4 => {
                // A list is its own triangle list: kept, not copied.
                let whole = list.len() - list.len() % 3;
                let mut list = list;
                list.truncate(whole);
                list
            }
            5 => (0..list.len().saturating_sub(2))
                .flat_map(|i| {
                    let odd = i % 2;
                    [list[i], list[i + 1 + odd], list[i + 2 - odd]]
                })
                .collect(),
            6 => (1..list.len().saturating_sub(1))
                .flat_map(|i| [list[i], list[i + 1], list[0]])
                .collect(),
            other => {
                return Err(Error::invalid(
                    format!("{at}.mode"),
                    format!("{other} is not a triangle mode (expected 4, 5 or 6)"),
                ))
            }
        };
        let mut targets = Vec::new();
        for (t, target) in json
            .get("targets")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
            .enumerate()
        {
            targets.push(read_attributes(
                self,
                Some(target),
                &format!("{at}.targets[{t}]"),
                true,
                max,
            )?);
        }
        Ok(PrimitiveData {
            attributes,
            indices,
            targets,
        })
    }
}

/// Decodes an `attributes` (or morph target) object.
fn read_attributes(
    doc: &Document,
    obj: Option<&Value>,
    at: &str,
    target: bool,
    max: u64,
) -> Result<Vec<Attribute>> {
    let Some(obj) = obj.and_then(Value::as_object) else {
        return Err(Error::invalid(at, "is not an object of accessor indices"));
    };
    let mut out = Vec::with_capacity(obj.len());
    for (name, index) in obj {
        let acc = accessor::read(doc, index_of(index, &format!("{at}.{name}"))?, max)?;
        let unsigned_int = !acc.normalized
            && matches!(
                acc.component_type,
                ComponentType::U8 | ComponentType::U16 | ComponentType::U32
            );
        let integer =
            !target && unsigned_int && (name.starts_with("JOINTS_") || name.starts_with('_'));
        let values = if integer {
            Values::Uint(acc.to_u32())
        } else {
            Values::Float(acc.to_f32())
        };
        out.push(Attribute {
            name: name.clone(),
            components: acc.components,
            values,
            component_type: acc.component_type,
            normalized: acc.normalized,
        });
    }
    Ok(out)
}

/// Replaces primitive `prim` of mesh `mesh` by `data`: new accessors (with min/max), mode
/// TRIANGLES; material, extensions, extras and any other property of the primitive are kept.
pub fn replace_primitive(
    doc: &mut Document,
    mesh: usize,
    prim: usize,
    data: &PrimitiveData,
) -> Result<()> {
    replace_primitive_owned(doc, mesh, prim, data.clone())
}

/// [`replace_primitive`] taking `data` by value: each array is dropped as soon as it is stored,
/// so a dense primitive is never held twice.
pub fn replace_primitive_owned(
    doc: &mut Document,
    mesh: usize,
    prim: usize,
    data: PrimitiveData,
) -> Result<()> {
    let at = format!("meshes[{mesh}].primitives[{prim}]");
    let mut json = doc
        .primitive_json(mesh, prim)
        .cloned()
        .ok_or_else(|| Error::invalid(&at, "does not exist"))?;
    collect_accessor_refs(&json, &mut doc.replaced_accessors);
    // The new data is written uncompressed: the Draco stream no longer describes it.
    if let Some(ext) = json.get_mut("extensions").and_then(Value::as_object_mut) {
        ext.remove(draco_decode::EXTENSION);
        if ext.is_empty() {
            json.as_object_mut().map(|o| o.remove("extensions"));
        }
    }
    let vertices = data.vertex_count();
    let index_bounds = bounds::uint_bounds(&data.indices);
    if let Some((_, bad)) = index_bounds.filter(|(_, hi)| *hi as usize >= vertices) {
        return Err(Error::invalid(
            &at,
            format!("new index {bad} is not below the vertex count {vertices}"),
        ));
    }
    if let Some(a) = data.attributes.iter().find(|a| a.count() != vertices) {
        return Err(Error::invalid(
            format!("{at}.attributes.{}", a.name),
            format!("has {} vertices (expected {vertices})", a.count()),
        ));
    }
    let PrimitiveData {
        attributes: attribute_data,
        indices: index_data,
        targets: target_data,
    } = data;
    let mut attributes = Map::new();
    for a in attribute_data {
        let name = a.name.clone();
        attributes.insert(name, json!(push_attribute(doc, a)));
    }
    let mut targets = Vec::new();
    for t in target_data {
        let mut obj = Map::new();
        for a in t {
            let name = a.name.clone();
            obj.insert(name, json!(push_target_attribute(doc, a)));
        }
        targets.push(Value::Object(obj));
    }
    let indices = push_indices(doc, index_data, index_bounds, vertices);
    let obj = json
        .as_object_mut()
        .ok_or_else(|| Error::invalid(&at, "is not an object"))?;
    obj.insert("attributes".into(), Value::Object(attributes));
    obj.insert("indices".into(), json!(indices));
    if obj.contains_key("mode") {
        obj.insert("mode".into(), json!(4));
    }
    if targets.is_empty() {
        obj.remove("targets");
    } else {
        obj.insert("targets".into(), Value::Array(targets));
    }
    // Keep the typed model in step, for readers of `doc.root`.
    let typed: gltf_json::mesh::Primitive =
        serde_json::from_value(json.clone()).map_err(|e| Error::invalid(&at, e.to_string()))?;
    let slot = &mut doc.root.meshes[mesh].primitives[prim];
    *slot = typed;
    slot.mode = Checked::Valid(Mode::Triangles);
    doc.replaced.insert((mesh, prim), json);
    Ok(())
}

/// Adds every accessor index `prim` refers to (attributes, indices, targets) to `out`.
pub(crate) fn collect_accessor_refs(prim: &Value, out: &mut std::collections::BTreeSet<usize>) {
    let attrs = prim
        .get("attributes")
        .and_then(Value::as_object)
        .into_iter()
        .flat_map(|o| o.values());
    let targets = prim
        .get("targets")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .filter_map(Value::as_object)
        .flat_map(|o| o.values());
    for v in attrs.chain(targets).chain(prim.get("indices")) {
        if let Some(i) = v.as_u64() {
            out.insert(i as usize);
        }
    }
}

/// Writes one attribute as a new accessor; floats as FLOAT, integers in their original type.
/// Float and 32-bit arrays move into the document uncopied.
fn push_attribute(doc: &mut Document, a: Attribute) -> usize {
    let n = a.components.max(1);
    let count = a.count();
    let (ct, data, min, max): (ComponentType, BufferData, Vec<Value>, Vec<Value>) = match a.values {
        Values::Float(v) => {
            let (lo, hi) = bounds::float_bounds(&v, n);
            (
                ComponentType::F32,
                BufferData::floats(v),
                lo.iter().map(|x| json!(*x)).collect(),
                hi.iter().map(|x| json!(*x)).collect(),
            )
        }
        Values::Uint(v) => {
            let ct = match a.component_type {
                ComponentType::U8 => ComponentType::U8,
                ComponentType::U16 => ComponentType::U16,
                _ => ComponentType::U32,
            };
            let (mut lo, mut hi) = (vec![u32::MAX; n], vec![0u32; n]);
            for e in v.chunks_exact(n) {
                for (k, x) in e.iter().enumerate() {
                    lo[k] = lo[k].min(*x);
                    hi[k] = hi[k].max(*x);
                }
            }
            let (lo, hi) = (
                lo.iter().map(|x| json!(*x)).collect(),
                hi.iter().map(|x| json!(*x)).collect(),
            );
            let data = match ct {
                ComponentType::U8 => BufferData::Bytes(v.iter().map(|x| *x as u8).collect()),
                ComponentType::U16 => {
                    BufferData::Bytes(v.iter().flat_map(|x| (*x as u16).to_le_bytes()).collect())
                }
                _ => BufferData::words(v),
            };
            (ct, data, lo, hi)
        }
    };
    // Vertex attribute elements must start on 4-byte boundaries: pad them when they are shorter.
    let elem = n * component_size(ct);
    let stride = elem.div_ceil(4) * 4;
    let data = if stride != elem {
        BufferData::Bytes(
            data.as_bytes()
                .chunks(elem)
                .flat_map(|e| {
                    e.iter()
                        .copied()
                        .chain(std::iter::repeat_n(0, stride - elem))
                })
                .collect(),
        )
    } else {
        data
    };
    let view = doc.push_array_view(
        data,
        (stride != elem).then_some(stride),
        Some(gltf_json::buffer::Target::ArrayBuffer),
    );
    let bounds = count > 0;
    push_accessor(
        doc,
        view,
        count,
        ct,
        vector_type(n),
        false,
        bounds.then(|| Value::Array(min)),
        bounds.then(|| Value::Array(max)),
    )
}

/// Writes a morph target's displacements sparse when that is smaller (most of a dense mesh
/// often does not move), dense otherwise. A target that moves nothing becomes an accessor
/// without data, which reads as zeros.
fn push_target_attribute(doc: &mut Document, a: Attribute) -> usize {
    let (Values::Float(v), n) = (&a.values, a.components.max(1)) else {
        return push_attribute(doc, a);
    };
    let count = a.count();
    let moved: Vec<usize> = (0..count)
        .filter(|&i| v[i * n..i * n + n].iter().any(|x| *x != 0.0))
        .collect();
    let index_size = if count <= usize::from(u16::MAX) { 2 } else { 4 };
    let sparse_bytes = moved.len() * (index_size + 4 * n);
    if sparse_bytes >= count * 4 * n {
        return push_attribute(doc, a);
    }
    let (mut lo, mut hi) = (vec![0f32; n], vec![0f32; n]);
    for &i in &moved {
        for k in 0..n {
            lo[k] = lo[k].min(v[i * n + k]);
            hi[k] = hi[k].max(v[i * n + k]);
        }
    }
    let index = push_accessor(
        doc,
        0,
        count,
        ComponentType::F32,
        vector_type(n),
        false,
        Some(json!(lo)),
        Some(json!(hi)),
    );
    let accessor = &mut doc.root.accessors[index];
    accessor.buffer_view = None;
    if moved.is_empty() {
        return index;
    }
    let (index_type, index_bytes): (ComponentType, Vec<u8>) = if index_size == 2 {
        let b = moved
            .iter()
            .flat_map(|&i| (i as u16).to_le_bytes())
            .collect();
        (ComponentType::U16, b)
    } else {
        let b = moved
            .iter()
            .flat_map(|&i| (i as u32).to_le_bytes())
            .collect();
        (ComponentType::U32, b)
    };
    let values: Vec<u8> = moved
        .iter()
        .flat_map(|&i| v[i * n..i * n + n].iter().flat_map(|x| x.to_le_bytes()))
        .collect();
    let indices_view = doc.push_view(&index_bytes, None, None);
    let values_view = doc.push_view(&values, None, None);
    doc.root.accessors[index].sparse = Some(gltf_json::accessor::sparse::Sparse {
        count: USize64(moved.len() as u64),
        indices: gltf_json::accessor::sparse::Indices {
            buffer_view: gltf_json::Index::new(indices_view as u32),
            byte_offset: USize64(0),
            component_type: Checked::Valid(gltf_json::accessor::IndexComponentType(index_type)),
            extensions: None,
            extras: Default::default(),
        },
        values: gltf_json::accessor::sparse::Values {
            buffer_view: gltf_json::Index::new(values_view as u32),
            byte_offset: USize64(0),
            extensions: None,
            extras: Default::default(),
        },
        extensions: None,
        extras: Default::default(),
    });
    index
}

/// Writes a triangle list as u16 indices when they fit (65535 is the restart value), else u32
/// (moved into the document uncopied).
fn push_indices(
    doc: &mut Document,
    indices: Vec<u32>,
    bounds: Option<(u32, u32)>,
    vertices: usize,
) -> usize {
    let bounds = bounds.map(|(l, h)| (json!([l]), json!([h])));
    let count = indices.len();
    let (ct, data) = if vertices <= 65535 {
        (
            ComponentType::U16,
            BufferData::Bytes(
                indices
                    .iter()
                    .flat_map(|i| (*i as u16).to_le_bytes())
                    .collect(),
            ),
        )
    } else {
        (ComponentType::U32, BufferData::words(indices))
    };
    let view = doc.push_array_view(
        data,
        None,
        Some(gltf_json::buffer::Target::ElementArrayBuffer),
    );
    push_accessor(
        doc,
        view,
        count,
        ct,
        Type::Scalar,
        false,
        bounds.as_ref().map(|b| b.0.clone()),
        bounds.map(|b| b.1),
    )
}

/// Appends an accessor over the whole of `view`; returns its index.
#[allow(clippy::too_many_arguments)]
pub(crate) fn push_accessor(
    doc: &mut Document,
    view: usize,
    count: usize,
    ct: ComponentType,
    ty: Type,
    normalized: bool,
    min: Option<Value>,
    max: Option<Value>,
) -> usize {
    doc.root.accessors.push(gltf_json::Accessor {
        buffer_view: Some(gltf_json::Index::new(view as u32)),
        byte_offset: None,
        count: USize64(count as u64),
        component_type: Checked::Valid(GenericComponentType(ct)),
        extensions: None,
        extras: Default::default(),
        type_: Checked::Valid(ty),
        min,
        max,
        name: None,
        normalized,
        sparse: None,
    });
    doc.root.accessors.len() - 1
}
