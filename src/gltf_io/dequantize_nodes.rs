//! Puts the dequantization of integer positions (see [`mod@super::quantize`]) into the node graph:
//! every node that uses a quantized mesh hands the mesh to a new child node whose translation and
//! uniform scale map the integers back to the mesh's space.
//!
//! A child node rather than an edit of the node itself, because the node may be animated, carry a
//! matrix, or have children of its own, none of which may see the dequantization. The mesh's
//! morph weights move with it, and `weights` animation channels follow. It deliberately works on
//! the output JSON, after the typed model has been merged, so the rest of each node is kept
//! verbatim.

use std::collections::BTreeMap;

use serde_json::{json, Map, Value};

use super::quantize::Dequantize;

/// Moves each quantized mesh to a dequantizing child of every node that uses it.
pub(crate) fn apply(root: &mut Map<String, Value>, meshes: &BTreeMap<usize, Dequantize>) {
    if meshes.is_empty() {
        return;
    }
    let Some(nodes) = root.get_mut("nodes").and_then(Value::as_array_mut) else {
        return;
    };
    let mut children = Vec::new();
    let mut moved = BTreeMap::new();
    let first_new = nodes.len();
    for (i, node) in nodes.iter_mut().enumerate() {
        let Some(obj) = node.as_object_mut() else {
            continue;
        };
        let Some(d) = obj
            .get("mesh")
            .and_then(Value::as_u64)
            .and_then(|m| meshes.get(&(m as usize)))
        else {
            continue;
        };
        let mut child = Map::new();
        child.insert(
            "mesh".into(),
            obj.shift_remove("mesh").expect("checked above"),
        );
        if let Some(w) = obj.shift_remove("weights") {
            child.insert("weights".into(), w);
        }
        child.insert("translation".into(), json!(d.offset.map(shortest)));
        let s = shortest(d.scale);
        child.insert("scale".into(), json!([s, s, s]));
        let index = first_new + children.len();
        match obj.get_mut("children").and_then(Value::as_array_mut) {
            Some(list) => list.push(json!(index)),
            None => {
                obj.insert("children".into(), json!([index]));
            }
        }
        moved.insert(i as u64, index);
        children.push(Value::Object(child));
    }
    nodes.extend(children);
    retarget_weight_channels(root, &moved);
}

/// `x` as the shortest decimal that reads back as the same `f32` (not its exact binary value,
/// which prints with 17 digits).
fn shortest(x: f32) -> f64 {
    x.to_string().parse().unwrap_or(f64::from(x))
}

/// Points `weights` animation channels of a node whose mesh moved at the new child.
fn retarget_weight_channels(root: &mut Map<String, Value>, moved: &BTreeMap<u64, usize>) {
    let channels = root
        .get_mut("animations")
        .and_then(Value::as_array_mut)
        .into_iter()
        .flatten()
        .filter_map(|a| a.get_mut("channels").and_then(Value::as_array_mut))
        .flatten();
    for channel in channels {
        let Some(target) = channel.get_mut("target").and_then(Value::as_object_mut) else {
            continue;
        };
        if target.get("path").and_then(Value::as_str) != Some("weights") {
            continue;
        }
        if let Some(child) = target
            .get("node")
            .and_then(Value::as_u64)
            .and_then(|n| moved.get(&n))
        {
            target.insert("node".into(), json!(child));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shared_mesh_gets_one_child_per_node_and_weights_follow() {
        let mut root = json!({
            "nodes": [
                {"mesh": 0, "weights": [0.5], "children": [1], "name": "a"},
                {"mesh": 0, "translation": [1, 0, 0]},
                {"mesh": 1}
            ],
            "animations": [{"channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}}]}]
        });
        let meshes = BTreeMap::from([(
            0,
            Dequantize {
                offset: [1.0, 2.0, 3.0],
                scale: 0.5,
            },
        )]);
        apply(root.as_object_mut().unwrap(), &meshes);
        assert_eq!(root["nodes"][0]["children"], json!([1, 3]));
        assert_eq!(root["nodes"][0].get("mesh"), None);
        assert_eq!(root["nodes"][3]["weights"], json!([0.5]));
        assert_eq!(root["nodes"][4]["mesh"], json!(0));
        assert_eq!(root["nodes"][4]["scale"], json!([0.5, 0.5, 0.5]));
        assert_eq!(root["nodes"][2]["mesh"], json!(1));
        assert_eq!(
            root["animations"][0]["channels"][0]["target"]["node"],
            json!(3)
        );
    }
}
