//! `config/default.toml` states every setting with the same default as the code.

use g2tess::options::{ConfigFile, Options};

#[test]
fn default_toml_equals_the_defaults_in_code() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/config/default.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let file = ConfigFile::parse(&text, path).unwrap();
    // Every setting present: the file's keys are exactly the fields of `ConfigFile`.
    let fields: Vec<String> = match serde_json::to_value(ConfigFile::default()).unwrap() {
        serde_json::Value::Object(o) => o.keys().cloned().collect(),
        other => panic!("ConfigFile serializes as {other}"),
    };
    let table: toml::Table = toml::from_str(&text).unwrap();
    let mut keys: Vec<String> = table.keys().cloned().collect();
    let mut fields = fields;
    keys.sort();
    fields.sort();
    assert_eq!(keys, fields, "config/default.toml and ConfigFile disagree");
    assert_eq!(Options::default().overlay(&file), Options::default());
    Options::default().validate("defaults").unwrap();
}
