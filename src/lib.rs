//! mandelreel: keyframed Mandelbulb films from RON timelines.
//!
//! Modules stand in layers, from the command line (`cli`) down through the
//! job, the output files, the timeline and the renderer to the fractal and the
//! arithmetic; each uses only the layers below it. docs/architecture.md lists
//! them and tests/it/layers.rs holds the code to that list.

#![forbid(unsafe_code)]

pub mod accuracy;
pub mod bench;
pub mod camera;
pub mod cli;
pub mod color;
pub mod deep;
pub mod environment;
pub mod error;
pub mod exact;
pub mod explore;
pub mod fractal;
pub mod host;
pub mod input;
pub mod interrupt;
pub mod job;
pub mod march;
pub mod math;
pub mod output;
pub mod quality;
pub mod render;
pub mod scene;
pub mod shade;
pub mod timeline;

/// Bumped whenever a change alters rendered pixels, so resume re-renders old frames.
pub const RENDERER_REVISION: u32 = 15;
