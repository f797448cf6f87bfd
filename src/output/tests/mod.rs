//! Tests of frame files in each format, written and checked back.

mod atomic;
mod exr;
mod frames;
mod png;

use super::frames::write_frame;
use super::Format;
use crate::math::Vec3;
use crate::render::{Film, FrameStats};
use std::path::Path;

/// `write_frame` without layers, shown as by default.
fn write_plain(path: &Path, format: Format, film: &Film, hash: &str) {
    write_frame(path, format, film, hash, &[], &super::Encoding::default()).unwrap();
}

fn film() -> Film {
    Film {
        width: 3,
        height: 2,
        colour: vec![Vec3::new(0.0, 0.5, 1.0); 6],
        alpha: vec![1.0; 6],
        depth: vec![2.5; 6],
        evaluations: vec![7; 6],
        normal: None,
        albedo: None,
        traps: None,
        coverage: None,
        stats: FrameStats::default(),
    }
}
