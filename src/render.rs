//! Turning a scene into a film: camera rays, the deterministic sampler, bands
//! of four rows of pixels spread over rayon's threads (a band's camera rays,
//! in cones over blocks of pixels, and its shadow rays marched side by side),
//! and per-frame counters.
//!
//! Every pixel depends only on (scene, frame, pixel, sample) and on the
//! pixels its camera rays share a cone with (fixed by the image size and
//! `quality.cone_rays`), never on which thread ran it or in which order, so
//! the image is identical for any thread count.

use crate::march::{normals_many, walk_many, MarchResult};
use crate::math::{finite_or_zero, sample_1d, Real, Vec3};
use crate::scene::Scene;
use crate::shade::{fogged, glow, StageCounts, SurfacePoint};
use rayon::prelude::*;

/// Depth written for pixels that see only background.
pub const BACKGROUND_DEPTH: f32 = 1.0e10;

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
    pub stats: FrameStats,
}

impl Film {
    /// A film of `width`×`height` with the layers asked for, for
    /// `finish_pixels` to fill (see `Film::prepare`).
    fn blank(width: u32, height: u32, layers: Layers) -> Film {
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
    fn prepare(&mut self, width: u32, height: u32, layers: Layers) {
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
        self.stats = FrameStats::default();
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
    fn bytes_per_pixel(self) -> u64 {
        12 * (self.normal as u64 + self.albedo as u64) + 16 * self.traps as u64
    }
}

/// About the most memory rendering and writing one frame of `width`×
/// `height` takes (upwards of it): the film (colour, alpha, depth and
/// estimates, 24 bytes a pixel, and the layers); for an EXR as much again
/// for its blocks, for a PNG its 3 bytes of sRGB codes and a byte of
/// compressed data; and for a frame of several samples per pixel the
/// running sums (colour in f64, hits, depth and estimates spent, 40 bytes a
/// pixel, and the layers). What a size can be checked against before it is
/// rendered.
pub fn frame_bytes(width: u32, height: u32, layers: Layers, exr: bool, many_samples: bool) -> u64 {
    let film = 24 + layers.bytes_per_pixel();
    let encoding = if exr { film } else { 4 };
    let sums = if many_samples {
        40 + layers.bytes_per_pixel()
    } else {
        0
    };
    width as u64 * height as u64 * (film + encoding + sums)
}

/// Work counted while rendering one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct FrameStats {
    /// Orbits computed for distance estimates and membership tests, every
    /// stage together (1 per analytic estimate, 5 per gradient estimate).
    pub de_evaluations: u64,
    /// The same by stage: primary marching, normals, shadow marches, occlusion.
    pub primary_evaluations: u64,
    pub normal_evaluations: u64,
    pub shadow_evaluations: u64,
    pub occlusion_evaluations: u64,
    /// Path tracing: bounce rays (marching and normals) and rays towards the sun.
    pub bounce_evaluations: u64,
    pub sun_evaluations: u64,
    pub samples: u64,
    pub hits: u64,
    /// The most evaluations any one pixel took.
    pub max_pixel_evaluations: u64,
    /// Orbit iterations over every stage: the kernel's unit of work.
    #[serde(default)]
    pub de_iterations: u64,
    /// Samples whose colour came out NaN or infinite and were replaced by
    /// black. Every known cause is guarded upstream, so this should stay 0;
    /// debug builds stop at the first one instead.
    pub repaired_samples: u64,
    /// Camera rays that ran out of `quality.max_steps` (counted as hits,
    /// where they stopped): many mean too few steps for the scene, or a
    /// small fudge.
    #[serde(default)]
    pub out_of_steps: u64,
}

impl FrameStats {
    /// Evaluations over every stage.
    pub fn stage_total(&self) -> u64 {
        self.primary_evaluations
            + self.normal_evaluations
            + self.shadow_evaluations
            + self.occlusion_evaluations
            + self.bounce_evaluations
            + self.sun_evaluations
    }

