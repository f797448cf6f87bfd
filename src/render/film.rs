//! The film: a rendered frame's pixels and layers, how a frame is
//! finished from its sums, and what a frame size costs in memory.

use super::rows::{optional_bands, BAND_ROWS, BAND_TASKS};
use super::sized;
use super::stats::FrameStats;
use crate::math::Vec3;
use rayon::prelude::*;

/// A rendered frame: linear colour, fractal coverage and camera distance per pixel.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    /// Linear RGB, row-major from the top-left pixel.
    pub colour: Vec<Vec3>,
    /// Share of the pixel's samples that hit the fractal.
    pub alpha: Vec<f32>,
    /// Distance from the camera to the nearest hit among the pixel's samples.
    pub depth: Vec<f32>,
    /// Orbits computed for the pixel (all samples): where the frame's time went.
    pub evaluations: Vec<u32>,
    /// Extra layers, present only when asked for (see `Layers`).
    pub normal: Option<Vec<Vec3>>,
    pub albedo: Option<Vec<Vec3>>,
    /// Orbit traps: origin, then the x, y and z planes.
    pub traps: Option<Vec<[f32; 4]>>,
    /// Share of the pixel's samples within the picture, where the
    /// projection leaves part of the image out (beyond a fisheye's circle):
    /// an opaque frame's alpha. `None` where every sample is in it.
    pub coverage: Option<Vec<f32>>,
    pub stats: FrameStats,
}

impl Film {
    /// A film of `width`×`height` with the layers asked for, for
    /// `finish_pixels` to fill (see `Film::prepare`).
    pub(super) fn blank(width: u32, height: u32, layers: Layers) -> Film {
        let mut film = Film::default();
        film.prepare(width, height, layers);
        film
    }

    /// This film sized to `width`×`height` with the layers asked for, in
    /// the buffers it already has where they are big enough, for
    /// `finish_pixels` to fill: it writes every element of every buffer,
    /// so no pass clears them first (a kept buffer that grows has only its
    /// new tail zeroed). A sequence's frames thus reuse pages
    /// already mapped, and a new buffer comes zeroed from the allocator:
    /// when it maps fresh memory (glibc does for big blocks, until freeing
    /// one raises its threshold and it clears reused memory instead, on
    /// the calling thread), as untouched pages that the threads finishing
    /// the bands fault in. (Filled on one thread first, as a new film once
    /// was, that took 3.1–3.4 ms of a 640×480 frame; some 1 ms to clear a
    /// reused one.)
    pub(super) fn prepare(&mut self, width: u32, height: u32, layers: Layers) {
        let pixels = width as usize * height as usize;
        fn layer<T: bytemuck::Zeroable + Clone>(v: &mut Option<Vec<T>>, on: bool, n: usize) {
            if on {
                sized(v.get_or_insert_with(Vec::new), n)
            } else {
                *v = None
            }
        }
        self.width = width;
        self.height = height;
        sized(&mut self.colour, pixels);
        sized(&mut self.alpha, pixels);
        sized(&mut self.depth, pixels);
        sized(&mut self.evaluations, pixels);
        layer(&mut self.normal, layers.normal, pixels);
        layer(&mut self.albedo, layers.albedo, pixels);
        layer(&mut self.traps, layers.traps, pixels);
        self.coverage = None;
        self.stats = FrameStats::default();
    }

    /// Gives the film its coverage layer (`coverage`) where `partial`,
    /// sized like the others, for `finish_pixels` to fill.
    pub(super) fn cover(&mut self, partial: bool) {
        self.coverage = partial.then(|| vec![0.0; self.colour.len()]);
    }

    /// Bytes per pixel of the buffers every film holds (colour, alpha,
    /// depth, evaluations); the optional layers add to it.
    pub const BYTES_PER_PIXEL: usize =
        std::mem::size_of::<Vec3>() + std::mem::size_of::<f32>() * 2 + std::mem::size_of::<u32>();
}

/// Which extra per-pixel layers to collect. Each is averaged over the
/// pixel's samples that hit; a layer not asked for costs no memory.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Layers {
    pub normal: bool,
    pub albedo: bool,
    pub traps: bool,
}

