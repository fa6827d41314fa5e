//! A file's bytes read by every thread at once.
//!
//! One `read` of a large file runs on one thread, which then takes the first-touch fault of
//! every page of the buffer and copies every byte while the others wait (a 28 MB input: about
//! 6,900 faults before any decoding can start). Read as blocks at their own offsets in
//! parallel, each thread faults and copies its own blocks into one buffer allocated zeroed
//! (fresh pages the kernel zeroes at the fault: nothing is written twice).

use std::fs::File;
use std::io::{self, Read, Seek};
use std::path::Path;

use rayon::prelude::*;

/// Bytes one parallel read takes; smaller files are read in one call.
const BLOCK: usize = 4 << 20;

/// The whole contents of the file at `path`, as [`std::fs::read`] gives them.
pub(crate) fn read_whole(path: &Path) -> io::Result<Vec<u8>> {
    let mut file = File::open(path)?;
    let len = usize::try_from(file.metadata()?.len()).unwrap_or(usize::MAX);
    if len < 2 * BLOCK || rayon::current_num_threads() < 2 {
        return std::fs::read(path);
    }
    let mut bytes = vec![0u8; len];
    let parallel = bytes
        .par_chunks_mut(BLOCK)
        .enumerate()
        .try_for_each(|(i, block)| read_at(&file, block, (i * BLOCK) as u64));
    match parallel {
        // The file shrank while it was read: read it again the ordinary way.
        Err(e) if e.kind() == io::ErrorKind::UnexpectedEof => std::fs::read(path),
        Err(e) => Err(e),
        Ok(()) => {
            // The file grew while it was read: what follows is read as `fs::read` would.
            let mut tail = Vec::new();
            file.seek(io::SeekFrom::Start(len as u64))?;
            file.read_to_end(&mut tail)?;
            bytes.extend_from_slice(&tail);
            Ok(bytes)
        }
    }
}

#[cfg(unix)]
fn read_at(file: &File, block: &mut [u8], offset: u64) -> io::Result<()> {
    std::os::unix::fs::FileExt::read_exact_at(file, block, offset)
}

#[cfg(not(unix))]
fn read_at(file: &File, block: &mut [u8], offset: u64) -> io::Result<()> {
    let mut done = 0;
    while done < block.len() {
        match std::os::windows::fs::FileExt::seek_read(
            file,
            &mut block[done..],
            offset + done as u64,
        ) {
            Ok(0) => return Err(io::ErrorKind::UnexpectedEof.into()),
            Ok(n) => done += n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every byte at its offset, for sizes around the block edges (the pool has two threads,
    /// so the parallel path runs): a block read at a wrong offset or a short last block would
    /// show as a mismatch.
    #[test]
    fn parallel_read_gives_the_file_bytes() {
        let dir = tempfile::tempdir().unwrap();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        for len in [
            0,
            1,
            2 * BLOCK - 1,
            2 * BLOCK,
            2 * BLOCK + 1,
            3 * BLOCK + 12_345,
        ] {
            let want: Vec<u8> = (0..len).map(|i| (i * 31 + i / 4099) as u8).collect();
            let path = dir.path().join(format!("f{len}"));
            std::fs::write(&path, &want).unwrap();
            let got = pool.install(|| read_whole(&path)).unwrap();
            assert!(got == want, "{len} bytes read differently");
        }
    }

    /// A missing file is the same error as `fs::read` gives.
    #[test]
    fn missing_file_is_not_found() {
        let e = read_whole(Path::new("/nonexistent/g2tess/file.glb")).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::NotFound);
    }
}