    /// These counts as a finished frame (or band) reports them: the stage
    /// total and the most any one pixel took.
    fn finished(self, max_pixel_evaluations: u64) -> FrameStats {
        FrameStats {
            de_evaluations: self.stage_total(),
            max_pixel_evaluations,
            ..self
        }
    }
}

impl std::ops::Add for FrameStats {
    type Output = FrameStats;
    fn add(self, o: FrameStats) -> FrameStats {
        FrameStats {
            de_evaluations: self.de_evaluations + o.de_evaluations,
            primary_evaluations: self.primary_evaluations + o.primary_evaluations,
            normal_evaluations: self.normal_evaluations + o.normal_evaluations,
            shadow_evaluations: self.shadow_evaluations + o.shadow_evaluations,
            occlusion_evaluations: self.occlusion_evaluations + o.occlusion_evaluations,
            bounce_evaluations: self.bounce_evaluations + o.bounce_evaluations,
            sun_evaluations: self.sun_evaluations + o.sun_evaluations,
            samples: self.samples + o.samples,
            hits: self.hits + o.hits,
            max_pixel_evaluations: self.max_pixel_evaluations.max(o.max_pixel_evaluations),
            de_iterations: self.de_iterations + o.de_iterations,
            repaired_samples: self.repaired_samples + o.repaired_samples,
            out_of_steps: self.out_of_steps + o.out_of_steps,
        }
    }
}

/// Sub-pixel offset of sample `s` of `n`: the centre for one sample; a
/// jittered point in cell `s` of a k×k grid when n = k²; otherwise stratified
/// in n rows with x uniform, which still covers the whole pixel evenly.
fn subpixel(scene: &Scene, frame: u32, pixel: u64, s: u32, n: u32) -> (Real, Real) {
    if n == 1 {
        return (0.5, 0.5);
    }
    let jx = sample_1d(scene.seed, frame, pixel, s, 0);
    let jy = sample_1d(scene.seed, frame, pixel, s, 1);
    let k = (n as Real).sqrt().round() as u32;
    if k * k == n {
        let (cx, cy) = (s % k, s / k);
        ((cx as Real + jx) / k as Real, (cy as Real + jy) / k as Real)
    } else {
        (jx, (s as Real + jy) / n as Real)
    }
}

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
    let frame = FrameSetup::new(scenes, frame_index, width, height, 0..n, on_row);
    film.prepare(width, height, layers);
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
            let stats = render_band(&frame, band * BAND_ROWS, sums.all_mut());
            let max_pixel = finish_pixels(&sums, n, pixels);
            ROW_SUMS.set(sums);
            stats.finished(max_pixel)
        })
        // `+` keeps the larger per-pixel maximum.
        .reduce(FrameStats::default, |a, b| a + b);
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
    fn reset(&mut self, width: u32, height: u32, layers: Layers) {
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
        self.stats = FrameStats::default();
    }

    /// The layers these sums collect.
    fn layers(&self) -> Layers {
        Layers {
            normal: !self.normal.is_empty(),
            albedo: !self.albedo.is_empty(),
            traps: !self.traps.is_empty(),
        }
    }

    /// All the sums as one run of pixels (for a one-band accumulation, its band).
    fn all_mut(&mut self) -> RowSums<'_> {
        RowSums {
            colour: &mut self.colour,
            hits: &mut self.hits,
            depth: &mut self.depth,
            spent: &mut self.spent,
            normal: (!self.normal.is_empty()).then_some(&mut self.normal[..]),
            albedo: (!self.albedo.is_empty()).then_some(&mut self.albedo[..]),
            traps: (!self.traps.is_empty()).then_some(&mut self.traps[..]),
        }
    }

    /// The sums a band of `BAND_ROWS` rows at a time, for rendering bands
    /// in parallel, each band a task of its own (`with_max_len(1)`; see
    /// `BAND_TASKS`).
    fn bands_mut(&mut self) -> impl IndexedParallelIterator<Item = RowSums<'_>> {
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
            .map(
                |((((((colour, hits), depth), spent), normal), albedo), traps)| RowSums {
                    colour,
                    hits,
                    depth,
                    spent,
                    normal,
                    albedo,
                    traps,
                },
            )
            .with_max_len(BAND_TASKS)
    }

    /// The finished film, with `n` samples per pixel.
    pub fn finish(self, n: u32) -> Film {
        let mut film = Film::blank(self.width, self.height, self.layers());
        let all = FilmPixels {
            colour: &mut film.colour,
            alpha: &mut film.alpha,
            depth: &mut film.depth,
            evaluations: &mut film.evaluations,
            normal: film.normal.as_deref_mut(),
            albedo: film.albedo.as_deref_mut(),
            traps: film.traps.as_deref_mut(),
        };
        let max_pixel = finish_pixels(&self, n, all);
        film.stats = self.stats.finished(max_pixel);
        film
    }
}

/// One band of an accumulation's sums.
struct RowSums<'a> {
    colour: &'a mut [[f64; 3]],
    hits: &'a mut [u32],
    depth: &'a mut [f32],
    spent: &'a mut [u64],
    normal: Option<&'a mut [Vec3]>,
    albedo: Option<&'a mut [Vec3]>,
    traps: Option<&'a mut [[f32; 4]]>,
}

/// Pixels of a film (a band, or all of them).
struct FilmPixels<'a> {
    colour: &'a mut [Vec3],
    alpha: &'a mut [f32],
    depth: &'a mut [f32],
    evaluations: &'a mut [u32],
    normal: Option<&'a mut [Vec3]>,
    albedo: Option<&'a mut [Vec3]>,
    traps: Option<&'a mut [[f32; 4]]>,
}

