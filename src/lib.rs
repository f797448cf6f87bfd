//! mandelreel: keyframed Mandelbulb films from RON timelines.
//!
//! Modules stand in layers, from the command line (`cli`) down through the
//! job, the output files, the timeline and the renderer to the fractal and the
//! arithmetic; each uses only the layers below it. docs/architecture.md lists
//! them and tests/it/layers.rs holds the code to that list.
//!
//! Public are the modules the binary, the tests, the benchmarks and the
//! examples use, and inside them the parts those use; everything else is
//! private to the crate.

#![forbid(unsafe_code)]

mod accuracy;
mod bench;
pub mod camera;
pub mod cli;
mod color;
pub mod deep;
mod environment;
pub mod error;
mod exact;
mod explore;
pub mod fractal;
mod host;
mod input;
mod interrupt;
pub mod job;
pub mod march;
pub mod math;
pub mod output;
mod quality;
pub mod render;
pub mod scene;
mod shade;
pub mod timeline;

/// Bumped whenever a change alters rendered pixels, so resume re-renders old frames.
pub const RENDERER_REVISION: u32 = 16;
