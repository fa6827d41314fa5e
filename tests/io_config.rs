//! `config/default.toml` states every setting with the same default as the code.

use g2tess::options::{ConfigFile, Options};

#[test]
fn default_toml_equals_the_defaults_in_code() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/config/default.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let file = ConfigFile::parse(&text, path).unwrap();
    // Every key present: overlaying onto options where every value differs changes them all.
    let every_key = [
        file.level.is_some(),
        file.h.is_some(),
        file.crease_angle.is_some(),
        file.profile.is_some(),
        file.scheme.is_some(),
        file.max_output_triangles.is_some(),
        file.allow_outside_uris.is_some(),
        file.overwrite_input.is_some(),
        file.quantize.is_some(),
        file.compress.is_some(),
    ];
    assert!(
        every_key.iter().all(|k| *k),
        "config/default.toml misses a setting: {file:?}"
    );
    assert_eq!(Options::default().overlay(&file), Options::default());
    Options::default().validate("defaults").unwrap();
}
