//! A frame in progress: per-pixel running sums that waves of samples add
//! to and a resumed render continues from.

use super::adaptive::Spread;
use super::film::{Film, FilmPixels, Layers};
use super::rows::{optional_bands, BAND_ROWS, BAND_TASKS};
use super::stats::FrameStats;
use super::BACKGROUND_DEPTH;
use crate::math::Vec3;
use rayon::prelude::*;

/// A frame in progress: per-pixel running sums over the samples done so far,
/// enough to continue it later. Samples are always added to a pixel in
/// sample order, so a frame rendered in waves, or resumed from a saved
/// accumulation, ends bit-identical to one rendered in one go.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Accumulation {
    pub width: u32,
    pub height: u32,
    pub samples_done: u32,
    pub colour: Vec<[f64; 3]>,
    pub hits: Vec<u32>,
    pub depth: Vec<f32>,
    pub spent: Vec<u64>,
    /// Layer sums; empty when the layer is not collected.
    pub normal: Vec<Vec3>,
    pub albedo: Vec<Vec3>,
    pub traps: Vec<[f32; 4]>,
    /// Each pixel's samples and their spread under adaptive sampling;
    /// empty for uniform sampling, where every pixel has `samples_done`.
    pub spread: Vec<Spread>,
    /// Each pixel's samples within the picture, where the projection
    /// leaves some of the image out (a fisheye's circle); empty otherwise.
    pub inside: Vec<u32>,
    pub stats: FrameStats,
}

impl Accumulation {
    /// Empty sums for `height` rows, every element written rather than left
    /// to the allocator's zero pages: sums are read before they are
    /// written, and a zero page first read and then written is copied on
    /// write, each copy flushing the TLB of every other core running the
    /// frame.
    pub fn new(width: u32, height: u32, layers: Layers) -> Accumulation {
        let mut acc = Accumulation::default();
        acc.reset(width, height, layers);
        acc
    }

    /// Empties the sums for `height` rows of `width`, keeping their memory.
    pub(super) fn reset(&mut self, width: u32, height: u32, layers: Layers) {
        fn refill<T: Clone>(v: &mut Vec<T>, n: usize, value: T) {
            v.clear();
            v.resize(n, value);
        }
        let pixels = width as usize * height as usize;
        let layer = |on: bool| if on { pixels } else { 0 };
        (self.width, self.height, self.samples_done) = (width, height, 0);
        refill(&mut self.colour, pixels, [0.0; 3]);
        refill(&mut self.hits, pixels, 0);
        refill(&mut self.depth, pixels, BACKGROUND_DEPTH);
        refill(&mut self.spent, pixels, 0);
        refill(&mut self.normal, layer(layers.normal), Vec3::ZERO);
        refill(&mut self.albedo, layer(layers.albedo), Vec3::ZERO);
        refill(&mut self.traps, layer(layers.traps), [0.0; 4]);
        self.spread.clear();
        self.inside.clear();
        self.stats = FrameStats::default();
    }

    /// The layers these sums collect.
    pub(super) fn layers(&self) -> Layers {
        Layers {
            normal: !self.normal.is_empty(),
            albedo: !self.albedo.is_empty(),
            traps: !self.traps.is_empty(),
        }
    }

    /// All the sums as one run of pixels (for a one-band accumulation, its band).
    pub(super) fn all_mut(&mut self) -> RowSums<'_> {
        RowSums {
            colour: &mut self.colour,
            hits: &mut self.hits,
            depth: &mut self.depth,
            spent: &mut self.spent,
            normal: (!self.normal.is_empty()).then_some(&mut self.normal[..]),
            albedo: (!self.albedo.is_empty()).then_some(&mut self.albedo[..]),
            traps: (!self.traps.is_empty()).then_some(&mut self.traps[..]),
            spread: (!self.spread.is_empty()).then_some(&mut self.spread[..]),
            inside: (!self.inside.is_empty()).then_some(&mut self.inside[..]),
        }
    }

    /// Starts counting each pixel's samples within the picture, before any
    /// sample.
    pub(super) fn start_coverage(&mut self) {
        debug_assert_eq!(self.samples_done, 0);
        self.inside.clear();
        self.inside.resize(self.colour.len(), 0);
    }

    /// Starts the per-pixel spreads of adaptive sampling, before any sample.
    pub(super) fn start_spreads(&mut self) {
        debug_assert_eq!(self.samples_done, 0);
        self.spread.clear();
        self.spread.resize(self.colour.len(), Spread::default());
    }

    /// The sums a band of `BAND_ROWS` rows at a time, for rendering bands
    /// in parallel, each band a task of its own (`with_max_len(1)`; see
    /// `BAND_TASKS`).
    pub(super) fn bands_mut(&mut self) -> impl IndexedParallelIterator<Item = RowSums<'_>> {
        let (w, h) = (self.width as usize, self.height as usize);
        let band = BAND_ROWS * w;
        self.colour
            .par_chunks_mut(band)
            .zip(self.hits.par_chunks_mut(band))
            .zip(self.depth.par_chunks_mut(band))
            .zip(self.spent.par_chunks_mut(band))
            .zip(optional_bands(&mut self.normal, w, h))
            .zip(optional_bands(&mut self.albedo, w, h))
            .zip(optional_bands(&mut self.traps, w, h))
            .zip(optional_bands(&mut self.spread, w, h))
            .zip(optional_bands(&mut self.inside, w, h))
            .map(
                |(
                    (((((((colour, hits), depth), spent), normal), albedo), traps), spread),
                    inside,
                )| {
                    RowSums {
                        colour,
                        hits,
                        depth,
                        spent,
                        normal,
                        albedo,
                        traps,
                        spread,
                        inside,
                    }
                },
            )
            .with_max_len(BAND_TASKS)
    }

    /// The finished film, with `n` samples per pixel.
    pub fn finish(self, n: u32) -> Film {
        let mut film = Film::blank(self.width, self.height, self.layers());
        film.cover(!self.inside.is_empty());
        let all = FilmPixels {
            colour: &mut film.colour,
            alpha: &mut film.alpha,
            depth: &mut film.depth,
            evaluations: &mut film.evaluations,
            normal: film.normal.as_deref_mut(),
            albedo: film.albedo.as_deref_mut(),
            traps: film.traps.as_deref_mut(),
            coverage: film.coverage.as_deref_mut(),
        };
        let max_pixel = finish_pixels(&self, n, all);
        film.stats = self.stats.finished(max_pixel);
        film
    }
}