impl Film {
    /// The film a band of `BAND_ROWS` rows at a time, for finishing bands
    /// in parallel, each band a task of its own (see `BAND_TASKS`).
    fn bands_mut(&mut self) -> impl IndexedParallelIterator<Item = FilmPixels<'_>> {
        let (w, h) = (self.width as usize, self.height as usize);
        let band = BAND_ROWS * w;
        let normal = self.normal.as_deref_mut().unwrap_or_default();
        let albedo = self.albedo.as_deref_mut().unwrap_or_default();
        let traps = self.traps.as_deref_mut().unwrap_or_default();
        self.colour
            .par_chunks_mut(band)
            .zip(self.alpha.par_chunks_mut(band))
            .zip(self.depth.par_chunks_mut(band))
            .zip(self.evaluations.par_chunks_mut(band))
            .zip(optional_bands(normal, w, h))
            .zip(optional_bands(albedo, w, h))
            .zip(optional_bands(traps, w, h))
            .map(
                |((((((colour, alpha), depth), evaluations), normal), albedo), traps)| FilmPixels {
                    colour,
                    alpha,
                    depth,
                    evaluations,
                    normal,
                    albedo,
                    traps,
                },
            )
            .with_max_len(BAND_TASKS)
    }
}

/// Averages the sums of `sums` (all its pixels) over `n` samples into
/// `out`, pixel for pixel; returns the most estimates one pixel took.
fn finish_pixels(sums: &Accumulation, n: u32, out: FilmPixels) -> u64 {
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
            && layer(out.traps.as_ref().map(|v| v.len()), sums.traps.len()),
        "a band's film and sums differ in size"
    );
    let inv = 1.0 / n as f64;
    for (c, s) in out.colour.iter_mut().zip(&sums.colour) {
        *c = Vec3::new(
            (s[0] * inv) as f32,
            (s[1] * inv) as f32,
            (s[2] * inv) as f32,
        );
    }
    for (a, &h) in out.alpha.iter_mut().zip(&sums.hits) {
        *a = h as f32 / n as f32;
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
    if let Some(traps) = out.traps {
        for (i, (o, v)) in traps.iter_mut().zip(&sums.traps).enumerate() {
            *o = v.map(|x| x * per_hit(i));
        }
    }
    sums.spent.iter().copied().max().unwrap_or(0)
}

/// Adds samples `acc.samples_done .. until` of every pixel to `acc`.
pub fn render_samples(
    scenes: &[Scene],
    frame_index: u32,
    acc: &mut Accumulation,
    until: u32,
    on_row: &(dyn Fn() + Sync),
) {
    let samples = acc.samples_done..until;
    let frame = FrameSetup::new(scenes, frame_index, acc.width, acc.height, samples, on_row);
    // One band of rows per task; rayon spreads bands over threads and each
    // pixel depends only on its own samples and its band, so the result is
    // independent of the split.
    let stats = acc
        .bands_mut()
        .enumerate()
        .map(|(band, sums)| render_band(&frame, band * BAND_ROWS, sums))
        .reduce(FrameStats::default, |a, b| a + b);
    acc.stats = acc.stats + stats;
    acc.samples_done = until;
}

/// What every band of one frame's rendering shares, worked out once.
struct FrameSetup<'a> {
    scenes: &'a [Scene],
    frame_index: u32,
    width: u32,
    height: u32,
    /// Samples per pixel, and the ones to take now.
    n: u32,
    samples: std::ops::Range<u32>,
    cameras: Vec<crate::camera::CameraFrame>,
    /// Fog is measured in camera–target distances, so zooms keep their haze.
    scales: Vec<Real>,
    /// An environment map is looked up once per frame, not per ray.
    environment: Option<std::sync::Arc<crate::environment::EnvironmentMap>>,
    on_row: &'a (dyn Fn() + Sync),
}

impl<'a> FrameSetup<'a> {
    fn new(
        scenes: &'a [Scene],
        frame_index: u32,
        width: u32,
        height: u32,
        samples: std::ops::Range<u32>,
        on_row: &'a (dyn Fn() + Sync),
    ) -> Self {
        FrameSetup {
            scenes,
            frame_index,
            width,
            height,
            n: scenes[0].samples_per_pixel.max(1),
            samples,
            cameras: scenes.iter().map(|s| s.camera.frame()).collect(),
            scales: scenes
                .iter()
                .map(|s| (s.camera.position - s.camera.target).length())
                .collect(),
            environment: scenes[0]
                .effects
                .path_tracing
                .as_ref()
                .and_then(|pt| pt.sky.environment()),
            on_row,
        }
    }
}

/// The image rows rendered together: the rows a block of cone rays can
/// span (`march::CONE_BLOCK_ROWS`).
const BAND_ROWS: usize = crate::march::CONE_BLOCK_ROWS;

