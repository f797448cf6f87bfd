//! `mandelreel bench`: whole renders timed against Mandelbulber2 on the same
//! frames, the distance-estimator kernel measured against the machine's
//! floating-point peak, thread scaling, peak memory and depth error against
//! the accuracy reference (Mandelbulber2's too, from its z-buffer); written
//! to `bench/results/<machine>.csv` and the Markdown tables of docs/performance.md.
//!
//! Every render runs in its own process, timed from spawn to exit (start-up,
//! parsing and PNG encoding included: what a user waits for), under a small
//! `mandelreel measure` wrapper whose only child it is, so the wrapper's
//! `getrusage(RUSAGE_CHILDREN)` is that render's peak resident memory.
//! mandelreel and Mandelbulber2 runs alternate (A B, B A, …) so drift in the
//! machine's speed falls on both alike; medians are reported.

mod ceiling;
mod child;
mod mandelbulber2;
mod options;
mod peak;
mod report;
mod rows;
mod run;
mod scenes;

pub use child::measure_child;
pub use options::Options;
pub use peak::{default_machine_name, Peak};
pub use run::run_and_write;
