//! `--merge-reports FILE`: the JSON reports of several runs (the shards of a CI matrix) as one,
//! as if a single run had processed every input.
//!
//! Records are kept whole, whatever fields they have, and sorted by input so that the merged
//! report does not depend on the order the shards finished in. Counts in `summary` add up;
//! `seconds` is the longest run's (the wall time of shards running side by side), and the
//! exit status is the worst. It refuses reports of another format, version or mode, and an
//! input reported twice (overlapping shards), since a sum of those would be wrong.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde_json::{Map, Value};

/// Merges `reports` into `out`; returns the merged exit status, or an error naming the file.
pub fn run(reports: &[PathBuf], out: &Path) -> Result<i32, String> {
    let mut merged: Option<Map<String, Value>> = None;
    let mut files: BTreeMap<String, (Value, &Path)> = BTreeMap::new();
    for path in reports {
        let shown = path.display();
        let text = std::fs::read(path)
            .map_err(|e| format!("{shown}: {}", e.to_string().to_lowercase()))?;
        let Ok(Value::Object(mut report)) = serde_json::from_slice::<Value>(&text) else {
            return Err(format!(
                "{shown}: not a JSON object (expected a report written by --report)"
            ));
        };
        let Some(Value::Array(records)) = report.remove("files") else {
            return Err(format!(
                "{shown}: files: missing (expected a report written by --report)"
            ));
        };
        for record in records {
            let input = record
                .get("input")
                .and_then(Value::as_str)
                .ok_or_else(|| {
                    format!("{shown}: files[]: no input (expected a report written by --report)")
                })?
                .to_string();
            if let Some((_, first)) = files.get(&input) {
                return Err(format!(
                    "{shown}: {input} is also in {} (expected shards that do not overlap)",
                    first.display()
                ));
            }
            files.insert(input, (record, path));
        }
        merged = Some(match merged {
            None => report,
            Some(acc) => combine(acc, report).map_err(|e| format!("{shown}: {e}"))?,
        });
    }
    let Some(mut merged) = merged else {
        return Err("no report given (expected report files as inputs)".into());
    };
    let status = merged
        .get("exit_status")
        .and_then(Value::as_i64)
        .unwrap_or(0);
    merged.insert(
        "files".into(),
        Value::Array(files.into_values().map(|(v, _)| v).collect()),
    );
    let mut text = serde_json::to_vec_pretty(&Value::Object(merged)).map_err(|e| e.to_string())?;
    text.push(b'\n');
    g2tess::gltf_io::write::atomic_write(out, &text).map_err(|e| e.to_string())?;
    Ok(i32::try_from(status).unwrap_or(1))
}

/// Adds report `b` (without its files) to `a`.
fn combine(mut a: Map<String, Value>, b: Map<String, Value>) -> Result<Map<String, Value>, String> {
    for key in ["format", "version", "mode"] {
        if a.get(key) != b.get(key) {
            return Err(format!(
                "{key}: {} (expected {} as in the first report)",
                b.get(key).unwrap_or(&Value::Null),
                a.get(key).unwrap_or(&Value::Null)
            ));
        }
    }
    let status = |m: &Map<String, Value>| m.get("exit_status").and_then(Value::as_i64).unwrap_or(0);
    let worst = status(&a).max(status(&b));
    a.insert("exit_status".into(), worst.into());
    if let (Some(Value::Object(sa)), Some(Value::Object(sb))) =
        (a.get_mut("summary"), b.get("summary"))
    {
        for (key, vb) in sb {
            let va = sa.entry(key.clone()).or_insert(Value::from(0));
            *va = match (key.as_str(), va.as_u64(), vb.as_u64()) {
                ("seconds", ..) => {
                    Value::from(va.as_f64().unwrap_or(0.0).max(vb.as_f64().unwrap_or(0.0)))
                }
                (_, Some(x), Some(y)) => Value::from(x + y),
                _ => Value::from(va.as_f64().unwrap_or(0.0) + vb.as_f64().unwrap_or(0.0)),
            };
        }
    }
    Ok(a)
}