impl Layers {
    /// Bytes a pixel of these layers takes in a film (the normal and the
    /// albedo three f32 each, the traps four).
    pub(super) fn bytes_per_pixel(self) -> u64 {
        12 * (self.normal as u64 + self.albedo as u64) + 16 * self.traps as u64
    }
}

/// About the most memory rendering and writing one frame of `width`×
/// `height` takes (upwards of it): the film (colour, alpha, depth and
/// estimates, 24 bytes a pixel, and the layers); for an EXR as much again
/// for its blocks, for a PNG its 3 bytes of sRGB codes and a byte of
/// compressed data; and for a frame of several samples per pixel the
/// running sums (colour in f64, hits, depth and estimates spent, 40 bytes a
/// pixel, and the layers, and under adaptive sampling each pixel's spread).
/// A `partial` frame (a fisheye's, which covers only its circle) adds its
/// coverage to the film (an f32 a pixel) and to the sums (a u32 a pixel).
/// What a size can be checked against before it is rendered.
pub fn frame_bytes(
    [width, height]: [u32; 2],
    layers: Layers,
    exr: bool,
    sums: Sums,
    partial: bool,
) -> u64 {
    let coverage = 4 * partial as u64;
    let film = 24 + layers.bytes_per_pixel() + coverage;
    let encoding = if exr { film } else { 4 };
    let spread = std::mem::size_of::<super::adaptive::Spread>() as u64;
    let sums = match sums {
        Sums::None => 0,
        Sums::Uniform => 40 + layers.bytes_per_pixel() + coverage,
        Sums::Adaptive => 40 + layers.bytes_per_pixel() + spread + coverage,
    };
    width as u64 * height as u64 * (film + encoding + sums)
}

/// The running sums a frame keeps while it renders (`frame_bytes`): none
/// for one sample a pixel, rendered band by band.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sums {
    None,
    Uniform,
    Adaptive,
}

/// Pixels of a film (a band, or all of them).
pub(super) struct FilmPixels<'a> {
    pub(super) colour: &'a mut [Vec3],
    pub(super) alpha: &'a mut [f32],
    pub(super) depth: &'a mut [f32],
    pub(super) evaluations: &'a mut [u32],
    pub(super) normal: Option<&'a mut [Vec3]>,
    pub(super) albedo: Option<&'a mut [Vec3]>,
    pub(super) traps: Option<&'a mut [[f32; 4]]>,
    pub(super) coverage: Option<&'a mut [f32]>,
}

impl Film {
    /// The film a band of `BAND_ROWS` rows at a time, for finishing bands
    /// in parallel, each band a task of its own (see `BAND_TASKS`).
    pub(super) fn bands_mut(&mut self) -> impl IndexedParallelIterator<Item = FilmPixels<'_>> {
        let (w, h) = (self.width as usize, self.height as usize);
        let band = BAND_ROWS * w;
        let normal = self.normal.as_deref_mut().unwrap_or_default();
        let albedo = self.albedo.as_deref_mut().unwrap_or_default();
        let traps = self.traps.as_deref_mut().unwrap_or_default();
        let coverage = self.coverage.as_deref_mut().unwrap_or_default();
        self.colour
            .par_chunks_mut(band)
            .zip(self.alpha.par_chunks_mut(band))
            .zip(self.depth.par_chunks_mut(band))
            .zip(self.evaluations.par_chunks_mut(band))
            .zip(optional_bands(normal, w, h))
            .zip(optional_bands(albedo, w, h))
            .zip(optional_bands(traps, w, h))
            .zip(optional_bands(coverage, w, h))
            .map(
                |(
                    ((((((colour, alpha), depth), evaluations), normal), albedo), traps),
                    coverage,
                )| {
                    FilmPixels {
                        colour,
                        alpha,
                        depth,
                        evaluations,
                        normal,
                        albedo,
                        traps,
                        coverage,
                    }
                },
            )
            .with_max_len(BAND_TASKS)
    }
}
