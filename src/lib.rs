//! mandelreel: keyframed Mandelbulb films from RON timelines.
//!
//! Layers, each depending only on those after it:
//! `cli → bench, accuracy → render, output → shade → march → fractal → math`, and `timeline → scene`;
//! `interrupt` (what Ctrl-C cleans up) sits under `output` and `job`.
//! `input` (reading the files a user names) sits below them all.

#![forbid(unsafe_code)]

pub mod accuracy;
pub mod bench;
pub mod camera;
pub mod cli;
pub mod color;
pub mod environment;
pub mod error;
pub mod fractal;
pub mod host;
pub mod input;
pub mod interrupt;
pub mod job;
pub mod march;
pub mod math;
pub mod output;
pub mod pick;
pub mod render;
pub mod scene;
pub mod shade;
pub mod spans;
pub mod timeline;

/// Bumped whenever a change alters rendered pixels, so resume re-renders old frames.
pub const RENDERER_REVISION: u32 = 14;
