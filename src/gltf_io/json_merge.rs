//! A three-way JSON merge that lets the typed `gltf-json` model edit a document without losing
//! what that model does not keep (numbers beyond `f32` precision, properties it does not know,
//! key order, defaults the file left out).
//!
//! `base` is the typed model serialized right after reading, `now` the same after edits, `raw`
//! the file as read. Where `now` equals `base` the raw JSON is kept verbatim; where it differs the
//! edit wins. It deliberately knows nothing of glTF.

use serde_json::{Map, Value};

/// Merges the edit `base → now` into `raw`.
pub fn merge(base: &Value, now: &Value, raw: &Value) -> Value {
    if now == base {
        return raw.clone();
    }
    match (base, now, raw) {
        (Value::Object(b), Value::Object(n), Value::Object(r)) => {
            Value::Object(merge_objects(b, n, r))
        }
        (Value::Array(b), Value::Array(n), Value::Array(r))
            if b.len() == n.len() && n.len() == r.len() =>
        {
            Value::Array(
                b.iter()
                    .zip(n)
                    .zip(r)
                    .map(|((b, n), r)| merge(b, n, r))
                    .collect(),
            )
        }
        _ => now.clone(),
    }
}

fn merge_objects(
    b: &Map<String, Value>,
    n: &Map<String, Value>,
    r: &Map<String, Value>,
) -> Map<String, Value> {
    let mut out = Map::new();
    for (key, raw) in r {
        match (b.get(key), n.get(key)) {
            (Some(base), Some(now)) => {
                out.insert(key.clone(), merge(base, now, raw));
            }
            (None, Some(now)) => {
                out.insert(key.clone(), now.clone());
            }
            // The typed model never saw this key: carry it.
            (None, None) => {
                out.insert(key.clone(), raw.clone());
            }
            // Removed by the edit.
            (Some(_), None) => {}
        }
    }
    for (key, now) in n {
        if !r.contains_key(key) {
            out.insert(key.clone(), now.clone());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn unchanged_subtrees_keep_the_raw_text() {
        let raw = json!({"a": 0.1, "unknown": 1, "b": [1, 2]});
        let base = json!({"a": 0.100000001, "b": [1, 2]});
        let now = json!({"a": 0.100000001, "b": [1, 3]});
        assert_eq!(
            merge(&base, &now, &raw),
            json!({"a": 0.1, "unknown": 1, "b": [1, 3]})
        );
    }

    #[test]
    fn removed_keys_stay_removed() {
        let raw = json!({"a": 1, "b": 2});
        let base = json!({"a": 1, "b": 2});
        let now = json!({"a": 1});
        assert_eq!(merge(&base, &now, &raw), json!({"a": 1}));
    }
}
