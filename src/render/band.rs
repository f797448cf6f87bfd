//! Bands of rows rendered on rayon's threads: a band's camera rays in
//! cones, its shadow, occlusion and path rays side by side, and the
//! radiance of each sample.

use super::accumulation::{Accumulation, RowSums};
use super::sampler;
use super::stats::FrameStats;
use crate::march::{normals_many, MarchResult};
use crate::math::{finite_or_zero, Real, Vec3};
use crate::scene::Scene;
use crate::shade::{fogged, glow, StageCounts, SurfacePoint};

/// What every band of one frame's rendering shares, worked out once.
pub(super) struct FrameSetup<'a> {
    /// As they render: a deep frame's measured from its anchor (`deep`).
    pub(super) scenes: std::borrow::Cow<'a, [Scene]>,
    pub(super) frame_index: u32,
    pub(super) width: u32,
    pub(super) height: u32,
    /// Samples per pixel, and the ones to take now.
    pub(super) n: u32,
    pub(super) samples: std::ops::Range<u32>,
    pub(super) cameras: Vec<crate::camera::CameraFrame>,
    /// Fog is measured in camera–target distances, so zooms keep their haze.
    pub(super) scales: Vec<Real>,
    /// Each instant's palette table (`shade::palette_table`).
    pub(super) palettes: Vec<Option<crate::shade::PaletteTable>>,
    /// An environment map is looked up once per frame, not per ray.
    pub(super) environment: Option<std::sync::Arc<crate::environment::EnvironmentMap>>,
    /// Under adaptive sampling, the pixels (of the whole frame) that take
    /// these samples; every pixel when `None`.
    pub(super) active: Option<&'a [bool]>,
    /// How samples will be displayed, for adaptive sampling's error.
    pub(super) display: crate::color::Display,
    /// The projection leaves part of the image out (beyond a fisheye's
    /// circle): samples there are transparent black, and counted apart.
    pub(super) partial: bool,
    pub(super) on_row: &'a (dyn Fn() + Sync),
}

impl<'a> FrameSetup<'a> {
    pub(super) fn new(
        scenes: &'a [Scene],
        frame_index: u32,
        width: u32,
        height: u32,
        samples: std::ops::Range<u32>,
        on_row: &'a (dyn Fn() + Sync),
    ) -> Self {
        let scenes = match crate::deep::prepare_all(scenes, [width, height]) {
            Some(deep) => std::borrow::Cow::Owned(deep),
            None => std::borrow::Cow::Borrowed(scenes),
        };
        let cameras: Vec<_> = scenes.iter().map(|s| s.camera.frame()).collect();
        FrameSetup {
            partial: !cameras.iter().all(|c| c.covers_all()),
            frame_index,
            width,
            height,
            n: scenes[0].samples_per_pixel.max(1),
            samples,
            cameras,
            scales: scenes
                .iter()
                .map(|s| crate::math::length(s.camera.position - s.camera.target))
                .collect(),
            palettes: scenes
                .iter()
                .map(|s| crate::shade::palette_table(&s.look, &s.fractal))
                .collect(),
            environment: scenes[0]
                .effects
                .path_tracing
                .as_ref()
                .and_then(|pt| pt.sky.environment()),
            active: None,
            display: scenes[0].look.display_transform(),
            scenes,
            on_row,
        }
    }
}

