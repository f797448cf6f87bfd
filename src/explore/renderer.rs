//! A view rendered in stages, each shown as it finishes: a quick small
//! frame, then the full size at one sample, then every sample. A new view
//! gives up the stages of the one before it; the last stage's pixels are
//! those `render` writes for the same frame, size and samples.

use super::view::Prepared;
use crate::output::{self, Format};
use crate::render::{render_in_waves, Film, Layers};
use crate::scene::Scene;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};
use std::time::Instant;

/// The time the quick stage aims at: a drag's views follow the pointer.
const QUICK_SECONDS: f64 = 0.05;
/// The quick stage's fewest and most pixels, and its first guess.
const QUICK_PIXELS: (u64, u64, u64) = (64 * 36, 320 * 180, 160 * 90);
/// The most pixels of a playback frame.
const PLAY_PIXELS: u64 = 320 * 180;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stage {
    /// Small, one sample.
    Quick,
    /// Full size, one sample.
    Full,
    /// Full size, every sample: what `render` writes.
    Final,
    /// A playback frame: small, one sample, and not given up for a view.
    Play,
}

/// A finished stage as a PNG.
pub struct Picture {
    pub png: Vec<u8>,
    pub width: u32,
    pub height: u32,
    pub samples: u32,
    pub seconds: f64,
}

/// The renders of one server: which view is current, and its progress.
pub struct Renders {
    generation: AtomicU64,
    pub rows_done: AtomicU32,
    pub rows_total: AtomicU32,
    /// Whose rows those are: 1 the full stage, 2 the final one.
    pub rows_stage: AtomicU32,
    /// Full-size stages begun: each is announced, though it repeat the last.
    pub rows_renders: AtomicU32,
    /// Pixels the next quick stage takes, from the pace of the last ones.
    quick_pixels: AtomicU64,
}

impl Default for Renders {
    fn default() -> Self {
        Renders {
            generation: AtomicU64::new(0),
            rows_done: AtomicU32::new(0),
            rows_total: AtomicU32::new(0),
            rows_stage: AtomicU32::new(0),
            rows_renders: AtomicU32::new(0),
            quick_pixels: AtomicU64::new(QUICK_PIXELS.2),
        }
    }
}

impl Renders {
    /// Makes a new view current, giving up the stages of the one before.
    pub fn begin(&self) -> u64 {
        self.generation.fetch_add(1, Ordering::SeqCst) + 1
    }

    /// Renders `stage` of `view`: none where a newer view gave it up.
    pub fn render(&self, view: &Prepared, stage: Stage, generation: u64) -> Option<Picture> {
        let started = Instant::now();
        let stop = || stage != Stage::Play && self.generation.load(Ordering::SeqCst) != generation;
        let n = view.scenes[0].samples_per_pixel.max(1);
        let (width, height, samples) = match stage {
            Stage::Quick => shrunk(view, self.quick_pixels.load(Ordering::Relaxed)),
            Stage::Play => shrunk(view, PLAY_PIXELS),
            Stage::Full => (view.width, view.height, 1),
            Stage::Final => (view.width, view.height, n),
        };
        let scenes: Vec<Scene> = if samples == n {
            view.scenes.clone()
        } else {
            // One sample, one instant: as `render --preview` takes it.
            let mut first = view.scenes[0].clone();
            first.samples_per_pixel = 1;
            vec![first]
        };
        // The full-size stages take seconds at large sizes: they show progress.
        let counted = matches!(stage, Stage::Full | Stage::Final);
        if counted {
            self.rows_done.store(0, Ordering::Relaxed);
            let waves = crate::render::wave_count(&scenes[0]);
            self.rows_total.store(height * waves, Ordering::Relaxed);
            let whose = if stage == Stage::Full { 1 } else { 2 };
            self.rows_stage.store(whose, Ordering::Relaxed);
            self.rows_renders.fetch_add(1, Ordering::Relaxed);
        }
        let on_row = || {
            if counted {
                self.rows_done.fetch_add(1, Ordering::Relaxed);
            }
        };
        let size = (width, height);
        let film = render_in_waves(&scenes, view.frame, size, Layers::default(), &on_row, &stop)?;
        let seconds = started.elapsed().as_secs_f64();
        if matches!(stage, Stage::Quick | Stage::Full) {
            self.pace((width * height) as f64 / seconds.max(1e-4));
        }
        Some(Picture {
            png: png_bytes(&film, &view.hash, &scenes[0]),
            width,
            height,
            samples,
            seconds,
        })
    }
}

