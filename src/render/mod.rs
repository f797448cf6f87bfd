//! Turning a scene into a film: camera rays, the deterministic sampler, bands
//! of four rows of pixels spread over rayon's threads (a band's camera rays,
//! in cones over blocks of pixels, and its shadow rays marched side by side),
//! and per-frame counters.
//!
//! Every pixel depends only on (scene, frame, pixel, sample) and on the
//! pixels its camera rays share a cone with (fixed by the image size and
//! `quality.cone_rays`), never on which thread ran it or in which order, so
//! the image is identical for any thread count.

use crate::scene::Scene;
use rayon::prelude::*;

mod accumulation;
pub(crate) mod adaptive;
mod band;
mod film;
pub(crate) mod pick;
mod rows;
mod sampler;
mod stats;

use accumulation::finish_pixels;
pub use accumulation::Accumulation;
pub use adaptive::{next_wave, wave_count};
use band::{render_band, FrameSetup, ROW_SUMS};
pub use film::{frame_bytes, Film, Layers, Sums};
use rows::BAND_ROWS;
pub use stats::FrameStats;

/// Depth written for pixels that see only background.
pub const BACKGROUND_DEPTH: f32 = 1.0e10;

/// Renders `scene` at `width`×`height` as frame `frame_index`. `on_row` is called
/// once per finished row (from any thread) for progress display.
pub fn render_frame(
    scene: &Scene,
    frame_index: u32,
    width: u32,
    height: u32,
    on_row: &(dyn Fn() + Sync),
) -> Film {
    let mut film = Film::default();
    render_frame_into(
        &mut film,
        std::slice::from_ref(scene),
        frame_index,
        width,
        height,
        Layers::default(),
        on_row,
    );
    film
}

/// Renders into `film` a frame whose samples see `scenes` in turn (sample
/// s the scene s mod len): one scene for a still instant, one per sample
/// for motion blur. The film's buffers are reused (see `Film::prepare`), so
/// a sequence's frames can share one; the pixels are those of a new film,
/// bit for bit.
pub fn render_frame_into(
    film: &mut Film,
    scenes: &[Scene],
    frame_index: u32,
    width: u32,
    height: u32,
    layers: Layers,
    on_row: &(dyn Fn() + Sync),
) {
    let n = scenes[0].samples_per_pixel.max(1);
    if scenes[0].adaptive.is_some() && n > 1 {
        // Adaptive sampling judges pixels between waves, frame-wide.
        let never = || false;
        *film = render_in_waves(scenes, frame_index, (width, height), layers, on_row, &never)
            .expect("a render that is never stopped finishes");
        return;
    }
    let frame = FrameSetup::new(scenes, frame_index, width, height, 0..n, on_row);
    film.prepare(width, height, layers);
    film.cover(frame.partial);
    // Every band of rows renders in parallel into this thread's one-band
    // sums (the running sums, f64 colour and counters, exist for a band at
    // a time, not the frame) and is finished straight into its place in the
    // film: no point where threads wait for each other.
    film.stats = film
        .bands_mut()
        .enumerate()
        .map(|(band, pixels)| {
            let mut sums = ROW_SUMS.take();
            let rows = pixels.colour.len() / width as usize;
            sums.reset(width, rows as u32, layers);
            if frame.partial {
                sums.start_coverage();
            }
            let stats = render_band(&frame, band * BAND_ROWS, sums.all_mut());
            let max_pixel = finish_pixels(&sums, n, pixels);
            ROW_SUMS.set(sums);
            stats.finished(max_pixel)
        })
        // `+` keeps the larger per-pixel maximum.
        .reduce(FrameStats::default, |a, b| a + b);
}

/// A frame rendered wave after wave of samples into whole-frame sums, as
/// `render` takes them; none where `stop` says so first.
pub fn render_in_waves(
    scenes: &[Scene],
    frame_index: u32,
    (width, height): (u32, u32),
    layers: Layers,
    on_row: &(dyn Fn() + Sync),
    stop: &(dyn Fn() -> bool + Sync),
) -> Option<Film> {
    let n = scenes[0].samples_per_pixel.max(1);
    let mut acc = Accumulation::new(width, height, layers);
    while acc.samples_done < n {
        let until = next_wave(&scenes[0], acc.samples_done);
        if !render_samples_unless(scenes, frame_index, &mut acc, until, on_row, stop) {
            return None;
        }
    }
    Some(acc.finish(n))
}

/// `v` at `n` elements: kept, with whatever values it holds, where its
/// buffer is big enough; else a new one of zeros from the allocator, whose
/// untouched pages are faulted in by the first write to each.
fn sized<T: bytemuck::Zeroable + Clone>(v: &mut Vec<T>, n: usize) {
    if v.capacity() < n {
        *v = bytemuck::zeroed_vec(n);
    } else {
        v.resize(n, T::zeroed());
    }
}

/// Adds samples `acc.samples_done .. until` of every pixel to `acc`.
pub fn render_samples(
    scenes: &[Scene],
    frame_index: u32,
    acc: &mut Accumulation,
    until: u32,
    on_row: &(dyn Fn() + Sync),
) {
    let finished = render_samples_unless(scenes, frame_index, acc, until, on_row, &|| false);
    debug_assert!(finished);
}

/// `render_samples`, given up as soon as `stop` says so (checked before
/// each band): then it returns false and `acc` holds no usable image.
pub fn render_samples_unless(
    scenes: &[Scene],
    frame_index: u32,
    acc: &mut Accumulation,
    until: u32,
    on_row: &(dyn Fn() + Sync),
    stop: &(dyn Fn() -> bool + Sync),
) -> bool {
    let samples = acc.samples_done..until;
    if scenes[0].adaptive.is_some() && acc.samples_done == 0 {
        acc.start_spreads();
    }
    let mut active = Vec::new();
    if let (Some(a), true) = (&scenes[0].adaptive, acc.samples_done > 0) {
        adaptive::refining(a, acc, &mut active);
    }
    let mut frame = FrameSetup::new(scenes, frame_index, acc.width, acc.height, samples, on_row);
    if frame.partial && acc.samples_done == 0 {
        acc.start_coverage();
    }
    frame.active = (!active.is_empty()).then_some(&active[..]);
    let stopped = std::sync::atomic::AtomicBool::new(false);
    // One band of rows per task; rayon spreads bands over threads and each
    // pixel depends only on its own samples and its band, so the result is
    // independent of the split.
    let stats = acc
        .bands_mut()
        .enumerate()
        .map(|(band, sums)| {
            if stopped.load(std::sync::atomic::Ordering::Relaxed) || stop() {
                stopped.store(true, std::sync::atomic::Ordering::Relaxed);
                return FrameStats::default();
            }
            render_band(&frame, band * BAND_ROWS, sums)
        })
        .reduce(FrameStats::default, |a, b| a + b);
    acc.stats = acc.stats + stats;
    acc.samples_done = until;
    !stopped.into_inner()
}

/// The default scene under adaptive sampling from `first` samples up to
/// `cap`, for the tests of the sampler and of the waves.
#[cfg(test)]
fn adaptive_scene(first: u32, cap: u32) -> Scene {
    Scene {
        samples_per_pixel: cap,
        adaptive: Some(crate::scene::Adaptive {
            first,
            ..crate::scene::Adaptive::default()
        }),
        ..Scene::default()
    }
}

#[cfg(test)]
mod tests;
