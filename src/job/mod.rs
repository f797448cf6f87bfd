//! The job between the command line and the renderer: a plain `Request`
//! built from the command line's arguments, the `Plan` it is checked into,
//! the run over its frames (waves, checkpoints, claims), what a render keeps
//! in its folder (record, lock, checkpoints), the status scan of an output
//! folder, warnings, and the cost probe `info` shows. Nothing here parses
//! arguments or prints.

pub mod checkpoint;
pub mod claim;
pub mod describe;
pub mod frames;
pub mod memory;
pub mod plan;
pub mod probe;
pub mod record;
pub mod request;
pub mod run;
pub mod status;
pub mod warnings;
pub mod waves;

pub use plan::Plan;
pub use request::{Request, Sequence};