impl Renders {
    /// Sizes the next quick stage from `pixels_per_second` at one sample.
    fn pace(&self, pixels_per_second: f64) {
        let (fewest, most, _) = QUICK_PIXELS;
        let pixels = (pixels_per_second * QUICK_SECONDS) as u64;
        self.quick_pixels
            .store(pixels.clamp(fewest, most), Ordering::Relaxed);
    }
}

/// The view's size scaled down, aspect kept, to at most `pixels`; one sample.
fn shrunk(view: &Prepared, pixels: u64) -> (u32, u32, u32) {
    let area = view.width as u64 * view.height as u64;
    let scale = ((pixels as f64 / area as f64).sqrt()).min(1.0);
    let side = |n: u32| ((n as f64 * scale).round() as u32).max(1);
    (side(view.width), side(view.height), 1)
}

/// `film` as `render` writes it into a PNG file.
fn png_bytes(film: &Film, hash: &str, scene: &Scene) -> Vec<u8> {
    let encoding = output::Encoding {
        display: scene.look.display_transform(),
        transparent: scene.look.transparent_background,
        exr_compression: Default::default(),
    };
    let key = output::frames::stored_key(Format::Png, hash, &[], encoding.exr_compression);
    let mut bytes = Vec::new();
    output::png::encode(&mut bytes, film, &key, output::PngKind::Rgb8, &encoding)
        .expect("a PNG encodes into memory");
    bytes
}

/// How long the whole film would take to render, from a few of its frames
/// rendered small with every sample and effect.
#[derive(Serialize)]
pub struct Estimate {
    pub seconds: f64,
    pub frames_measured: u32,
    pub measured_size: (u32, u32),
    pub measured_samples: u32,
}

/// The frames measured for an estimate, evenly spaced, their most pixels
/// and samples: 0.16 s for zoom.ron on the 2-core AMD EPYC, whatever the view.
const ESTIMATE_FRAMES: u32 = 5;
const ESTIMATE_PIXELS: u64 = 96 * 54;
const ESTIMATE_SAMPLES: u32 = 4;

/// Times a few frames of `timeline` small, at few samples, and scales the
/// time by pixels, samples and frames: each costs about the same anywhere.
pub fn estimate(timeline: &crate::timeline::Timeline, view: &Prepared) -> Estimate {
    let (w, h, _) = shrunk(view, ESTIMATE_PIXELS);
    let n = view.scenes[0].samples_per_pixel.max(1);
    let samples = n.min(ESTIMATE_SAMPLES);
    let sampled = timeline.clone().with_samples(Some(samples));
    let count = timeline.frame_count.min(ESTIMATE_FRAMES);
    let started = Instant::now();
    for i in 0..count {
        let last = (timeline.frame_count - 1) as u64;
        let frame = (i as u64 * last / (count.max(2) - 1) as u64) as u32;
        render_in_waves(
            &sampled.scenes_for_frame(frame),
            frame,
            (w, h),
            Layers::default(),
            &|| {},
            &|| false,
        );
    }
    let per_frame = started.elapsed().as_secs_f64() / count as f64;
    let pixels = (view.width as f64 * view.height as f64) / (w as f64 * h as f64);
    Estimate {
        seconds: per_frame * pixels * (n as f64 / samples as f64) * timeline.frame_count as f64,
        frames_measured: count,
        measured_size: (w, h),
        measured_samples: samples,
    }
}