/// Bands in one rayon task at most: one. Left to itself, rayon cuts an
/// indexed loop into a few runs of bands and a thread works through its run
/// in order, so a thread that runs out of work can take nothing from a
/// run another thread has begun, and a frame whose costly bands bunch
/// together ends on one thread.
const BAND_TASKS: usize = 1;

/// Adds `frame.samples` of every pixel of the band of image rows from `y0`
/// (as many as `sums` holds) to `sums`.
fn render_band(frame: &FrameSetup, y0: usize, sums: RowSums) -> FrameStats {
    let FrameSetup {
        scenes,
        frame_index,
        width,
        height,
        n,
        ..
    } = *frame;
    let w = width as usize;
    let rows = sums.colour.len() / w.max(1);
    let RowSums {
        colour: colour_row,
        hits: hits_row,
        depth: depth_row,
        spent: spent_row,
        normal: mut normal_row,
        albedo: mut albedo_row,
        traps: mut traps_row,
    } = sums;
    let mut stats = FrameStats::default();
    // A band runs start to end on one thread, so this thread's
    // count of orbit iterations measures exactly the band's.
    let iterations_before = crate::fractal::iterations_on_this_thread();
    // Each sample index at a time over the whole band, so the
    // band's camera rays march side by side, a block of pixels to a cone
    // (`march_camera_rays`); each
    // pixel still takes its samples in order.
    // This thread's buffers, kept from band to band: allocating
    // and freeing them per band made the allocator hand pages
    // back and fault them in again, flushing the other cores' TLBs.
    let mut scratch = ROW_SCRATCH.take();
    let RowScratch {
        laid_out,
        order,
        runs,
        rays,
        marched,
        surfaces,
        walks,
        shadows,
        occluded,
        cone_free,
        paths,
    } = &mut scratch;
    marched.resize(rows * w, MarchResult::default());
    for s in frame.samples.clone() {
        let k = s as usize % scenes.len();
        let (scene, camera, scale) = (&scenes[k], &frame.cameras[k], frame.scales[k]);
        // The band's pixels block by block (`cone_blocks`): ray i is the
        // pixel `order[i]` of the band. Laid out again only when the shape
        // changes (a thread's bands and samples mostly share one).
        let layout = (w, rows, crate::march::cone_block(scene.cone_rays()));
        if *laid_out != Some(layout) {
            crate::march::cone_blocks(w, rows, layout.2, order, runs);
            *laid_out = Some(layout);
        }
        rays.clear();
        rays.extend(order.iter().map(|&p| {
            let (x, y) = (p % w, y0 + p / w);
            let pixel = (y0 * w + p) as u64;
            let (ox, oy) = subpixel(scene, frame_index, pixel, s, n);
            if camera.has_lens() {
                let u = sample_1d(scene.seed, frame_index, pixel, s, 2);
                let v = sample_1d(scene.seed, frame_index, pixel, s, 3);
                camera.lens_ray(x as Real + ox, y as Real + oy, width, height, u, v)
            } else {
                camera.ray(x as Real + ox, y as Real + oy, width, height)
            }
        }));
        let (f, q) = (&scene.fractal, &scene.quality);
        crate::march::march_camera_rays(rays, f, q, runs, marched, cone_free);
        // Where each ray met the surface, with its normal (the band's hits
        // four to a kernel call); each pixel's cost goes straight to its sum.
        surfaces.clear();
        surfaces.resize(rays.len(), None);
        let hits = rays
            .iter()
            .zip(marched.iter())
            .enumerate()
            .filter_map(|(x, (ray, result))| Some((x, ray, result.hit.as_ref()?)));
        normals_many(
            hits,
            &scene.fractal,
            &scene.quality,
            |i, ray, hit, (nrm, evals)| {
                stats.normal_evaluations += evals as u64;
                spent_row[order[i]] += evals as u64;
                surfaces[i] = Some(SurfacePoint::from_hit(ray, hit, nrm));
            },
        );
        // The band's shadow rays, walked side by side. Shading takes their
        // outcomes back in the same order, pixel after pixel.
        shadows.clear();
        if scene.effects.path_tracing.is_none() && scene.effects.shadows.is_some() {
            walks.clear();
            for at in surfaces.iter().flatten() {
                walks.extend(scene.look.shadow_walks(&scene.effects, &scene.quality, at));
            }
            shadows.resize(walks.len(), (1.0, 0));
            walk_many(walks.drain(..), &scene.fractal, &scene.quality, |i, out| {
                shadows[i] = out
            });
        }
        let mut outcomes = shadows.iter().copied();
        // The band's ambient occlusion, its samples packed across the hits
        // (left empty when it is off, or replaced by path tracing).
        occluded.clear();
        if let (None, Some(ao)) = (
            &scene.effects.path_tracing,
            &scene.effects.ambient_occlusion,
        ) {
            occluded.resize(rays.len(), None);
            let hits = surfaces.iter().enumerate().filter_map(|(x, at)| {
                let at = at.as_ref()?;
                Some((x, at.point, at.normal, at.t, at.footprint))
            });
            crate::shade::occlusions(&scene.fractal, ao, hits, |x, out| occluded[x] = Some(out));
        }
        // The band's path-traced samples, a bounce at a time side by side.
        let traced = match &scene.effects.path_tracing {
            Some(pt) => {
                let random = |i: usize, d: u32| {
                    sample_1d(scene.seed, frame_index, (y0 * w + order[i]) as u64, s, d)
                };
                crate::shade::trace_paths(
                    &scene.look,
                    pt,
                    &scene.fractal,
                    &scene.quality,
                    surfaces,
                    camera.up,
                    frame.environment.as_deref(),
                    &random,
                    paths,
                );
                &paths.out[..]
            }
            None => &[][..],
        };
        for (i, ((ray, result), at)) in rays
            .iter()
            .zip(marched.iter())
            .zip(surfaces.iter())
            .enumerate()
        {
            // The pixel's offset in the band; its camera ray's cost first.
            let p = order[i];
            stats.primary_evaluations += result.evaluations as u64;
            stats.out_of_steps += result.out_of_steps as u64;
            spent_row[p] += result.evaluations as u64;
            let before = stats.stage_total();
            let c = trace(
                scene,
                ray,
                result,
                at.as_ref(),
                &mut outcomes,
                occluded.get(i).copied().flatten(),
                traced.get(i).copied(),
                camera.up,
                scale,
                frame.environment.as_deref(),
                &mut stats,
            );
            if let Some(&SurfacePoint {
                t,
                normal: nrm,
                traps,
                ..
            }) = at.as_ref()
            {
                hits_row[p] += 1;
                stats.hits += 1;
                depth_row[p] = depth_row[p].min(t as f32);
                if let Some(row) = normal_row.as_deref_mut() {
                    row[p] += nrm.as_vec3();
                }
                // Only a requested albedo layer pays for the albedo.
                if let Some(row) = albedo_row.as_deref_mut() {
                    row[p] += scene.look.albedo(&traps);
                }
                if let Some(row) = traps_row.as_deref_mut() {
                    let v = [
                        traps.origin as f32,
                        traps.planes.x as f32,
                        traps.planes.y as f32,
                        traps.planes.z as f32,
                    ];
                    for k in 0..4 {
                        row[p][k] += v[k];
                    }
                }
            }
            debug_assert!(
                c.is_finite(),
                "non-finite sample at pixel ({}, {})",
                p % w,
                y0 + p / w
            );
            if !c.is_finite() {
                stats.repaired_samples += 1;
            }
            let c = finite_or_zero(c);
            colour_row[p][0] += c.x as f64;
            colour_row[p][1] += c.y as f64;
            colour_row[p][2] += c.z as f64;
            stats.samples += 1;
            spent_row[p] += stats.stage_total() - before;
        }
        debug_assert!(outcomes.next().is_none(), "a shadow outcome per ray walked");
    }
    ROW_SCRATCH.set(scratch);
    stats.de_iterations += crate::fractal::iterations_on_this_thread() - iterations_before;
    for _ in 0..rows {
        (frame.on_row)();
    }
    stats
}

