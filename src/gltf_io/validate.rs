//! The checks that make the reader refuse what the glTF specification calls an error: node
//! cycles, attribute formats, counts, indices out of range, non-finite or non-unit data, bounds
//! that disagree with the data they describe.
//!
//! It deliberately checks only what would make the output wrong or invalid; advice-level issues
//! (unused objects, missing tangents) are left to the Khronos validator.

use std::collections::{BTreeMap, BTreeSet};

use gltf_json::accessor::{ComponentType, Type};
use gltf_json::mesh::{Mode, Semantic};
use gltf_json::validation::Checked;
use serde_json::Value;

use super::accessor::{self, Accessor};
use super::document::Document;
use super::error::{Error, Result};

/// How far a unit vector's length may be from 1: loose enough for 8-bit quantized normals,
/// tight enough to catch zero and garbage vectors.
const UNIT_TOLERANCE: f64 = 0.02;
/// How far skin weights may sum from 1 (8-bit weights round by up to 4 × 1/510).
const WEIGHT_SUM_TOLERANCE: f64 = 0.02;

/// Is `mode` one the tool replaces with a triangle list?
pub fn is_triangle_mode(mode: &Checked<Mode>) -> bool {
    matches!(
        mode,
        Checked::Valid(Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan)
    )
}

/// Every index a primitive holds points at an existing accessor. `gltf-json`'s own validation
/// indexes POSITION without checking, so this runs first.
pub fn primitive_references(root: &gltf_json::Root) -> Result<()> {
    let n = root.accessors.len();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let at = format!("meshes[{m}].primitives[{p}]");
            for (sem, a) in &prim.attributes {
                if a.value() >= n {
                    return Err(Error::invalid(
                        format!("{at}.attributes.{}", semantic_name(sem)),
                        format!(
                            "refers to accessor {} but there are {n} (expected an index in range)",
                            a.value()
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// JSON-only checks, before any buffer is read.
pub fn structure(root: &gltf_json::Root, _raw: &Value) -> Result<()> {
    for (i, ext) in root.extensions_required.iter().enumerate() {
        if !root.extensions_used.contains(ext) {
            return Err(Error::invalid(
                format!("extensionsRequired[{i}]"),
                format!("{ext} is not listed in extensionsUsed (expected every required extension to be used)"),
            ));
        }
    }
    nodes(root)?;
    for (m, mesh) in root.meshes.iter().enumerate() {
        let targets = mesh
            .primitives
            .first()
            .map_or(0, |p| p.targets.as_ref().map_or(0, Vec::len));
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let at = format!("meshes[{m}].primitives[{p}]");
            let n = prim.targets.as_ref().map_or(0, Vec::len);
            if n != targets {
                return Err(Error::invalid(
                    format!("{at}.targets"),
                    format!(
                        "{n} morph targets (expected {targets}, as in the mesh's first primitive)"
                    ),
                ));
            }
            primitive_formats(root, prim, &at)?;
        }
        if let Some(w) = &mesh.weights {
            if w.len() != targets {
                return Err(Error::invalid(
                    format!("meshes[{m}].weights"),
                    format!(
                        "has {} entries (expected one per morph target: {targets})",
                        w.len()
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Every node has at most one parent, no cycles, and matrices that are affine TRS transforms.
fn nodes(root: &gltf_json::Root) -> Result<()> {
    let n = root.nodes.len();
    let mut parent = vec![None; n];
    for (i, node) in root.nodes.iter().enumerate() {
        for c in node.children.iter().flatten() {
            let c = c.value();
            if let Some(p) = parent[c] {
                return Err(Error::invalid(
                    format!("nodes[{i}].children"),
                    format!(
                        "node {c} is already a child of node {p} (expected one parent per node)"
                    ),
                ));
            }
            parent[c] = Some(i);
        }
        if let Some(m) = node.matrix {
            let mat = glam::Mat4::from_cols_array(&m);
            let (s, r, t) = mat.to_scale_rotation_translation();
            let back = glam::Mat4::from_scale_rotation_translation(s, r, t);
            let scale = m.iter().fold(1.0f32, |a, v| a.max(v.abs()));
            let affine = m[3] == 0.0 && m[7] == 0.0 && m[11] == 0.0 && m[15] == 1.0;
            if !affine || !back.abs_diff_eq(mat, 1e-3 * scale) || !mat.is_finite() {
                return Err(Error::invalid(
                    format!("nodes[{i}].matrix"),
                    "is not decomposable into translation, rotation and scale (expected a TRS matrix)",
                ));
            }
        }
    }
    for start in 0..n {
        let (mut at, mut steps) = (start, 0);
        while let Some(p) = parent[at] {
            at = p;
            steps += 1;
            if p == start || steps > n {
                return Err(Error::invalid(
                    format!("nodes[{start}]"),
                    "is its own ancestor (expected a tree of nodes)",
                ));
            }
        }
    }
    Ok(())
}

fn semantic_name(s: &Checked<Semantic>) -> String {
    match s {
        Checked::Valid(s) => s.to_string(),
        Checked::Invalid => "?".into(),
    }
}

/// Attribute sets are numbered from 0 without gaps; formats are the ones the spec (with
/// KHR_mesh_quantization where required) allows; counts agree.
fn primitive_formats(
    root: &gltf_json::Root,
    prim: &gltf_json::mesh::Primitive,
    at: &str,
) -> Result<()> {
    let quantized = root
        .extensions_required
        .iter()
        .any(|e| e == "KHR_mesh_quantization");
    let mut sets: BTreeMap<&str, BTreeSet<u32>> = BTreeMap::new();
    let mut count = None;
    for (sem, index) in &prim.attributes {
        let name = semantic_name(sem);
        let aat = format!("{at}.attributes.{name}");
        let a = &root.accessors[index.value()];
        let (Checked::Valid(ct), Checked::Valid(ty)) = (&a.component_type, &a.type_) else {
            return Err(Error::invalid(
                aat,
                "accessor has an invalid componentType or type",
            ));
        };
        check_format(sem, ct.0, *ty, a.normalized, quantized, false, &aat)?;
        match sem {
            Checked::Valid(Semantic::TexCoords(n)) => {
                sets.entry("TEXCOORD").or_default().insert(*n)
            }
            Checked::Valid(Semantic::Colors(n)) => sets.entry("COLOR").or_default().insert(*n),
            Checked::Valid(Semantic::Joints(n)) => sets.entry("JOINTS").or_default().insert(*n),
            Checked::Valid(Semantic::Weights(n)) => sets.entry("WEIGHTS").or_default().insert(*n),
            _ => true,
        };
        match count {
            None => count = Some((a.count.0, name)),
            Some((c, ref first)) if c != a.count.0 => {
                return Err(Error::invalid(
                    aat,
                    format!(
                        "has {} elements but {first} has {c} (expected equal counts)",
                        a.count.0
                    ),
                ))
            }
            _ => {}
        }
    }
    for (kind, set) in &sets {
        if let Some(missing) = (0..set.len() as u32).find(|n| !set.contains(n)) {
            return Err(Error::invalid(
                format!("{at}.attributes"),
                format!(
                    "has {kind}_{} but no {kind}_{missing} (expected sets numbered from 0)",
                    set.iter().max().unwrap()
                ),
            ));
        }
    }
    if sets.get("JOINTS") != sets.get("WEIGHTS") {
        return Err(Error::invalid(
            format!("{at}.attributes"),
            "JOINTS_n and WEIGHTS_n sets do not pair up (expected one WEIGHTS_n per JOINTS_n)",
        ));
    }
    for (t, target) in prim.targets.iter().flatten().enumerate() {
        let list = [
            (Semantic::Positions, target.positions),
            (Semantic::Normals, target.normals),
            (Semantic::Tangents, target.tangents),
        ];
        for (sem, index) in list {
            let Some(index) = index else { continue };
            let aat = format!("{at}.targets[{t}].{}", sem.to_string());
            let a = &root.accessors[index.value()];
            let (Checked::Valid(ct), Checked::Valid(ty)) = (&a.component_type, &a.type_) else {
                return Err(Error::invalid(
                    aat,
                    "accessor has an invalid componentType or type",
                ));
            };
            check_format(
                &Checked::Valid(sem),
                ct.0,
                *ty,
                a.normalized,
                quantized,
                true,
                &aat,
            )?;
            if let Some((c, first)) = &count {
                if *c != a.count.0 {
                    return Err(Error::invalid(
                        aat,
                        format!(
                            "has {} elements but {first} has {c} (expected equal counts)",
                            a.count.0
                        ),
                    ));
                }
            }
        }
    }
    let vertices = count.map(|(c, _)| c);
    if let Some(indices) = prim.indices {
        let a = &root.accessors[indices.value()];
        let ok = matches!(a.type_, Checked::Valid(Type::Scalar))
            && matches!(&a.component_type, Checked::Valid(c) if matches!(c.0, ComponentType::U8 | ComponentType::U16 | ComponentType::U32))
            && !a.normalized;
        if !ok {
            return Err(Error::invalid(format!("{at}.indices"), "accessor is not an unsigned integer SCALAR (expected componentType 5121, 5123 or 5125)"));
        }
    }
    if is_triangle_mode(&prim.mode) {
        if !prim
            .attributes
            .contains_key(&Checked::Valid(Semantic::Positions))
        {
            return Err(Error::invalid(
                format!("{at}.attributes"),
                "a triangle primitive has no POSITION (expected a VEC3 POSITION accessor)",
            ));
        }
        let n = prim
            .indices
            .map_or(vertices.unwrap_or(0), |i| root.accessors[i.value()].count.0);
        if matches!(prim.mode, Checked::Valid(Mode::Triangles)) && n % 3 != 0 {
            let what = if prim.indices.is_some() {
                "indices"
            } else {
                "vertices"
            };
            return Err(Error::invalid(
                at,
                format!("{n} {what} do not form whole triangles (expected a multiple of 3)"),
            ));
        }
    }
    Ok(())
}

/// The component formats the spec allows per semantic; KHR_mesh_quantization widens them.
fn check_format(
    sem: &Checked<Semantic>,
    ct: ComponentType,
    ty: Type,
    normalized: bool,
    quantized: bool,
    target: bool,
    at: &str,
) -> Result<()> {
    use ComponentType as C;
    let float = ct == C::F32;
    let unorm = normalized && matches!(ct, C::U8 | C::U16);
    let snorm = normalized && matches!(ct, C::I8 | C::I16);
    let small_int = matches!(ct, C::I8 | C::U8 | C::I16 | C::U16);
    let (types, core, widened): (&[Type], bool, bool) = match sem {
        Checked::Valid(Semantic::Positions) => (&[Type::Vec3], float, small_int),
        Checked::Valid(Semantic::Normals) => (&[Type::Vec3], float, snorm || (target && small_int && normalized)),
        Checked::Valid(Semantic::Tangents) => (if target { &[Type::Vec3] } else { &[Type::Vec4] }, float, snorm),
        Checked::Valid(Semantic::TexCoords(_)) => (&[Type::Vec2], float || unorm, small_int),
        Checked::Valid(Semantic::Colors(_)) => (&[Type::Vec3, Type::Vec4], float || unorm, false),
        Checked::Valid(Semantic::Joints(_)) => (&[Type::Vec4], !normalized && matches!(ct, C::U8 | C::U16), false),
        Checked::Valid(Semantic::Weights(_)) => (&[Type::Vec4], float || unorm, false),
        Checked::Valid(Semantic::Extras(_)) => return Ok(()),
        Checked::Invalid => return Err(Error::invalid(at, "is not a glTF attribute semantic (expected POSITION, NORMAL, TANGENT, TEXCOORD_n, COLOR_n, JOINTS_n, WEIGHTS_n or a name starting with _)")),
    };
    if !types.contains(&ty) {
        return Err(Error::invalid(
            at,
            format!("accessor type is {ty:?} (expected {types:?})"),
        ));
    }
    if core || (widened && quantized) {
        return Ok(());
    }
    if widened {
        return Err(Error::invalid(
            at,
            format!("componentType {ct:?} (normalized: {normalized}) needs KHR_mesh_quantization (expected it in extensionsRequired)"),
        ));
    }
    Err(Error::invalid(
        at,
        format!("componentType {ct:?} (normalized: {normalized}) is not allowed for this semantic"),
    ))
}

/// Buffer views lie inside their buffers and have legal strides.
pub fn buffer_views(root: &gltf_json::Root, buffers: &[&[u8]]) -> Result<()> {
    for (i, v) in root.buffer_views.iter().enumerate() {
        let at = format!("bufferViews[{i}]");
        let b = v.buffer.value();
        let end = v
            .byte_offset
            .map_or(0, |o| o.0)
            .checked_add(v.byte_length.0);
        let declared = root.buffers[b].byte_length.0;
        let compressed = v.extensions.as_ref().is_some_and(|e| {
            super::meshopt_decode::EXTENSIONS
                .iter()
                .any(|n| e.others.contains_key(*n))
        });
        if end.is_none_or(|e| e > declared || (!compressed && e > buffers[b].len() as u64)) {
            return Err(Error::invalid(
                &at,
                format!("byteOffset + byteLength = {} runs past the end of buffers[{b}] ({declared} bytes)", end.unwrap_or(u64::MAX)),
            ));
        }
        if let Some(s) = v.byte_stride {
            if s.0 < 4 || s.0 > 252 || s.0 % 4 != 0 {
                return Err(Error::invalid(
                    format!("{at}.byteStride"),
                    format!("{} (expected a multiple of 4 from 4 to 252)", s.0),
                ));
            }
            if s.0 as u64 > v.byte_length.0 {
                return Err(Error::invalid(
                    format!("{at}.byteStride"),
                    format!(
                        "{} is larger than the view's byteLength {} (expected a stride that fits)",
                        s.0, v.byte_length.0
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Which accessors the writer carries through unchanged (anything not used solely by triangle
/// primitives, which are rewritten with fresh bounds).
fn carried_accessors(root: &gltf_json::Root) -> Vec<bool> {
    let mut carried = vec![true; root.accessors.len()];
    let mut other_use = vec![false; root.accessors.len()];
    for mesh in &root.meshes {
        for prim in &mesh.primitives {
            let tri = is_triangle_mode(&prim.mode);
            let targets = prim
                .targets
                .iter()
                .flatten()
                .flat_map(|t| [t.positions, t.normals, t.tangents])
                .flatten();
            for a in prim
                .attributes
                .values()
                .copied()
                .chain(prim.indices)
                .chain(targets)
            {
                if tri {
                    carried[a.value()] = false;
                } else {
                    other_use[a.value()] = true;
                }
            }
        }
    }
    carried
        .iter()
        .zip(&other_use)
        .map(|(c, o)| *c || *o)
        .collect()
}

/// Data checks: finite floats, bounds arrays of the right length (and equal to the data where
/// the accessor is carried through), indices in range, unit tangents, valid skin weights.
///
/// Every accessor is decoded, so their declared sizes together must fit in `budget` (see
/// [`super::ReadOptions::EXPANSION_FACTOR`]); each is checked before it is allocated.
pub fn data(doc: &Document, max_bytes: u64, budget: u64) -> Result<()> {
    let root = &doc.root;
    let carried = carried_accessors(root);
    let mut decoded: Vec<Option<Accessor<'_>>> = vec![None; root.accessors.len()];
    let mut total = 0u64;
    for (i, a) in root.accessors.iter().enumerate() {
        let at = format!("accessors[{i}]");
        total = total.saturating_add(accessor::decoded_size(a));
        if total > budget {
            return Err(Error::invalid(
                format!("{at}.count"),
                format!("the accessors up to this one decode to {total} bytes, over the budget of {budget} for this file's data (expected counts that match the data)"),
            ));
        }
        // Read in place where the data is tightly packed: checking copies nothing.
        let acc = accessor::read(doc, i, max_bytes)?;
        if acc.component_type == ComponentType::F32 {
            if let Some((k, x)) = acc.find_first(|x| !x.is_finite()) {
                return Err(Error::invalid(
                    &at,
                    format!(
                        "element {} holds {} (expected finite numbers)",
                        k / acc.components,
                        x
                    ),
                ));
            }
        }
        check_bounds(a, &acc, carried[i], &at)?;
        decoded[i] = Some(acc);
    }
    let get = |i: usize| decoded[i].as_ref().expect("every accessor decoded above");
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let at = format!("meshes[{m}].primitives[{p}]");
            let draco = prim
                .extensions
                .as_ref()
                .is_some_and(|e| e.others.contains_key("KHR_draco_mesh_compression"));
            if draco {
                continue; // its accessors are placeholders; reading the primitive reports Draco
            }
            let vertices = prim
                .attributes
                .values()
                .next()
                .map_or(0, |a| get(a.value()).count);
            if let Some(ix) = prim.indices {
                let acc = get(ix.value());
                let restart = match acc.component_type {
                    ComponentType::U8 => 255.0,
                    ComponentType::U16 => 65535.0,
                    _ => 4294967295.0,
                };
                if let Some((k, v)) = acc.find_first(|v| v == restart || v >= vertices as f64) {
                    return Err(Error::invalid(
                        format!("{at}.indices"),
                        format!("index {v} at position {k} (expected a vertex below {vertices}, not the restart value {restart})"),
                    ));
                }
            }
            // Normals need no check of their own: a normal's direction is all the surface
            // needs (the pipeline normalizes one of another length and rebuilds a zero one, an
            // exporter's "no normal here", from the faces around its vertex, each with a
            // warning), and finiteness, all that matters, was checked for every float accessor
            // above (integer ones are finite).
            for (sem, ix) in &prim.attributes {
                if *sem == Checked::Valid(Semantic::Tangents) {
                    let aat = format!("{at}.attributes.{}", semantic_name(sem));
                    unit_tangents(get(ix.value()), &aat)?;
                }
            }
            skin_data(doc, m, prim, &at, &get)?;
        }
    }
    Ok(())
}

/// Declared `min` and `max` must be arrays of one number per component, and equal the data's
/// own bounds where the accessor is carried through unchanged. The data's bounds are computed
/// only there: a triangle primitive's accessors are rewritten with fresh bounds, and scanning
/// them (most of a large file) would decide nothing.
fn check_bounds(a: &gltf_json::Accessor, acc: &Accessor, carried: bool, at: &str) -> Result<()> {
    let mut bounds = None;
    for (key, declared) in [("min", &a.min), ("max", &a.max)] {
        let Some(declared) = declared else { continue };
        let values: Option<Vec<f64>> = declared
            .as_array()
            .map(|v| v.iter().map(Value::as_f64).collect())
            .unwrap_or(None);
        let Some(values) = values.filter(|v| v.len() == acc.components) else {
            return Err(Error::invalid(
                format!("{at}.{key}"),
                format!(
                    "is not an array of {} numbers (expected one per component)",
                    acc.components
                ),
            ));
        };
        // Zero-filled accessors are not checked (the Khronos validator does not either).
        let zero_filled = a.buffer_view.is_none() && a.sparse.is_none();
        if !carried || acc.is_empty() || zero_filled {
            continue;
        }
        let (actual_min, actual_max) = bounds.get_or_insert_with(|| data_bounds(acc));
        let actual = if key == "min" { actual_min } else { actual_max };
        let float = acc.component_type == ComponentType::F32;
        for (c, (d, v)) in values.iter().zip(actual.iter()).enumerate() {
            let same = if float {
                (*d as f32) == (*v as f32)
            } else {
                d == v
            };
            if !same {
                return Err(Error::invalid(
                    format!("{at}.{key}[{c}]"),
                    format!("is {d} but the data's {key} is {v} (expected declared bounds to match the data)"),
                ));
            }
        }
    }
    Ok(())
}

/// The per-component minimum and maximum of `acc`'s data, widened as [`Accessor::for_each`]
/// gives it.
fn data_bounds(acc: &Accessor) -> (Vec<f64>, Vec<f64>) {
    let mut actual_min = vec![f64::INFINITY; acc.components];
    let mut actual_max = vec![f64::NEG_INFINITY; acc.components];
    let mut c = 0;
    acc.for_each(|x| {
        actual_min[c] = actual_min[c].min(x);
        actual_max[c] = actual_max[c].max(x);
        c = if c + 1 == acc.components { 0 } else { c + 1 };
    });
    (actual_min, actual_max)
}

/// Tangents are finite unit vectors with w = ±1.
fn unit_tangents(acc: &Accessor<'_>, at: &str) -> Result<()> {
    let n = acc.components;
    let v = acc.to_f32();
    for (e, chunk) in v.chunks_exact(n).enumerate() {
        if chunk.iter().any(|x| !x.is_finite()) {
            return Err(Error::invalid(
                at,
                format!("element {e} is not finite (expected a unit vector)"),
            ));
        }
        let len = (chunk[..3].iter().map(|x| (*x as f64).powi(2)).sum::<f64>()).sqrt();
        if (len - 1.0).abs() > UNIT_TOLERANCE {
            return Err(Error::invalid(
                at,
                format!("element {e} has length {len:.4} (expected a unit vector)"),
            ));
        }
        if n == 4 && chunk[3].abs() != 1.0 {
            return Err(Error::invalid(
                at,
                format!("element {e} has w = {} (expected 1 or -1)", chunk[3]),
            ));
        }
    }
    Ok(())
}

/// Joint indices exist in every skin the mesh is used with; weights are non-negative and sum to 1.
fn skin_data<'a>(
    doc: &Document,
    mesh: usize,
    prim: &gltf_json::mesh::Primitive,
    at: &str,
    get: &dyn Fn(usize) -> &'a Accessor<'a>,
) -> Result<()>
where
{
    let root = &doc.root;
    let joints: Vec<_> = (0..)
        .map_while(|n| prim.attributes.get(&Checked::Valid(Semantic::Joints(n))))
        .collect();
    let weights: Vec<_> = (0..)
        .map_while(|n| prim.attributes.get(&Checked::Valid(Semantic::Weights(n))))
        .collect();
    if weights.is_empty() {
        return Ok(());
    }
    let wvals: Vec<Vec<f32>> = weights.iter().map(|w| get(w.value()).to_f32()).collect();
    let count = get(weights[0].value()).count;
    for v in 0..count {
        let mut sum = 0.0;
        for (set, w) in wvals.iter().enumerate() {
            for c in 0..4 {
                let x = w[v * 4 + c] as f64;
                if x < 0.0 {
                    return Err(Error::invalid(
                        format!("{at}.attributes.WEIGHTS_{set}"),
                        format!("vertex {v} has a negative weight {x} (expected weights >= 0)"),
                    ));
                }
                sum += x;
            }
        }
        if (sum - 1.0).abs() > WEIGHT_SUM_TOLERANCE {
            return Err(Error::invalid(
                format!("{at}.attributes.WEIGHTS_0"),
                format!("vertex {v}'s weights sum to {sum} (expected 1)"),
            ));
        }
    }
    let skins: BTreeSet<usize> = root
        .nodes
        .iter()
        .filter(|n| n.mesh.map(|m| m.value()) == Some(mesh))
        .filter_map(|n| n.skin.map(|s| s.value()))
        .collect();
    for skin in skins {
        let limit = root.skins[skin].joints.len() as u32;
        for (set, j) in joints.iter().enumerate() {
            if let Some((k, bad)) = get(j.value())
                .to_u32()
                .iter()
                .enumerate()
                .find(|(_, x)| **x >= limit)
            {
                return Err(Error::invalid(
                    format!("{at}.attributes.JOINTS_{set}"),
                    format!("vertex {} uses joint {bad}, but skins[{skin}] has {limit} joints (expected a joint below {limit})", k / 4),
                ));
            }
        }
    }
    Ok(())
}
