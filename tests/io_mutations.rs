//! Bad input never panics: small real assets with bytes flipped, truncated or JSON numbers
//! changed are read (and, when readable, processed and written) without a panic.

mod corpus;

use g2tess::gltf_io::{self, ReadOptions, WriteOptions};

/// A small deterministic generator, so failures reproduce.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> usize {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 33) as usize
    }
}

#[test]
fn mutated_assets_never_panic() {
    let Some(corpus) = corpus::fixtures_real() else {
        return;
    };
    let out = corpus::temp_dir();
    let small: Vec<_> = corpus::gltf_files(&corpus.join("valid"))
        .into_iter()
        .filter(|p| std::fs::metadata(p).is_ok_and(|m| m.len() < 20_000))
        .collect();
    let mut rng = Lcg(7);
    for path in &small {
        let original = std::fs::read(path).unwrap();
        for round in 0..60 {
            let mut bytes = original.clone();
            match round % 3 {
                0 => {
                    let i = rng.next() % bytes.len();
                    bytes[i] = rng.next() as u8;
                }
                1 => bytes.truncate(rng.next() % bytes.len()),
                _ => {
                    // Replace a digit: indices, counts and offsets go out of range.
                    let digits: Vec<usize> = (0..bytes.len())
                        .filter(|i| bytes[*i].is_ascii_digit())
                        .collect();
                    if let Some(i) = digits.get(rng.next() % digits.len().max(1)) {
                        bytes[*i] = b'0' + (rng.next() % 10) as u8;
                    }
                }
            }
            let result = std::panic::catch_unwind(|| {
                let Ok(mut doc) =
                    gltf_io::read_bytes(&bytes, path.parent(), &ReadOptions::default())
                else {
                    return;
                };
                let mut options = g2tess::options::Options::default();
                options.level = 2;
                if g2tess::pipeline::process_document(&mut doc, path, &options).is_ok() {
                    let _ =
                        gltf_io::write(&doc, &out.path().join("m.glb"), &WriteOptions::default());
                }
            });
            assert!(result.is_ok(), "{} round {round} panicked", path.display());
        }
    }
}
