//! The job between the command line and the renderer: a plain `Request`
//! built from the command line's arguments, the `Plan` it is checked into,
//! the run over its frames (waves, checkpoints, claims), what a render keeps
//! in its folder (record, lock, checkpoints), the status scan of an output
//! folder, warnings, and the cost probe `info` shows. Nothing here parses
//! arguments or prints.

pub(crate) mod checkpoint;
pub(crate) mod claim;
pub(crate) mod describe;
pub(crate) mod frames;
pub(crate) mod memory;
pub(crate) mod plan;
pub(crate) mod probe;
pub(crate) mod record;
pub mod request;
pub(crate) mod run;
pub(crate) mod status;
pub(crate) mod warnings;
pub(crate) mod waves;

pub use plan::Plan;
pub use request::{Request, Sequence};
