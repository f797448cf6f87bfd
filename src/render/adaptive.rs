//! Adaptive sampling: the waves a frame's samples come in, and which pixels
//! take the next wave. A pixel goes on while the standard error of its
//! mean display value, or a neighbour's, is above the scene's `noise`,
//! while a camera ray of it grazed the surface, or while it stands out from
//! a neighbour: a detail smaller than a pixel is often missed by all of a
//! pixel's first samples, but seldom by its neighbours' too.
//!
//! Every decision is taken from the sums of a finished wave over the whole
//! frame, never from a band's own: the image does not depend on the
//! threads, and a frame resumed from a checkpoint decides alike.

use super::Accumulation;
use crate::color::SrgbCurve;
use crate::math::{Real, Vec3};
use crate::scene::{Adaptive, Scene};
use rayon::prelude::*;

/// What adaptive sampling keeps of a pixel besides its sums: the samples
/// it took, how many of its camera rays grazed the surface, and the sum
/// and sum of squares of its samples' display values.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Spread {
    pub taken: u32,
    pub grazes: u32,
    pub sum: f64,
    pub squares: f64,
}

/// A miss that came within this many pixel footprints of the surface
/// grazed it: the surface covers part of the pixel that no sample hit.
const GRAZE_FOOTPRINTS: Real = 1.0;

/// A pixel whose mean display value differs from a neighbour's by more
/// than this many times `noise` takes more samples.
const CONTRAST_NOISES: f64 = 8.0;

impl Spread {
    /// Adds one sample: its radiance `c` as it will be displayed, and
    /// whether its camera ray missed within a footprint of the surface.
    pub(super) fn add(&mut self, c: Vec3, display: &crate::color::Display, closest: Real) {
        let v = display_value(c, display) as f64;
        self.taken += 1;
        self.grazes += (closest < GRAZE_FOOTPRINTS) as u32;
        self.sum += v;
        self.squares += v * v;
    }

    fn mean(&self) -> f64 {
        self.sum / self.taken.max(1) as f64
    }

    /// The standard error of the mean display value; 0 before two samples.
    fn error(&self) -> f64 {
        if self.taken < 2 {
            return 0.0;
        }
        let m = self.taken as f64;
        let variance = ((self.squares - self.sum * self.mean()) / (m - 1.0)).max(0.0);
        (variance / m).sqrt()
    }
}

/// A sample's display value: the luma of its sRGB-coded colour, as the
/// frame's PNG will show it (exposure, tone map, sRGB curve).
fn display_value(c: Vec3, display: &crate::color::Display) -> f32 {
    let curve = SrgbCurve::get();
    let code = |x: f32| curve.value(display.apply(x));
    0.2126 * code(c.x) + 0.7152 * code(c.y) + 0.0722 * code(c.z)
}

/// Samples per pixel every pixel still refining has after the wave that
/// follows `done`: uniform sampling in about 16 even waves; adaptive in
/// `first`, then doubling, up to `samples_per_pixel`.
pub fn next_wave(scene: &Scene, done: u32) -> u32 {
    let n = scene.samples_per_pixel.max(1);
    match &scene.adaptive {
        None => (done + n.div_ceil(16)).min(n),
        Some(a) if done == 0 => a.first.clamp(1, n),
        Some(_) => done.saturating_mul(2).min(n),
    }
}

/// The waves of samples a frame of `scene` takes.
pub fn wave_count(scene: &Scene) -> u32 {
    let n = scene.samples_per_pixel.max(1);
    let (mut done, mut waves) = (0, 0);
    while done < n {
        done = next_wave(scene, done);
        waves += 1;
    }
    waves
}

/// Which pixels of `acc`, a wave or more in, take the next wave: those
/// still refining (`Spread` and the module's rules).
pub(super) fn refining(adaptive: &Adaptive, acc: &Accumulation, out: &mut Vec<bool>) {
    let done = acc.samples_done;
    debug_assert!(done > 0 && acc.spread.len() == acc.colour.len());
    let (w, h) = (acc.width as usize, acc.height as usize);
    let noise = adaptive.noise as f64;
    let spread = &acc.spread;
    // Each pixel's error once, then each pixel's decision from the finished
    // wave alone: any split of the pixels over threads decides alike.
    let mut noisy = Vec::new();
    noisy.par_extend(
        spread
            .par_iter()
            .map(|p| p.taken >= done && p.error() > noise),
    );
    out.clear();
    out.par_extend((0..w * h).into_par_iter().map(|i| {
        let p = &spread[i];
        if p.taken < done {
            return false; // stopped by an earlier wave
        }
        p.grazes > 0
            || neighbours(i, w, h).any(|j| noisy[j])
            || stands_out(spread, i, w, h, noise * CONTRAST_NOISES)
    }));
}

/// Pixel `i` and its neighbours (eight, fewer at the frame's edges).
fn neighbours(i: usize, w: usize, h: usize) -> impl Iterator<Item = usize> {
    let (x, y) = (i % w, i / w);
    let ys = y.saturating_sub(1)..(y + 2).min(h);
    ys.flat_map(move |ny| (x.saturating_sub(1)..(x + 2).min(w)).map(move |nx| ny * w + nx))
}

/// Whether pixel `i`'s mean differs from one of its eight neighbours' by
/// more than `contrast`.
fn stands_out(spread: &[Spread], i: usize, w: usize, h: usize, contrast: f64) -> bool {
    let mean = spread[i].mean();
    neighbours(i, w, h).any(|j| (spread[j].mean() - mean).abs() > contrast)
}

#[cfg(test)]
mod tests;