/// Adds `frame.samples` of every pixel of the band of image rows from `y0`
/// (as many as `sums` holds) to `sums`.
pub(super) fn render_band(frame: &FrameSetup, y0: usize, mut sums: RowSums) -> FrameStats {
    let scenes = &*frame.scenes;
    let w = frame.width as usize;
    let rows = sums.colour.len() / w.max(1);
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
    scratch.picked_valid = false; // another band's pixels
    scratch.marched.resize(rows * w, MarchResult::default());
    for s in frame.samples.clone() {
        let k = sampler::instant(&scenes[0], s, scenes.len());
        let (scene, camera, scale) = (&scenes[k], &frame.cameras[k], frame.scales[k]);
        scratch.camera_rays(frame, scene, camera, y0, rows, s);
        let RowScratch {
            picked: order,
            picked_runs: runs,
            rays,
            seen,
            marched,
            surfaces,
            walks,
            shadows,
            bundles,
            occluded,
            cone_free,
            paths,
            ..
        } = &mut scratch;
        let (f, q) = (&scene.fractal, &scene.quality);
        let marched = &mut marched[..rays.len()];
        crate::march::march_camera_rays(rays, f, q, runs, marched, cone_free);
        // Where each ray met the surface, with its normal (the band's hits
        // four to a kernel call); each pixel's cost goes straight to its sum.
        // A sample beyond the picture (`seen`) meets nothing.
        surfaces.clear();
        surfaces.resize(rays.len(), None);
        let in_picture = |i: usize| seen.get(i).is_none_or(|&s| s);
        let hits = rays
            .iter()
            .zip(marched.iter())
            .enumerate()
            .filter(|&(i, _)| in_picture(i))
            .filter_map(|(x, (ray, result))| Some((x, ray, result.hit.as_ref()?)));
        normals_many(
            hits,
            &scene.fractal,
            &scene.quality,
            |i, ray, hit, (nrm, evals)| {
                stats.normal_evaluations += evals as u64;
                sums.spent[order[i]] += evals as u64;
                let at = SurfacePoint::from_hit(ray, hit, nrm);
                let palette = frame.palettes[k].as_ref();
                surfaces[i] = Some(at.coloured(palette, &scene.fractal, &hit.estimate));
            },
        );
        band_shadows(scene, surfaces, runs, walks, shadows, bundles);
        let mut outcomes = shadows.iter().copied();
        band_occlusion(scene, surfaces, occluded);
        let traced = band_paths(frame, k, y0, s, order, surfaces, paths);
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
            sums.spent[p] += result.evaluations as u64;
            let before = stats.stage_total();
            if !in_picture(i) {
                // Transparent black: no light, and not within the picture.
                add_black(&mut sums, p, &frame.display);
                stats.samples += 1;
                continue;
            }
            if let Some(inside) = sums.inside.as_deref_mut() {
                inside[p] += 1;
            }
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
            if let Some(at) = at.as_ref() {
                sums.add_hit(p, scene, at);
                stats.hits += 1;
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
            if let Some(spread) = sums.spread.as_deref_mut() {
                let closest = if at.is_some() {
                    Real::INFINITY
                } else {
                    result.closest
                };
                spread[p].add(c, &frame.display, closest);
            }
            sums.colour[p][0] += c.x as f64;
            sums.colour[p][1] += c.y as f64;
            sums.colour[p][2] += c.z as f64;
            stats.samples += 1;
            sums.spent[p] += stats.stage_total() - before;
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

/// Adds a sample beyond the picture to pixel `p`: no colour, and to an
/// adaptive pixel's spread as black.
fn add_black(sums: &mut RowSums, p: usize, display: &crate::color::Display) {
    if let Some(spread) = sums.spread.as_deref_mut() {
        spread[p].add(Vec3::ZERO, display, Real::INFINITY);
    }
}

impl RowSums<'_> {
    /// Adds a sample's hit at `at` to pixel `p`'s hit count, depth and the
    /// layers collected.
    pub(super) fn add_hit(&mut self, p: usize, scene: &Scene, at: &SurfacePoint) {
        let &SurfacePoint {
            t,
            normal: nrm,
            traps,
            palette_colour,
            ..
        } = at;
        self.hits[p] += 1;
        self.depth[p] = self.depth[p].min(t as f32);
        if let Some(row) = self.normal.as_deref_mut() {
            row[p] += nrm.as_vec3();
        }
        // Only a requested albedo layer pays for the albedo.
        if let Some(row) = self.albedo.as_deref_mut() {
            row[p] += scene.look.albedo(&traps, palette_colour);
        }
        if let Some(row) = self.traps.as_deref_mut() {
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
}

impl RowScratch {
    /// The band's camera rays for sample `s`, block by block
    /// (`cone_blocks`): ray i is the pixel `order[i]` of the band. Laid out
    /// again only when the shape changes (a thread's bands and samples
    /// mostly share one).
    pub(super) fn camera_rays(
        &mut self,
        frame: &FrameSetup,
        scene: &Scene,
        camera: &crate::camera::CameraFrame,
        y0: usize,
        rows: usize,
        s: u32,
    ) {
        let (width, height, n) = (frame.width, frame.height, frame.n);
        let w = width as usize;
        let layout = (w, rows, crate::march::cone_block(scene.cone_rays()));
        if self.laid_out != Some(layout) {
            crate::march::cone_blocks(w, rows, layout.2, &mut self.order, &mut self.runs);
            self.laid_out = Some(layout);
            self.picked_valid = false;
        }
        // The same pixels take every sample of a wave; those the
        // projection leaves wholly out (beyond a fisheye's circle) take none.
        if !self.picked_valid {
            let active = frame.active.map(|a| &a[y0 * w..(y0 + rows) * w]);
            let seen = |p: usize| {
                let (x, y) = ((p % w) as u32, (y0 + p / w) as u32);
                active.is_none_or(|a| a[p]) && camera.touches(x, y, width, height)
            };
            match (active, camera.covers_all()) {
                (None, true) => self.pick(None::<fn(usize) -> bool>),
                _ => self.pick(Some(seen)),
            }
            self.picked_valid = true;
        }
        self.rays.clear();
        self.seen.clear();
        let partial = frame.partial;
        self.rays.extend(self.picked.iter().map(|&p| {
            let (x, y) = (p % w, y0 + p / w);
            let pixel = (y0 * w + p) as u64;
            let (ox, oy) = sampler::offset(scene, frame.frame_index, pixel, s, n);
            if partial {
                let (x, y) = (x as Real + ox, y as Real + oy);
                self.seen.push(camera.sees(x, y, width, height));
            }
            if camera.has_lens() {
                let (u, v) = sampler::lens(scene, frame.frame_index, pixel, s);
                camera.lens_ray(x as Real + ox, y as Real + oy, width, height, u, v)
            } else {
                camera.ray(x as Real + ox, y as Real + oy, width, height)
            }
        }));
    }
}

impl RowScratch {
    /// The band's pixels that take this sample, from the whole layout:
    /// each block's pixels `active` takes (all without it), their run as
    /// long as they are.
    fn pick(&mut self, active: Option<impl Fn(usize) -> bool>) {
        self.picked.clear();
        self.picked_runs.clear();
        let Some(active) = active else {
            self.picked.extend_from_slice(&self.order);
            self.picked_runs.extend_from_slice(&self.runs);
            return;
        };
        let mut start = 0;
        for &run in &self.runs {
            let block = &self.order[start..start + run as usize];
            let before = self.picked.len();
            self.picked
                .extend(block.iter().copied().filter(|&p| active(p)));
            let taken = (self.picked.len() - before) as u32;
            if taken > 0 {
                self.picked_runs.push(taken);
            }
            start += run as usize;
        }
    }
}

/// The band's shadow rays, walked side by side, a cone block's rays to a
/// bundle (`walk_shadows`; where camera rays march alone, each shadow ray
/// does too). Shading takes their outcomes back in the same order, pixel
/// after pixel.
fn band_shadows(
    scene: &Scene,
    surfaces: &[Option<SurfacePoint>],
    runs: &[u32],
    walks: &mut Vec<Result<crate::shade::ShadowWalk, (f32, u64)>>,
    shadows: &mut Vec<(f32, u64)>,
    bundles: &mut crate::shade::BundleScratch,
) {
    shadows.clear();
    if scene.effects.path_tracing.is_some() || scene.effects.shadows.is_none() {
        return;
    }
    walks.clear();
    let mut groups = Vec::with_capacity(runs.len());
    for span in crate::march::run_spans(runs) {
        let (first, alone) = (walks.len(), span.len() == 1);
        for at in surfaces[span].iter().flatten() {
            walks.extend(scene.look.shadow_walks(&scene.effects, &scene.quality, at));
        }
        if !alone {
            groups.push(first..walks.len());
        }
    }
    shadows.resize(walks.len(), (1.0, 0));
    let (f, q) = (&scene.fractal, &scene.quality);
    crate::shade::walk_shadows(walks, groups.into_iter(), f, q, shadows, bundles);
}

/// The band's path-traced samples, a bounce at a time side by side (none
/// when the scene is not path traced).
fn band_paths<'p>(
    frame: &FrameSetup,
    k: usize,
    y0: usize,
    s: u32,
    order: &[usize],
    surfaces: &[Option<SurfacePoint>],
    paths: &'p mut crate::shade::PathScratch,
) -> &'p [(Vec3, StageCounts)] {
    let w = frame.width as usize;
    let (scene, camera) = (&frame.scenes[k], &frame.cameras[k]);
    match &scene.effects.path_tracing {
        Some(pt) => {
            let random = |i: usize, d: u32| {
                sampler::path_number(scene, frame.frame_index, (y0 * w + order[i]) as u64, s, d)
            };
            crate::shade::trace_paths(
                &scene.look,
                pt,
                &scene.fractal,
                &scene.quality,
                surfaces,
                camera.up,
                frame.environment.as_deref(),
                frame.palettes[k].as_ref(),
                &random,
                paths,
            );
            &paths.out[..]
        }
        None => &[][..],
    }
}

/// The band's ambient occlusion, its samples packed across the hits
/// (left empty when it is off, or replaced by path tracing).
fn band_occlusion(
    scene: &Scene,
    surfaces: &[Option<SurfacePoint>],
    occluded: &mut Vec<Option<(f32, u64)>>,
) {
    occluded.clear();
    if let (None, Some(ao)) = (
        &scene.effects.path_tracing,
        &scene.effects.ambient_occlusion,
    ) {
        occluded.resize(surfaces.len(), None);
        let hits = surfaces.iter().enumerate().filter_map(|(x, at)| {
            let at = at.as_ref()?;
            Some((x, at.point, at.normal, at.t, at.footprint))
        });
        crate::shade::occlusions(&scene.fractal, ao, hits, |x, out| occluded[x] = Some(out));
    }
}

/// A band's working buffers (see `render_band`).
#[derive(Default)]
pub(super) struct RowScratch {
    /// Each camera ray's pixel in the band, and the blocks' sizes
    /// (`cone_blocks`), for the width, rows and block shape they were laid
    /// out for.
    pub(super) laid_out: Option<(usize, usize, (usize, usize))>,
    pub(super) order: Vec<usize>,
    pub(super) runs: Vec<u32>,
    /// The pixels of `order` that take this sample, and their blocks' sizes.
    pub(super) picked: Vec<usize>,
    pub(super) picked_runs: Vec<u32>,
    /// Whether `picked` holds this band's pixels for this layout.
    pub(super) picked_valid: bool,
    pub(super) rays: Vec<crate::march::Ray>,
    /// Whether each camera ray's sample is within the picture, where the
    /// projection leaves part of the image out; empty otherwise.
    pub(super) seen: Vec<bool>,
    pub(super) marched: Vec<MarchResult>,
    /// Where each camera ray met the surface.
    pub(super) surfaces: Vec<Option<SurfacePoint>>,
    pub(super) walks: Vec<Result<crate::shade::ShadowWalk, (f32, u64)>>,
    pub(super) shadows: Vec<(f32, u64)>,
    /// The shadow bundles' scratch space.
    pub(super) bundles: crate::shade::BundleScratch,
    /// Each pixel's ambient occlusion and its cost, where it hit.
    pub(super) occluded: Vec<Option<(f32, u64)>>,
    /// Each camera ray's bounding-sphere interval; where each run of them
    /// may start, and what its cone cost.
    pub(super) cone_free: crate::march::ConeScratch,
    /// The band's path-traced samples, traced together.
    pub(super) paths: crate::shade::PathScratch,
}

thread_local! {
    pub(super) static ROW_SCRATCH: std::cell::Cell<RowScratch> = std::cell::Cell::default();
    /// One band's sums for `render_frame_into`, kept like `ROW_SCRATCH`.
    pub(super) static ROW_SUMS: std::cell::Cell<Accumulation> = std::cell::Cell::default();
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
        let sky = if scene.look.transparent_background {
            Vec3::ZERO
        } else if let Some(pt) = &scene.effects.path_tracing {
            pt.sky.radiance(&scene.look, ray.dir, up, environment) * pt.sky_intensity
        } else {
            scene.look.background(ray.dir, up)
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