/// A band's working buffers (see `render_band`).
#[derive(Default)]
struct RowScratch {
    /// Each camera ray's pixel in the band, and the blocks' sizes
    /// (`cone_blocks`), for the width, rows and block shape they were laid
    /// out for.
    laid_out: Option<(usize, usize, (usize, usize))>,
    order: Vec<usize>,
    runs: Vec<u32>,
    rays: Vec<crate::march::Ray>,
    marched: Vec<MarchResult>,
    /// Where each camera ray met the surface.
    surfaces: Vec<Option<SurfacePoint>>,
    walks: Vec<Result<crate::shade::ShadowWalk, (f32, u64)>>,
    shadows: Vec<(f32, u64)>,
    /// Each pixel's ambient occlusion and its cost, where it hit.
    occluded: Vec<Option<(f32, u64)>>,
    /// Each camera ray's bounding-sphere interval; where each run of them
    /// may start, and what its cone cost.
    cone_free: crate::march::ConeScratch,
    /// The band's path-traced samples, traced together.
    paths: crate::shade::PathScratch,
}

thread_local! {
    static ROW_SCRATCH: std::cell::Cell<RowScratch> = std::cell::Cell::default();
    /// One band's sums for `render_frame_into`, kept like `ROW_SCRATCH`.
    static ROW_SUMS: std::cell::Cell<Accumulation> = std::cell::Cell::default();
}

