//! Fuzz target: the whole per-file job on in-memory bytes (read, smooth, quantize, compress,
//! write), and the output read back. Any panic, abort or non-finite number in the output is a
//! finding; an error return is the expected answer to bad input.
//!
//! The options vary with the input's length (never with its bytes, so the real assets used as
//! seeds stay valid glTF): every scheme, with and without quantization and compression.
#![no_main]

use std::path::Path;

use g2tess::gltf_io::{self, Compression, ReadOptions};
use g2tess::options::{Options, Scheme};
use g2tess::pipeline;

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| {
    let Ok(mut doc) = gltf_io::read_bytes(bytes, None, &ReadOptions::default()) else {
        return;
    };
    let n = bytes.len();
    let mut options = Options::default();
    options.level = 2;
    // Small enough that one execution stays fast; large enough for every seed at level 2.
    options.max_output_triangles = 400_000;
    options.scheme = [Scheme::G2, Scheme::Pn, Scheme::Hybrid, Scheme::Coons][n % 4];
    let asset = Path::new("fuzz-input.glb");
    if pipeline::process_document(&mut doc, asset, &options).is_err() {
        return;
    }
    if n % 3 == 0 {
        let q = gltf_io::Quantization::default().with_octahedral(n % 2 == 0);
        if gltf_io::quantize(&mut doc, &q).is_err() {
            return;
        }
    }
    let compression = (n % 2 == 0).then(|| Compression::new(false));
    let Ok(out) = gltf_io::to_glb_bytes(&doc, compression) else {
        return;
    };
    // What we write must read back: valid, bounded, and finite everywhere.
    if let Err(e) = gltf_io::read_bytes(&out, None, &ReadOptions::default()) {
        panic!("the output does not read back: {e}");
    }
});
