//! `hil-sim`: the host tool of the MR clutch controller. See `hil-sim --help`.

mod cli;

use clap::Parser;

fn main() {
    map_large_buffers();
    let args = cli::Cli::parse();
    if let Err(e) = cli::run(args) {
        // One line, with the chain of causes.
        eprintln!("error: {}", format!("{e:#}").replace('\n', " "));
        std::process::exit(1);
    }
}

/// Large buffers (a long recording's channels, a fit's kinematics and shifted copies) are
/// mapped and unmapped on their own. glibc raises its mapping threshold to the size of each
/// such buffer freed and then serves the next ones from a heap arena, where freed memory stays
/// resident: the peak resident memory then grows past what is live (by about half on a fit of
/// a long recording). A fixed threshold of 256 KiB keeps the resident memory what is in use.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn map_large_buffers() {
    // SAFETY: mallopt only sets an allocator parameter; called before any thread starts.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 256 << 10);
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn map_large_buffers() {}