/// One band of an accumulation's sums.
pub(super) struct RowSums<'a> {
    pub(super) colour: &'a mut [[f64; 3]],
    pub(super) hits: &'a mut [u32],
    pub(super) depth: &'a mut [f32],
    pub(super) spent: &'a mut [u64],
    pub(super) normal: Option<&'a mut [Vec3]>,
    pub(super) albedo: Option<&'a mut [Vec3]>,
    pub(super) traps: Option<&'a mut [[f32; 4]]>,
    pub(super) spread: Option<&'a mut [Spread]>,
    pub(super) inside: Option<&'a mut [u32]>,
}

/// Averages the sums of `sums` (all its pixels) over `n` samples into
/// `out`, pixel for pixel; returns the most estimates one pixel took.
pub(super) fn finish_pixels(sums: &Accumulation, n: u32, out: FilmPixels) -> u64 {
    // Every element of `out` is written (a film is not cleared before:
    // `Film::prepare`), which the zips below do only with sums as long.
    let pixels = sums.colour.len();
    let layer =
        |out: Option<usize>, sums: usize| out.is_none_or(|len| len == pixels && sums == len);
    debug_assert!(
        [
            out.colour.len(),
            out.alpha.len(),
            out.depth.len(),
            out.evaluations.len()
        ]
        .into_iter()
        .chain([sums.hits.len(), sums.depth.len(), sums.spent.len()])
        .all(|len| len == pixels)
            && layer(out.normal.as_ref().map(|v| v.len()), sums.normal.len())
            && layer(out.albedo.as_ref().map(|v| v.len()), sums.albedo.len())
            && layer(out.traps.as_ref().map(|v| v.len()), sums.traps.len())
            && layer(out.coverage.as_ref().map(|v| v.len()), sums.inside.len()),
        "a band's film and sums differ in size"
    );
    // Under adaptive sampling each pixel has the samples it took.
    let taken = |i: usize| sums.spread.get(i).map_or(n, |p| p.taken).max(1);
    for (i, (c, s)) in out.colour.iter_mut().zip(&sums.colour).enumerate() {
        let inv = 1.0 / taken(i) as f64;
        *c = Vec3::new(
            (s[0] * inv) as f32,
            (s[1] * inv) as f32,
            (s[2] * inv) as f32,
        );
    }
    for (i, (a, &h)) in out.alpha.iter_mut().zip(&sums.hits).enumerate() {
        *a = h as f32 / taken(i) as f32;
    }
    out.depth.copy_from_slice(&sums.depth);
    for (e, &s) in out.evaluations.iter_mut().zip(&sums.spent) {
        *e = s.min(u32::MAX as u64) as u32;
    }
    // A pixel no sample hit has zero layer sums, which stay zero.
    let per_hit = |i: usize| 1.0 / sums.hits[i].max(1) as f32;
    if let Some(normal) = out.normal {
        for (o, v) in normal.iter_mut().zip(&sums.normal) {
            *o = v.normalize_or_zero();
        }
    }
    if let Some(albedo) = out.albedo {
        for (i, (o, &v)) in albedo.iter_mut().zip(&sums.albedo).enumerate() {
            *o = v * per_hit(i);
        }
    }
    if let Some(coverage) = out.coverage {
        for (i, (o, &k)) in coverage.iter_mut().zip(&sums.inside).enumerate() {
            *o = k as f32 / taken(i) as f32;
        }
    }
    if let Some(traps) = out.traps {
        for (i, (o, v)) in traps.iter_mut().zip(&sums.traps).enumerate() {
            *o = v.map(|x| x * per_hit(i));
        }
    }
    sums.spent.iter().copied().max().unwrap_or(0)
}