/// Bands of `BAND_ROWS` rows of an optional layer for the parallel zip:
/// `Some(band)` per band when the layer is collected, `None` for each band
/// otherwise.
fn optional_bands<T: Send>(
    layer: &mut [T],
    width: usize,
    height: usize,
) -> impl IndexedParallelIterator<Item = Option<&mut [T]>> {
    let rows: Vec<Option<&mut [T]>> = if layer.is_empty() {
        (0..height.div_ceil(BAND_ROWS)).map(|_| None).collect()
    } else {
        layer.chunks_mut(BAND_ROWS * width).map(Some).collect()
    };
    rows.into_par_iter()
}

/// The radiance of one camera sample, which met the surface at `at` or
/// nothing. Shadow rays' outcomes come from `shadows` and its ambient
/// occlusion from `occluded` (see `Look::shade_with`); a path-traced sample's light and counts from
/// `traced` (see `trace_paths`). Only the stages of the scene's enabled
/// effects run; `stats` counts each.
#[allow(clippy::too_many_arguments)]
fn trace(
    scene: &Scene,
    ray: &crate::march::Ray,
    result: &MarchResult,
    at: Option<&SurfacePoint>,
    shadows: &mut dyn Iterator<Item = (f32, u64)>,
    occluded: Option<(f32, u64)>,
    traced: Option<(Vec3, StageCounts)>,
    up: crate::math::DVec3,
    scale: Real,
    environment: Option<&crate::environment::EnvironmentMap>,
    stats: &mut FrameStats,
) -> Vec3 {
    let Some(at) = at else {
        let sky = match &scene.effects.path_tracing {
            Some(pt) => pt.sky.radiance(&scene.look, ray.dir, up, environment) * pt.sky_intensity,
            None => scene.look.background(ray.dir, up),
        };
        let colour = match &scene.effects.glow {
            Some(g) => sky + glow(g, result.closest),
            None => sky,
        };
        return colour;
    };
    let mut stages = StageCounts::default();
    let lit = match traced {
        Some((radiance, counts)) => {
            stages = counts;
            radiance
        }
        None => scene
            .look
            .shade_with(&scene.effects, at, &mut stages, shadows, occluded),
    };
    stats.shadow_evaluations += stages.shadows;
    stats.occlusion_evaluations += stages.occlusion;
    stats.bounce_evaluations += stages.bounces;
    stats.sun_evaluations += stages.sun_rays;
    match &scene.effects.fog {
        Some(fog) => fogged(lit, fog, at.t, scale),
        None => lit,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subpixel_offsets_stay_in_the_pixel_and_cover_it() {
        let scene = Scene::default();
        assert_eq!(subpixel(&scene, 0, 0, 0, 1), (0.5, 0.5));
        let pts: Vec<_> = (0..4).map(|s| subpixel(&scene, 0, 9, s, 4)).collect();
        for &(x, y) in &pts {
            assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
        }
        // Three samples: one in each horizontal third, averaging over the whole pixel.
        let thirds: std::collections::HashSet<_> = (0..3)
            .map(|s| (subpixel(&scene, 0, 9, s, 3).1 * 3.0) as u8)
            .collect();
        assert_eq!(thirds.len(), 3);
        // Four samples: one in each quadrant of a 2×2 grid.
        let quadrants: std::collections::HashSet<_> = pts
            .iter()
            .map(|&(x, y)| ((x * 2.0) as u8, (y * 2.0) as u8))
            .collect();
        assert_eq!(quadrants.len(), 4);
    }

    #[test]
    fn a_reused_film_renders_each_frame_as_a_new_one_would() {
        // The film first holds another view at another size with every
        // layer, then values no frame gives, so anything left would show.
        let mut other = Scene::default();
        other.camera.position = crate::math::DVec3::new(0.4, -1.9, 1.2);
        let scene = Scene::default();
        let every = Layers {
            normal: true,
            albedo: true,
            traps: true,
        };
        let mut film = Film::default();
        render_frame_into(&mut film, &[other], 0, 44, 33, every, &|| {});
        let normal_only = Layers {
            normal: true,
            ..Layers::default()
        };
        // Every layer follows a frame that had it too, so each is reused.
        for (w, h, layers) in [
            (32, 24, Layers::default()),
            (40, 30, every),
            (24, 16, every),
            (48, 20, normal_only),
            (16, 12, every),
            (16, 12, every),
        ] {
            // Values no frame could give, in every element the film holds,
            // so a pixel finishing missed would show whatever it missed.
            film.colour.fill(Vec3::splat(-7.0));
            film.alpha.fill(-7.0);
            film.depth.fill(-7.0);
            film.evaluations.fill(7_777_777);
            for layer in [&mut film.normal, &mut film.albedo].into_iter().flatten() {
                layer.fill(Vec3::splat(-7.0));
            }
            if let Some(traps) = &mut film.traps {
                traps.fill([-7.0; 4]);
            }
            render_frame_into(
                &mut film,
                std::slice::from_ref(&scene),
                0,
                w,
                h,
                layers,
                &|| {},
            );
            let mut new = Film::default();
            let one = std::slice::from_ref(&scene);
            render_frame_into(&mut new, one, 0, w, h, layers, &|| {});
            assert!(film == new, "{w}x{h} {layers:?}");
            assert_eq!(film.colour.len(), (w * h) as usize);
            assert_eq!(film.normal.is_some(), layers.normal);
        }
    }

    #[test]
    fn default_scene_shows_the_bulb_in_the_middle_and_background_in_corners() {
        let scene = Scene::default();
        let film = render_frame(&scene, 0, 32, 24, &|| {});
        let at = |x: u32, y: u32| (y * 32 + x) as usize;
        assert_eq!(film.alpha[at(16, 12)], 1.0);
        assert!(film.depth[at(16, 12)] < 3.0);
        assert_eq!(film.alpha[at(0, 0)], 0.0);
        assert_eq!(film.depth[at(0, 0)], BACKGROUND_DEPTH);
        assert!(film.colour.iter().all(|c| c.is_finite()));
        assert!(film.stats.de_evaluations > film.stats.samples);
        // Per-pixel counts add up to the frame's, and the bulb costs more than the sky.
        let per_pixel: u64 = film.evaluations.iter().map(|&e| e as u64).sum();
        assert_eq!(per_pixel, film.stats.de_evaluations);
        assert_eq!(
            film.stats.max_pixel_evaluations,
            *film.evaluations.iter().max().unwrap() as u64
        );
        assert!(film.evaluations[at(16, 12)] > film.evaluations[at(0, 0)]);
        assert_eq!(film.stats.samples, 32 * 24);
    }

    #[test]
    fn each_effect_alone_moves_only_its_stage_and_changes_the_image() {
        use crate::shade::{AmbientOcclusion, Effects, Fog, Glow, PathTracing, Shadows, Specular};
        let plain_scene = Scene::default();
        let plain = render_frame(&plain_scene, 0, 40, 30, &|| {});
        let counters = |s: &FrameStats| {
            [
                s.primary_evaluations,
                s.normal_evaluations,
                s.shadow_evaluations,
                s.occlusion_evaluations,
                s.bounce_evaluations,
                s.sun_evaluations,
            ]
        };
        // With every effect off nothing but marching and normals runs.
        let p = counters(&plain.stats);
        assert!(p[0] > 0 && p[1] > 0);
        assert_eq!((p[2], p[3], p[4], p[5]), (0, 0, 0, 0));
        assert_eq!(plain.stats.de_evaluations, p.iter().sum::<u64>());
        let cases: [(&str, Effects, [bool; 6]); 6] = [
            (
                "shadows",
                Effects {
                    shadows: Some(Shadows::default()),
                    ..Effects::default()
                },
                [false, false, true, false, false, false],
            ),
            (
                "ambient_occlusion",
                Effects {
                    ambient_occlusion: Some(AmbientOcclusion::default()),
                    ..Effects::default()
                },
                [false, false, false, true, false, false],
            ),
            (
                "specular",
                Effects {
                    specular: Some(Specular::default()),
                    ..Effects::default()
                },
                [false; 6],
            ),
            (
                "fog",
                Effects {
                    fog: Some(Fog::default()),
                    ..Effects::default()
                },
                [false; 6],
            ),
            (
                "glow",
                Effects {
                    glow: Some(Glow::default()),
                    ..Effects::default()
                },
                [false; 6],
            ),
            (
                "path_tracing",
                Effects {
                    path_tracing: Some(PathTracing::default()),
                    ..Effects::default()
                },
                [false, false, false, false, true, true],
            ),
        ];
        // Glow needs each camera ray's own nearest approach, so its rays march
        // alone, without cones: against the plain frame marched that way.
        let mut alone_scene = Scene::default();
        alone_scene.quality.cone_rays = 1;
        let alone_film = render_frame(&alone_scene, 0, 40, 30, &|| {});
        let alone = counters(&alone_film.stats);
        assert!(
            alone[0] > p[0],
            "cones save primary estimates: {alone:?} {p:?}"
        );
        for (name, effects, moves) in cases {
            let (p, plain) = match effects.glow {
                Some(_) => (alone, &alone_film),
                None => (p, &plain),
            };
            let scene = Scene {
                effects,
                ..Scene::default()
            };
            let film = render_frame(&scene, 0, 40, 30, &|| {});
            let c = counters(&film.stats);
            for k in 0..6 {
                if moves[k] {
                    assert!(c[k] > p[k], "{name}: stage {k} should run");
                } else {
                    assert_eq!(c[k], p[k], "{name}: stage {k} should not change");
                }
            }
            assert_eq!(film.stats.de_evaluations, c.iter().sum::<u64>());
            assert!(
                film.colour != plain.colour,
                "{name} changed nothing in the image"
            );
            assert!(film.colour.iter().all(|v| v.is_finite()));
        }
    }

    #[test]
    fn depth_of_field_blurs_only_when_the_lens_is_open() {
        let sharp = Scene {
            samples_per_pixel: 4,
            ..Scene::default()
        };
        let mut blurred = sharp.clone();
        blurred.camera.aperture_radius = 0.15;
        blurred.camera.focus_distance = Some(1.0); // well in front of the bulb
        let a = render_frame(&sharp, 0, 32, 24, &|| {});
        let b = render_frame(&blurred, 0, 32, 24, &|| {});
        assert!(a.colour != b.colour);
        assert!(b.colour.iter().all(|c| c.is_finite()));
        // A zero aperture is the pinhole exactly, whatever the focus.
        let mut closed = sharp.clone();
        closed.camera.focus_distance = Some(1.0);
        assert!(render_frame(&closed, 0, 32, 24, &|| {}).colour == a.colour);
        // The lens costs marching only through its extra rays' paths: same sample count.
        assert_eq!(a.stats.samples, b.stats.samples);
    }

    #[test]
    fn cones_in_blocks_find_the_pixels_rays_alone_find() {
        // A width that blocks of 4 do not divide and a last band of two
        // rows (54 = 4·13 + 2): each pixel's hit and depth, with its rays marched in 4×4
        // cones, against every ray alone. A pixel's sums taken from
        // another pixel's ray would move the silhouette. At hit thresholds
        // past one footprint too, where a ray alone stops that much sooner:
        // cones that went on to a footprint missed the rays' hits (at 20,
        // 1135 of 5184 pixels disagreed at 96×54) and set the depth tens of
        // footprints too deep; a depth is then as good as the threshold.
        let (w, h) = (97, 54);
        for (threshold, within, share) in [(0.5, 2.0, 95), (5.0, 5.0, 90), (20.0, 20.0, 90)] {
            let mut blocks = Scene::default();
            blocks.quality.hit_threshold = threshold;
            let mut alone = blocks.clone();
            alone.quality.cone_rays = 1;
            assert_eq!(crate::march::cone_block(blocks.cone_rays()), (4, 4));
            let (a, b) = (
                render_frame(&alone, 0, w, h, &|| {}),
                render_frame(&blocks, 0, w, h, &|| {}),
            );
            let pixel_angle = (blocks.camera.fov_degrees.to_radians() / h as Real) as f32;
            let (mut hits, mut agree, mut near) = (0, 0, 0);
            for i in 0..(w * h) as usize {
                agree += (a.alpha[i] == b.alpha[i]) as usize;
                if a.alpha[i] > 0.0 && b.alpha[i] > 0.0 {
                    hits += 1;
                    let footprint = a.depth[i] * pixel_angle;
                    near += ((a.depth[i] - b.depth[i]).abs() <= within * footprint) as usize;
                }
            }
            let n = (w * h) as usize;
            assert!(hits > n / 4, "{threshold}: {hits} hits of {n}");
            assert!(
                agree * 100 >= n * 98,
                "{threshold}: {agree} of {n} agree on hit or miss"
            );
            assert!(
                near * 100 >= hits * share,
                "{threshold}: {near} of {hits} hits within {within} footprints"
            );
            if threshold < 1.0 {
                assert!(b.stats.primary_evaluations < a.stats.primary_evaluations);
            }
        }
    }

    #[test]
    fn a_frame_rendered_in_waves_equals_one_rendered_at_once() {
        let scene = Scene {
            samples_per_pixel: 6,
            effects: crate::shade::Effects {
                path_tracing: Some(Default::default()),
                ..Default::default()
            },
            ..Scene::default()
        };
        let layers = Layers {
            normal: true,
            albedo: true,
            traps: true,
        };
        let scenes = std::slice::from_ref(&scene);
        // Enough rows that every thread takes several.
        let (w, h) = (12, 130);
        let mut at_once = Film::default();
        render_frame_into(&mut at_once, scenes, 3, w, h, layers, &|| {});
        let mut acc = Accumulation::new(w, h, layers);
        for until in [1, 2, 5, 6] {
            render_samples(scenes, 3, &mut acc, until, &|| {});
        }
        let waves = acc.finish(6);
        assert!(waves.colour == at_once.colour && waves.depth == at_once.depth);
        assert!(waves.normal == at_once.normal && waves.traps == at_once.traps);
        assert_eq!(waves.stats, at_once.stats);
        assert!(waves.albedo == at_once.albedo && waves.alpha == at_once.alpha);
        assert_eq!(waves.evaluations, at_once.evaluations);
        assert_eq!(at_once.colour.len(), (w * h) as usize);
    }
}
