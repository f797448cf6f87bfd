//! The job: what a render into an output folder records and keeps there
//! (its record and lock, checkpoints) and how renders share a folder (claims).

pub mod checkpoint;
pub mod claim;
pub mod record;
