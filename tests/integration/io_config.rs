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

/// Each ranged setting's default and range are written the same in `--help`, the README's
/// settings table and `config/default.toml` as in the one table in code
/// ([`g2tess::options::RANGED_SETTINGS`]).
#[test]
fn help_readme_and_default_toml_state_the_table() {
    let help = std::process::Command::new(env!("CARGO_BIN_EXE_g2tess"))
        .arg("--help")
        .output()
        .unwrap();
    // Joined into one line: clap wraps long help paragraphs.
    let help = String::from_utf8(help.stdout)
        .unwrap()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ");
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).unwrap();
    let toml = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/config/default.toml"))
        .unwrap()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ");
    for s in g2tess::options::RANGED_SETTINGS {
        let flag = format!("--{}", s.key.replace('_', "-"));
        let range = s.range_text();
        // The flag's paragraph in --help: from the flag to the next "--" at a line start.
        let at = help
            .find(&format!("{flag} <"))
            .unwrap_or_else(|| panic!("{flag} in --help"));
        let para = &help[at..];
        let para = &para[..para[2..].find(" --").map_or(para.len(), |e| e + 2)];
        assert!(
            para.contains(&range),
            "--help of {flag} lacks {range:?}: {para}"
        );
        assert!(
            para.contains(&format!("[default: {}]", s.default)),
            "--help of {flag} lacks its default {}: {para}",
            s.default
        );
        let row = readme
            .lines()
            .find(|l| l.starts_with(&format!("| `{flag}")))
            .unwrap_or_else(|| panic!("README has no row for {flag}"));
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        assert_eq!(cells[2], format!("`{}`", s.key), "{row}");
        assert_eq!(
            cells[3],
            s.default.to_string(),
            "README default of {flag}: {row}"
        );
        // The level's range is written with its meaning in between; the others as "a to b".
        assert!(
            row.contains(&range),
            "README row of {flag} lacks {range:?}: {row}"
        );
        let line = toml
            .find(&format!("{} = ", s.key))
            .unwrap_or_else(|| panic!("{} in default.toml", s.key));
        let before = &toml[..line];
        let comment = &before[before.rfind(" = ").unwrap_or(0)..];
        assert!(
            comment.contains(&range),
            "default.toml comment of {} lacks {range:?}: {comment}",
            s.key
        );
    }
}
