//! A global allocator that asks Linux for transparent huge pages on large buffers.
//!
//! A dense tessellation fills a few hundred MiB of fresh memory (the output buffers and the
//! intermediates beside them). With 4 KiB pages every one of those pages is a separate page
//! fault, and on the 100k-triangle benchmark those faults were about a third of the process's
//! time (sys 0.26 s of 0.78 s CPU). Most distributions ship transparent huge pages in `madvise`
//! mode, so a buffer only gets 2 MiB pages when the program asks for them: this allocator does,
//! for every allocation of at least [`HUGE_PAGE_THRESHOLD`] bytes, with
//! `madvise(MADV_HUGEPAGE)` on the page-aligned part of the block before anything touches it.
//! The call is only advice: where the kernel has no huge pages to give, or on other systems,
//! the program behaves exactly as with the system allocator, and the bytes it writes never
//! depend on it.
//!
//! The command-line binary installs it; a program using the library chooses its own allocator.

use std::alloc::{GlobalAlloc, Layout, System};

/// Blocks smaller than this are left alone: they rarely span a whole 2 MiB page, and advising
/// many small ranges would only split the kernel's memory map into more pieces.
pub const HUGE_PAGE_THRESHOLD: usize = 4 << 20;

/// The system allocator, with huge pages requested for large blocks (see the module docs).
#[derive(Debug, Default, Clone, Copy)]
pub struct HugePageAlloc;

// SAFETY: every call is forwarded to `System` with the same arguments; the only addition is an
// `madvise` on memory the returned block owns, which changes no byte of it.
unsafe impl GlobalAlloc for HugePageAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let ptr = unsafe { System.alloc(layout) };
        advise(ptr, layout.size());
        ptr
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let ptr = unsafe { System.alloc_zeroed(layout) };
        advise(ptr, layout.size());
        ptr
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let new_ptr = unsafe { System.realloc(ptr, layout, new_size) };
        if new_size > layout.size() {
            advise(new_ptr, new_size);
        }
        new_ptr
    }
}

/// Requests huge pages for the whole pages inside `[ptr, ptr + size)`.
#[cfg(target_os = "linux")]
fn advise(ptr: *mut u8, size: usize) {
    if ptr.is_null() || size < HUGE_PAGE_THRESHOLD {
        return;
    }
    const PAGE: usize = 4096;
    let start = (ptr as usize).next_multiple_of(PAGE);
    let end = (ptr as usize + size) & !(PAGE - 1);
    if end > start {
        // SAFETY: the range lies inside a block the allocator just handed out; MADV_HUGEPAGE
        // only sets a flag on the mapping and never changes its contents. A failure (a kernel
        // without transparent huge pages) leaves the mapping as it was, which is fine.
        unsafe {
            libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
        }
    }
}

#[cfg(not(target_os = "linux"))]
fn advise(_ptr: *mut u8, _size: usize) {}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    /// The `VmFlags` line of the mapping in `/proc/self/smaps` that contains `addr`.
    fn vm_flags_of(addr: usize) -> Option<String> {
        let smaps = std::fs::read_to_string("/proc/self/smaps").ok()?;
        let mut inside = false;
        for line in smaps.lines() {
            let first = line.split_whitespace().next().unwrap_or("");
            if let Some((lo, hi)) = first.split_once('-') {
                if let (Ok(lo), Ok(hi)) =
                    (usize::from_str_radix(lo, 16), usize::from_str_radix(hi, 16))
                {
                    inside = (lo..hi).contains(&addr);
                    continue;
                }
            }
            if inside {
                if let Some(flags) = line.strip_prefix("VmFlags:") {
                    return Some(flags.trim().to_string());
                }
            }
        }
        None
    }

    /// Transparent huge pages exist and the memory map can be read (a sandbox may hide it).
    fn observable() -> bool {
        std::path::Path::new("/sys/kernel/mm/transparent_hugepage/enabled").exists()
            && std::fs::read_to_string("/proc/self/smaps").is_ok_and(|s| s.contains("VmFlags:"))
    }

    #[test]
    fn large_blocks_are_advised_and_keep_their_bytes() {
        if !observable() {
            eprintln!("skipped: no transparent huge pages, or no readable /proc/self/smaps");
            return;
        }
        let alloc = HugePageAlloc;
        let large = Layout::from_size_align(64 << 20, 8).unwrap();
        let small = Layout::from_size_align(64 << 10, 8).unwrap();
        unsafe {
            let p = alloc.alloc_zeroed(large);
            assert!(!p.is_null());
            // The middle of the block is whole pages, so it must carry the flag ("hg").
            let middle = p as usize + (32 << 20);
            let flags = vm_flags_of(middle).expect("mapping of the large block");
            assert!(flags.split(' ').any(|f| f == "hg"), "flags {flags}");
            // Contents are untouched: still zero, and writable end to end.
            assert_eq!(*p.add(32 << 20), 0);
            p.write_bytes(7, large.size());
            assert_eq!(*p.add(large.size() - 1), 7);

            // Growing keeps the bytes and the advice.
            let q = alloc.realloc(p, large, 96 << 20);
            assert_eq!(*q.add((64 << 20) - 1), 7);
            let flags = vm_flags_of(q as usize + (80 << 20)).expect("mapping of the grown block");
            assert!(flags.split(' ').any(|f| f == "hg"), "flags {flags}");
            alloc.dealloc(q, Layout::from_size_align(96 << 20, 8).unwrap());

            // Small blocks go straight through.
            let s = alloc.alloc(small);
            assert!(!s.is_null());
            s.write_bytes(1, small.size());
            assert_eq!(*s.add(small.size() - 1), 1);
            alloc.dealloc(s, small);
        }
    }
}
