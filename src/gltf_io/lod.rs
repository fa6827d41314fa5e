//! Levels of detail in one document: copies of a mesh for the coarser levels, and nodes that
//! show them, linked from the node of the finest level by `MSFT_lod`
//! (<https://github.com/KhronosGroup/glTF/tree/main/extensions/2.0/Vendor/MSFT_lod>).
//!
//! Everything is added at the [`Document`] level (new meshes, nodes and, through
//! [`super::replace_primitive_owned`], accessors), kept in step in the typed model, the JSON as
//! read and its typed snapshot, so the writer needs no special case. It deliberately decides
//! nothing about which meshes get levels or what the coverage values are: the pipeline does.

use serde_json::{json, Map, Value};

use super::{Document, Error, Result};

/// The extension's name, listed in `extensionsUsed` (never required: a loader without it shows
/// the finest level, which sits where the mesh always was).
pub const MSFT_LOD: &str = "MSFT_lod";

/// The `extras` key of the screen-coverage hints that go with `MSFT_lod`.
pub const SCREEN_COVERAGE: &str = "MSFT_screencoverage";

/// Node extensions a LOD node shares with its finest node: they describe where and how often
/// the mesh is drawn, which a coarser level must do the same way.
const SHARED_NODE_EXTENSIONS: [&str; 1] = ["EXT_mesh_gpu_instancing"];

/// Node properties a LOD node shares with its finest node: its transform, its skin (a skinned
/// level must follow the same joints) and its morph weights (every level carries the targets).
const SHARED_NODE_KEYS: [&str; 6] = [
    "translation",
    "rotation",
    "scale",
    "matrix",
    "skin",
    "weights",
];

/// `name_LOD3`, the suffix Unity's model importer groups levels by within one model (glTF
/// importers read `MSFT_lod` instead; the name still says which is which); unnamed: `LOD3`.
pub fn lod_name(name: Option<&str>, level: usize) -> String {
    match name {
        Some(n) => format!("{n}_LOD{level}"),
        None => format!("LOD{level}"),
    }
}

/// The nodes that show mesh `mesh`, in index order.
pub fn nodes_using(doc: &Document, mesh: usize) -> Vec<usize> {
    (0..doc.root.nodes.len())
        .filter(|&n| doc.root.nodes[n].mesh.is_some_and(|m| m.value() == mesh))
        .collect()
}

/// Why node `node` cannot carry levels of detail, if it cannot: an unskinned node with
/// children (a viewer may put a LOD node in place of the node's whole subtree, and a glTF node
/// has one parent, so the children could not be shared), or one that has `MSFT_lod` already.
///
/// A skinned node's children are allowed: they are usually its skeleton, which the LOD node
/// reaches through the same `skin` (joints are named by index, not by parenthood), and a skinned
/// mesh is placed by its joints, not by its node's transform or place in the tree.
pub fn why_not_linkable(doc: &Document, node: usize) -> Option<&'static str> {
    let raw = doc.raw.pointer(&format!("/nodes/{node}"))?;
    let has_children = raw
        .get("children")
        .and_then(Value::as_array)
        .is_some_and(|c| !c.is_empty());
    if has_children && raw.get("skin").is_none() {
        return Some(
            "it has children and no skin, and a LOD node (which may stand in for the whole subtree) could not share them",
        );
    }
    if raw.pointer(&format!("/extensions/{MSFT_LOD}")).is_some() {
        return Some("it has levels of detail already");
    }
    None
}

/// Appends a copy of mesh `mesh` named for level `level` and returns its index. Its triangle
/// primitives still refer to the input's accessors until the caller replaces them; its other
/// primitives (points, lines) are shared with the original.
pub fn add_mesh_copy(doc: &mut Document, mesh: usize, level: usize) -> Result<usize> {
    let at = format!("meshes[{mesh}]");
    let mut typed = doc
        .root
        .meshes
        .get(mesh)
        .cloned()
        .ok_or_else(|| Error::invalid(&at, "does not exist"))?;
    let name = lod_name(typed.name.as_deref(), level);
    typed.name = Some(name.clone());
    let mut raw = doc
        .raw
        .pointer(&format!("/meshes/{mesh}"))
        .cloned()
        .ok_or_else(|| Error::invalid(&at, "does not exist"))?;
    if let Some(obj) = raw.as_object_mut() {
        obj.insert("name".into(), json!(name));
    }
    let snapshot = serde_json::to_value(&typed).map_err(|e| Error::invalid(&at, e))?;
    push(&mut doc.raw, "meshes", raw, &at)?;
    push(&mut doc.base, "meshes", snapshot, &at)?;
    doc.root.meshes.push(typed);
    Ok(doc.root.meshes.len() - 1)
}

