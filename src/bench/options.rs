//! What a bench run is asked to do, and its progress lines.

use super::peak::Peak;
use std::path::PathBuf;

/// What the bench is asked to do.
#[derive(Clone, Debug)]
pub struct Options {
    /// Folder of benchmark timelines (`timelines/bench`).
    pub scenes: PathBuf,
    /// Folder of the matching Mandelbulber2 settings (`bench/mandelbulber2`).
    pub fract_dir: PathBuf,
    /// The Mandelbulber2 program, when it is to be compared.
    pub mandelbulber: Option<PathBuf>,
    /// A/B pairs per scene, and samples per pool of the in-process
    /// (render only), kernel and ceiling rows.
    pub runs: usize,
    /// Thread counts for the scaling rows (every scene; in-process on the
    /// first; the kernel alone).
    pub threads: Vec<usize>,
    /// Size of the peak-memory render; `None` skips it.
    pub memory_size: Option<(u32, u32)>,
    /// Size of the depth comparison against the accuracy reference; `None` skips it.
    pub depth_size: Option<(u32, u32)>,
    /// Where `<machine>.csv` and `<machine>.md` go.
    pub results: PathBuf,
    pub machine: String,
    /// The machine's peak, detected once for every row.
    pub peak: Peak,
    pub quiet: bool,
}

pub(super) fn log(quiet: bool, message: &str) {
    if !quiet {
        eprintln!("{message}");
    }
}
