//! The `g2tess` command line.
mod cli;

/// Huge pages for the large buffers of a dense tessellation (see `g2tess::huge_pages`).
#[global_allocator]
static ALLOCATOR: g2tess::huge_pages::HugePageAlloc = g2tess::huge_pages::HugePageAlloc;

fn main() {
    std::process::exit(cli::run());
}