/// Adds one node per mesh of `meshes` (coarser levels, finest first) beside node `node`, and
/// links them from it: `extensions.MSFT_lod.ids` lists them, `extras.MSFT_screencoverage`
/// holds `coverage` (one value per level, the finest's first). Returns the new nodes.
///
/// The new nodes are in no scene and no node's children: only the extension refers to them.
pub fn link_levels(
    doc: &mut Document,
    node: usize,
    meshes: &[usize],
    coverage: &[f64],
) -> Result<Vec<usize>> {
    let at = format!("nodes[{node}]");
    let source = doc
        .raw
        .pointer(&format!("/nodes/{node}"))
        .and_then(Value::as_object)
        .cloned()
        .ok_or_else(|| Error::invalid(&at, "does not exist"))?;
    if !matches!(source.get("extras"), None | Some(Value::Object(_))) {
        return Err(Error::invalid(
            format!("{at}.extras"),
            format!("is not an object, so {SCREEN_COVERAGE} cannot be added to it"),
        ));
    }
    // Unnamed nodes take their level names from the mesh's, so engines can still group them.
    let mesh_name = doc
        .raw
        .pointer(&format!(
            "/meshes/{}/name",
            meshes.first().copied().unwrap_or(0)
        ))
        .and_then(Value::as_str)
        .and_then(|n| n.strip_suffix("_LOD1"))
        .map(str::to_owned);
    let name = source
        .get("name")
        .and_then(Value::as_str)
        .map(str::to_owned)
        .or(mesh_name);
    let name = name.as_deref();
    let mut ids = Vec::with_capacity(meshes.len());
    for (k, &mesh) in meshes.iter().enumerate() {
        let mut lod = Map::new();
        lod.insert("name".into(), json!(lod_name(name, k + 1)));
        lod.insert("mesh".into(), json!(mesh));
        for key in SHARED_NODE_KEYS {
            if let Some(v) = source.get(key) {
                lod.insert(key.into(), v.clone());
            }
        }
        let typed: gltf_json::Node = serde_json::from_value(Value::Object(lod.clone()))
            .map_err(|e| Error::invalid(&at, e))?;
        let shared: Map<String, Value> = SHARED_NODE_EXTENSIONS
            .iter()
            .filter_map(|e| {
                let v = source.get("extensions")?.get(*e)?;
                Some((e.to_string(), v.clone()))
            })
            .collect();
        if !shared.is_empty() {
            lod.insert("extensions".into(), Value::Object(shared));
        }
        let snapshot = serde_json::to_value(&typed).map_err(|e| Error::invalid(&at, e))?;
        push(&mut doc.raw, "nodes", Value::Object(lod), &at)?;
        push(&mut doc.base, "nodes", snapshot, &at)?;
        doc.root.nodes.push(typed);
        ids.push(doc.root.nodes.len() - 1);
    }
    // The typed model does not know the extension: it goes into the JSON as read, which the
    // writer keeps wherever the typed model did not change.
    let raw = doc
        .raw
        .pointer_mut(&format!("/nodes/{node}"))
        .and_then(Value::as_object_mut)
        .ok_or_else(|| Error::invalid(&at, "does not exist"))?;
    let extensions = raw.entry("extensions").or_insert_with(|| json!({}));
    if let Some(e) = extensions.as_object_mut() {
        e.insert(MSFT_LOD.into(), json!({ "ids": ids }));
    }
    let extras = raw.entry("extras").or_insert_with(|| json!({}));
    if let Some(e) = extras.as_object_mut() {
        e.insert(SCREEN_COVERAGE.into(), json!(coverage));
    }
    if !doc.root.extensions_used.iter().any(|e| e == MSFT_LOD) {
        doc.root.extensions_used.push(MSFT_LOD.to_string());
    }
    Ok(ids)
}

/// Appends `value` to the top-level array `key` of `root`.
fn push(root: &mut Value, key: &str, value: Value, at: &str) -> Result<()> {
    root.get_mut(key)
        .and_then(Value::as_array_mut)
        .ok_or_else(|| Error::invalid(at, format!("the document has no `{key}` array")))?
        .push(value);
    Ok(())
}
