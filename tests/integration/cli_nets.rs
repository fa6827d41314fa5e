//! `--nets` and the `nets` configuration key: `paper` gives the published PN surface, the same
//! from the flag and from a file, different from the default round nets; a bad value is a usage
//! error naming the file and line.

use crate::corpus;

use std::path::{Path, PathBuf};

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/icosahedron.glb")
}

#[test]
fn paper_nets_from_flag_and_file_agree_and_differ_from_the_default() {
    let dir = corpus::temp_dir();
    let config = dir.path().join("paper.toml");
    std::fs::write(&config, "nets = \"paper\"\n").unwrap();
    let out = |name: &str, args: &[&std::ffi::OsStr]| {
        let path = dir.path().join(name);
        let run = corpus::g2tess()
            .arg(example())
            .arg("-o")
            .arg(&path)
            .args(args)
            .output()
            .unwrap();
        assert_eq!(run.status.code(), Some(0), "{run:?}");
        std::fs::read(path).unwrap()
    };
    let default = out("default.glb", &[]);
    let round = out("round.glb", &["--nets".as_ref(), "round".as_ref()]);
    let flag = out("flag.glb", &["--nets".as_ref(), "paper".as_ref()]);
    let file = out("file.glb", &["--config".as_ref(), config.as_os_str()]);
    assert_eq!(default, round);
    assert_eq!(flag, file);
    assert_ne!(default, flag);
}

#[test]
fn unknown_nets_value_names_file_and_line() {
    let dir = corpus::temp_dir();
    let config = dir.path().join("bad.toml");
    std::fs::write(&config, "level = 2\nnets = \"square\"\n").unwrap();
    let run = corpus::g2tess()
        .arg(example())
        .arg("--config")
        .arg(&config)
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains(&format!("{}:2: ", config.display())) && stderr.contains("square"),
        "{stderr}"
    );
}
