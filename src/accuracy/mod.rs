//! What accuracy costs in time: `mandelreel accuracy` renders one frame of a
//! user's own scene as a reference that trusts no distance estimate, then
//! sweeps every quality knob, distance estimator and precision one at a time
//! around the scene's settings and measures, for each, the wall time, the
//! orbits computed, the depth error against the reference and the image error.
//!
//! The reference has two parts: hit depths found by membership stepping and
//! bisection (`march::march_by_membership`), and a shaded image of the same
//! fractal with every marching knob set high (`reference_scene`).

use crate::color::linear_to_srgb;
use crate::fractal::{DeMethod, Precision};
use crate::march::march_by_membership;
use crate::math::Real;
use crate::render::{render_frame, Film};
use crate::scene::Scene;
use rayon::prelude::*;
use serde::Serialize;
use std::time::Instant;

mod chart;
pub use chart::write_chart;

/// One setting to measure: the scene with one knob changed.
#[derive(Clone, Debug)]
pub struct Variant {
    /// The knob varied (`iterations`, `de`, …), or `reference` / `scene`.
    pub knob: &'static str,
    /// Its value in this variant.
    pub setting: String,
    pub scene: Scene,
}

/// What one variant cost and how far it is from the reference.
#[derive(Clone, Debug, Serialize)]
pub struct Measurement {
    pub knob: &'static str,
    pub setting: String,
    pub seconds: f64,
    /// Orbits computed (distance-estimator evaluations, membership tests, normals).
    pub de_evaluations: u64,
    /// Mean and 99th percentile of |depth − reference depth| in pixel footprints,
    /// over pixels that both hit.
    pub depth_error_mean_px: f64,
    pub depth_error_p99_px: f64,
    /// Share of pixels where this variant and the reference disagree on hit or miss.
    pub hit_mismatch: f64,
    /// Share of pixels whose hit lies more than one footprint past the reference
    /// crossing: the marcher went through the surface (the failure that matters;
    /// stopping early, where a pixel's cone grazes a sub-pixel feature in front
    /// of the centre ray's crossing, is what a footprint threshold is meant to do).
    pub overshoot: f64,
    /// Root-mean-square difference of the sRGB images (0..1 per channel).
    pub image_rmse: f64,
    /// Peak signal-to-noise ratio of that difference in dB (infinite when identical).
    pub psnr_db: f64,
    /// On the Pareto front of median time against image error, timing noise
    /// allowed for (`pareto_front`).
    pub pareto: bool,
}

/// The scene's own set (its iterations and bailout: they define which
/// points are in it) with every marching knob set high: the reference. The
/// analytic estimator in f64, trusted (no membership walk, which goes
/// through the thin parts of the set: docs/surface.md) down to hit
/// threshold ÷ 8, fudge ≤ 0.5, no over-relaxation, every ray marched alone
/// (no cones), 8× the steps, normal step ÷ 4 and at least 16 samples in
/// every pixel.
pub fn reference_scene(scene: &Scene) -> Scene {
    let mut r = scene.clone();
    r.fractal.de = DeMethod::Analytic;
    r.fractal.precision = Precision::F64;
    r.quality.hit_threshold = scene.quality.hit_threshold / 8.0;
    r.quality.membership_step = 0.0;
    r.quality.fudge = scene.quality.fudge.min(0.5);
    r.quality.max_steps = scene.quality.max_steps.saturating_mul(8);
    r.quality.normal_step = scene.quality.normal_step / 4.0;
    r.quality.over_relaxation = 1.0;
    r.quality.cone_rays = 1;
    r.samples_per_pixel = scene.samples_per_pixel.max(16);
    r.adaptive = None;
    r
}

/// Membership steps of the reference depths, as a fraction of the footprint.
pub const REFERENCE_STEP: Real = 1.0 / 16.0;

/// How settled the reference depths are: the same pass at twice the step.
#[derive(Clone, Debug, Serialize)]
pub struct Convergence {
    /// Mean |depth difference| in footprints, over pixels both passes hit.
    pub depth_change_mean_px: f64,
    /// Share of pixels whose hit/miss changes.
    pub hit_change: f64,
}

/// Everything `accuracy` measured.
#[derive(Clone, Debug)]
pub struct Report {
    pub rows: Vec<Measurement>,
    pub reference: Scene,
    pub convergence: Convergence,
}

fn scaled(v: u32, f: Real) -> u32 {
    ((v as Real * f).round() as u32).max(1)
}

/// The sweep: the reference, the scene itself, then one knob at a time.
pub fn variants(scene: &Scene) -> Vec<Variant> {
    let mut out = vec![
        Variant {
            knob: "reference",
            setting: "membership depth + high-quality shading".into(),
            scene: reference_scene(scene),
        },
        Variant {
            knob: "scene",
            setting: "as in the timeline".into(),
            scene: scene.clone(),
        },
    ];
    let mut add = |knob: &'static str, setting: String, change: &dyn Fn(&mut Scene)| {
        let mut s = scene.clone();
        change(&mut s);
        if s != *scene && !out.iter().any(|v| v.scene == s) {
            out.push(Variant {
                knob,
                setting,
                scene: s,
            });
        }
    };
    let f = &scene.fractal;
    let q = &scene.quality;
    for k in [0.25, 0.5, 0.75, 1.5] {
        let n = scaled(f.iterations, k);
        add("iterations", n.to_string(), &|s| s.fractal.iterations = n);
    }
    for b in [2.0, 16.0, 256.0] {
        add("bailout", format!("{b}"), &|s| s.fractal.bailout = b);
    }
    for k in [4.0, 2.0, 0.5, 0.25] {
        let v = q.hit_threshold * k;
        add("hit_threshold", format!("{v}"), &|s| {
            s.quality.hit_threshold = v
        });
    }
    for v in [0.0, 0.125, 0.25, 0.5, 1.0, 2.0] {
        add("membership_step", format!("{v}"), &|s| {
            s.quality.membership_step = v
        });
    }
    for v in [0.5, 0.7, 0.9, 1.0] {
        add("fudge", format!("{v}"), &|s| s.quality.fudge = v);
    }
    for v in [1.0, 1.2, 1.5, 1.8] {
        add("over_relaxation", format!("{v}"), &|s| {
            s.quality.over_relaxation = v
        });
    }
    for v in [1, 4, 8, 16, 64] {
        add("cone_rays", v.to_string(), &|s| s.quality.cone_rays = v);
    }
    for k in [0.25, 0.5, 2.0] {
        let v = scaled(q.max_steps, k);
        add("max_steps", v.to_string(), &|s| s.quality.max_steps = v);
    }
    for k in [4.0, 0.25] {
        let v = q.normal_step * k;
        add("normal_step", format!("{v}"), &|s| {
            s.quality.normal_step = v
        });
    }
    for n in [1, 4, 9, 16] {
        add("samples_per_pixel", n.to_string(), &|s| {
            s.samples_per_pixel = n;
            s.adaptive = None;
        });
    }
    for noise in [0.04, 0.02, 0.01] {
        add("adaptive", format!("noise {noise} (at most 16)"), &|s| {
            s.samples_per_pixel = 16;
            s.adaptive = Some(crate::scene::Adaptive { first: 2, noise });
        });
    }
    add("perturbation", "off: f64 alone".into(), &|s| {
        s.fractal.perturbation = false
    });
    for precision in [Precision::F64, Precision::F32] {
        for de in DeMethod::ALL {
            add("de", format!("{} {}", de.name(), precision.name()), &|s| {
                s.fractal.de = de;
                s.fractal.precision = precision;
            });
        }
    }
    out
}

/// Membership-reference hit distance for every pixel centre (None for a
/// miss, and for a pixel the camera does not cover, which the render
/// leaves empty), stepping `step_fraction` of a footprint, with the tests
/// spent.
pub fn reference_depths(
    scene: &Scene,
    width: u32,
    height: u32,
    step_fraction: Real,
) -> (Vec<Option<Real>>, u64) {
    // A deep frame is marched as it renders, measured from its target.
    let deep = crate::deep::prepare(scene, [width, height]);
    let scene = deep.as_ref().unwrap_or(scene);
    let camera = scene.camera.frame();
    // Never step finer than a millionth of the camera–target distance: bounds the
    // work for rays that start right on the surface in deep zooms.
    let min_step = 1e-6 * scene.camera.relative_position().length();
    let rows: Vec<(Vec<Option<Real>>, u64)> = (0..height)
        .into_par_iter()
        .map(|y| {
            let mut tests = 0u64;
            let row = (0..width)
                .map(|x| {
                    if !camera.covers(x, y, width, height) {
                        return None;
                    }
                    let ray = camera.ray(x as Real + 0.5, y as Real + 0.5, width, height);
                    let (t, n) = march_by_membership(
                        &ray,
                        &scene.fractal,
                        &scene.quality,
                        step_fraction,
                        min_step,
                        1_000_000,
                    );
                    tests += n as u64;
                    t
                })
                .collect();
            (row, tests)
        })
        .collect();
    let mut depths = Vec::with_capacity((width * height) as usize);
    let mut tests = 0;
    for (row, n) in rows {
        depths.extend(row);
        tests += n;
    }
    (depths, tests)
}

/// The sRGB image of a film as its PNG shows it (`look`'s exposure and
/// tone map), as 0..1 floats.
fn srgb(film: &Film, look: &crate::shade::Look) -> Vec<f32> {
    let display = look.display_transform();
    film.colour
        .iter()
        .flat_map(|c| [c.x, c.y, c.z])
        .map(|x| linear_to_srgb(display.apply(x)))
        .collect()
}

/// Errors of one variant against the reference.
struct Errors {
    depth: DepthErrors,
    rmse: f64,
}

/// How far hit distances lie from the reference's, per pixel, in pixel
/// footprints at the reference depth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthErrors {
    /// Mean and 99th percentile of |depth − reference depth| over pixels
    /// that both hit.
    pub mean_px: f64,
    pub p99_px: f64,
    /// Share of pixels where one hits and the other misses.
    pub hit_mismatch: f64,
    /// Share of pixels whose hit lies more than a footprint past the reference.
    pub overshoot: f64,
}

/// The hits of a rendered film: its nearest depth where any sample hit.
pub fn film_hits(film: &Film) -> Vec<Option<Real>> {
    film.alpha
        .iter()
        .zip(&film.depth)
        .map(|(&a, &d)| (a > 0.0).then_some(d as Real))
        .collect()
}

/// Each pixel's footprint at its reference depth (at distance 1 where the
/// reference misses), for `depth_errors`.
pub fn footprints_at(scene: &Scene, width: u32, height: u32, depths: &[Option<Real>]) -> Vec<Real> {
    let camera = scene.camera.frame();
    (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .map(|(x, y)| camera.ray(x as Real + 0.5, y as Real + 0.5, width, height))
        .map(|ray| ray.footprint(1.0))
        .zip(depths)
        // Footprints scale with distance: footprint(t) = t × footprint(1).
        .map(|(f, t)| t.map_or(f, |t| (t * f).max(1e-300)))
        .collect()
}

/// Depth errors of `hits` against `reference` (see `DepthErrors`).
pub fn depth_errors(
    hits: &[Option<Real>],
    reference: &[Option<Real>],
    footprints: &[Real],
) -> DepthErrors {
    let mut errors = Vec::new();
    let mut mismatches = 0usize;
    let mut overshoots = 0usize;
    for (i, (hit, reference)) in hits.iter().zip(reference).enumerate() {
        match (hit, reference) {
            (Some(t), Some(r)) => {
                let signed = (t - r) / footprints[i];
                if signed > 1.0 {
                    overshoots += 1;
                }
                errors.push(signed.abs())
            }
            (None, None) => {}
            _ => mismatches += 1,
        }
    }
    errors.sort_by(|a, b| a.total_cmp(b));
    let mean = if errors.is_empty() {
        0.0
    } else {
        errors.iter().sum::<f64>() / errors.len() as f64
    };
    let p99 = errors
        .get(((errors.len() as f64 * 0.99).ceil() as usize).saturating_sub(1))
        .copied()
        .unwrap_or(0.0);
    let pixels = reference.len().max(1) as f64;
    DepthErrors {
        mean_px: mean,
        p99_px: p99,
        hit_mismatch: mismatches as f64 / pixels,
        overshoot: overshoots as f64 / pixels,
    }
}

/// Errors of `hits` and `image` against the reference.
fn compare(
    hits: &[Option<Real>],
    image: &[f32],
    reference_image: &[f32],
    reference_depth: &[Option<Real>],
    footprints: &[Real],
) -> Errors {
    let mse = image
        .iter()
        .zip(reference_image)
        .map(|(a, b)| ((a - b) as f64).powi(2))
        .sum::<f64>()
        / image.len().max(1) as f64;
    Errors {
        depth: depth_errors(hits, reference_depth, footprints),
        rmse: mse.sqrt(),
    }
}

/// PSNR of an RMSE in unit values.
fn psnr(rmse: f64) -> f64 {
    crate::math::psnr_db(rmse * rmse, 1.0)
}

/// Timed runs per variant: more while the variant has had under
/// `TIMING_BUDGET_SECONDS`, at most `MAX_TIMED_RUNS`; at least
/// `MIN_TIMED_RUNS` where they fit in `SLOW_BUDGET_SECONDS`, so a slow
/// frame is not rendered five times over.
pub const MIN_TIMED_RUNS: usize = 5;
pub const MAX_TIMED_RUNS: usize = 21;
const TIMING_BUDGET_SECONDS: f64 = 0.3;
const SLOW_BUDGET_SECONDS: f64 = 3.0;

/// Renders `scene` and returns the film with the median wall time of
/// several runs. The median, not the fastest run: a single lucky run of a
/// 15 ms frame moved variants on and off the Pareto front.
fn timed_render(scene: &Scene, frame_index: u32, width: u32, height: u32) -> (Film, f64) {
    let mut seconds = Vec::with_capacity(MAX_TIMED_RUNS);
    let mut film = None;
    let started = Instant::now();
    let more = |runs: usize, elapsed: f64| {
        runs == 0
            || (runs < MAX_TIMED_RUNS && elapsed < TIMING_BUDGET_SECONDS)
            || (runs < MIN_TIMED_RUNS && elapsed < SLOW_BUDGET_SECONDS)
    };
    while more(seconds.len(), started.elapsed().as_secs_f64()) {
        let t0 = Instant::now();
        let f = render_frame(scene, frame_index, width, height, &|| {});
        seconds.push(t0.elapsed().as_secs_f64());
        film = Some(f);
    }
    (
        film.expect("rendered at least once"),
        crate::math::median(&mut seconds),
    )
}

/// Runs the whole sweep on frame `frame_index` of `scene` at `width`×`height`.
/// `progress` hears each variant's name before it is rendered.
pub fn measure(
    scene: &Scene,
    frame_index: u32,
    width: u32,
    height: u32,
    progress: &dyn Fn(usize, usize, &Variant),
) -> Report {
    // Perturbation is a knob only where the frame is deep.
    let deep = crate::deep::needed(scene, [width, height])
        && crate::fractal::whole_power(scene.fractal.power).is_some();
    let all: Vec<Variant> = variants(scene)
        .into_iter()
        .filter(|v| deep || v.knob != "perturbation")
        .map(|mut v| {
            if crate::deep::f32_too_coarse(&v.scene, [width, height]) {
                v.setting += " (renders in f64: f32 cannot resolve these pixels)";
            }
            v
        })
        .collect();
    let reference = &all[0].scene;
    progress(0, all.len(), &all[0]);
    let started = Instant::now();
    let (reference_depth, tests) = reference_depths(reference, width, height, REFERENCE_STEP);
    let reference_film = render_frame(reference, frame_index, width, height, &|| {});
    let reference_seconds = started.elapsed().as_secs_f64();
    let reference_image = srgb(&reference_film, &scene.look);
    let footprint_at_reference = footprints_at(scene, width, height, &reference_depth);

    // The same depths at twice the step: how far the reference itself has settled.
    let (coarse, _) = reference_depths(reference, width, height, 2.0 * REFERENCE_STEP);
    let settled = depth_errors(&coarse, &reference_depth, &footprint_at_reference);
    let convergence = Convergence {
        depth_change_mean_px: settled.mean_px,
        hit_change: settled.hit_mismatch,
    };

    let measurement = |variant: &Variant, seconds: f64, evaluations: u64, e: Errors| Measurement {
        knob: variant.knob,
        setting: variant.setting.clone(),
        seconds,
        de_evaluations: evaluations,
        depth_error_mean_px: e.depth.mean_px,
        depth_error_p99_px: e.depth.p99_px,
        hit_mismatch: e.depth.hit_mismatch,
        overshoot: e.depth.overshoot,
        image_rmse: e.rmse,
        psnr_db: psnr(e.rmse),
        pareto: false,
    };
    // The reference against itself, through the same comparison as every variant.
    let own = compare(
        &reference_depth,
        &reference_image,
        &reference_image,
        &reference_depth,
        &footprint_at_reference,
    );
    let mut rows = vec![measurement(
        &all[0],
        reference_seconds,
        tests + reference_film.stats.de_evaluations,
        own,
    )];
    for (i, variant) in all.iter().enumerate().skip(1) {
        progress(i, all.len(), variant);
        let (film, seconds) = timed_render(&variant.scene, frame_index, width, height);
        let e = compare(
            &film_hits(&film),
            &srgb(&film, &scene.look),
            &reference_image,
            &reference_depth,
            &footprint_at_reference,
        );
        rows.push(measurement(variant, seconds, film.stats.de_evaluations, e));
    }
    mark_pareto(&mut rows);
    Report {
        rows,
        reference: reference.clone(),
        convergence,
    }
}

/// Median times closer than this factor are within timing noise.
pub const TIMING_NOISE: f64 = 1.03;

/// One candidate for a Pareto front: its cost and one of its errors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrontPoint {
    /// Median wall time.
    pub seconds: f64,
    pub de_evaluations: u64,
    pub error: f64,
    /// The scene's own settings (wins ties).
    pub is_scene: bool,
}

impl FrontPoint {
    fn of(row: &Measurement, error: f64) -> FrontPoint {
        FrontPoint {
            seconds: row.seconds,
            de_evaluations: row.de_evaluations,
            error,
            is_scene: row.knob == "scene",
        }
    }
}

/// Which points are on the Pareto front of cost against error (`None` is
/// no candidate). Median times within `TIMING_NOISE` of each other are the
/// same cost, and errors equal to three significant digits the same error, so:
/// - a point is off the front when another has less error at no more than
///   `TIMING_NOISE` × its time;
/// - points with equal error are one point: of those within `TIMING_NOISE`
///   of the fastest of them, or with its DE evaluation count (the same work,
///   whose time differences are noise), the one with fewer evaluations
///   stays, then the scene's own settings, then the faster, then the first.
///
/// Deciding equal errors as a group, not pair by pair, keeps the rule free
/// of cycles (A ties B, B ties C, C beats A), so the front is never empty.
pub fn pareto_front(points: &[Option<FrontPoint>]) -> Vec<bool> {
    let candidates: Vec<(usize, FrontPoint)> = points
        .iter()
        .enumerate()
        .filter_map(|(i, p)| p.map(|p| (i, p)))
        .collect();
    let preferred = |a: &&(usize, FrontPoint), b: &&(usize, FrontPoint)| {
        (a.1.de_evaluations.cmp(&b.1.de_evaluations))
            .then(b.1.is_scene.cmp(&a.1.is_scene))
            .then(a.1.seconds.total_cmp(&b.1.seconds))
            .then(a.0.cmp(&b.0))
    };
    // Errors are compared to three significant digits: a variant whose image
    // differs from another's in the sixth digit is not better.
    let candidates: Vec<(usize, FrontPoint)> = candidates
        .into_iter()
        .map(|(i, p)| {
            let error = significant(p.error, 3);
            (i, FrontPoint { error, ..p })
        })
        .collect();
    let mut front = vec![false; points.len()];
    let undercut = |p: &FrontPoint| {
        candidates
            .iter()
            .any(|(_, q)| q.error < p.error && q.seconds <= p.seconds * TIMING_NOISE)
    };
    for &(i, p) in &candidates {
        // A NaN error is no error level to be on the front at.
        if p.error.is_nan() || undercut(&p) {
            continue;
        }
        // The level's members another variant beats cannot hold its star.
        let same_error = || {
            candidates
                .iter()
                .filter(|(_, q)| q.error == p.error && !undercut(q))
        };
        let fastest = same_error()
            .min_by(|a, b| a.1.seconds.total_cmp(&b.1.seconds))
            .expect("p itself qualifies")
            .1;
        let kept = same_error()
            .filter(|(_, q)| {
                q.seconds <= fastest.seconds * TIMING_NOISE
                    || q.de_evaluations == fastest.de_evaluations
            })
            .min_by(preferred)
            .expect("the fastest qualifies");
        front[i] = kept.0 == i;
    }
    front
}

/// `v` rounded to `digits` significant digits.
fn significant(v: f64, digits: i32) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    let scale = 10f64.powi(digits - 1 - v.abs().log10().floor() as i32);
    (v * scale).round() / scale
}

/// The front of median time against `error` over `rows`. The reference is
/// the yardstick, not a candidate, and is never on it.
pub fn front_of(rows: &[Measurement], error: impl Fn(&Measurement) -> f64) -> Vec<bool> {
    let points: Vec<Option<FrontPoint>> = rows
        .iter()
        .map(|r| (r.knob != "reference").then(|| FrontPoint::of(r, error(r))))
        .collect();
    pareto_front(&points)
}

/// Marks (★) the front of median time against image error.
pub fn mark_pareto(rows: &mut [Measurement]) {
    let front = front_of(rows, |r| r.image_rmse);
    for (row, on) in rows.iter_mut().zip(front) {
        row.pareto = on;
    }
}

/// The share of pixels whose overshoot earns a variant a warning: one in
/// a thousand (15 pixels of a 160×90 frame). The scene's own settings
/// overshoot on 2 pixels at zoom frame 60, the analytic estimator at finer
/// hit thresholds on 6, the membership walk on 3% and more.
pub const OVERSHOOT_FLAG: f64 = 0.001;
/// PSNR differences under this many dB are taken as not worth paying for
/// (a convention, not a measurement of what shows).
pub const VISIBLE_PSNR_DB: f64 = 0.5;

/// Marched through the surface on at least `OVERSHOOT_FLAG` of the pixels.
/// Hit/miss differences do not count: they grow with samples per pixel
/// (a pixel hits where any sample does) and with the reference's finer
/// threshold, on every setting of a scene alike (2.6–3.9% on S1).
pub fn flagged(r: &Measurement) -> bool {
    r.overshoot >= OVERSHOOT_FLAG
}

/// The setting to use: of the variants not `flagged`, the cheapest whose
/// image is within `VISIBLE_PSNR_DB` of the best of them. Of those within
/// `TIMING_NOISE` of the cheapest, the scene's own settings win, then
/// fewer DE evaluations. `None` when every variant is flagged.
pub fn recommended(rows: &[Measurement]) -> Option<usize> {
    let candidates = || {
        rows.iter()
            .enumerate()
            .filter(|(_, r)| r.knob != "reference" && !flagged(r) && !r.psnr_db.is_nan())
    };
    let best = candidates().map(|(_, r)| r.psnr_db).reduce(f64::max)?;
    let good = || candidates().filter(|(_, r)| r.psnr_db >= best - VISIBLE_PSNR_DB);
    let cheapest = good().map(|(_, r)| r.seconds).reduce(f64::min)?;
    good()
        .filter(|(_, r)| r.seconds <= cheapest * TIMING_NOISE)
        .min_by(|(_, a), (_, b)| {
            (b.knob == "scene")
                .cmp(&(a.knob == "scene"))
                .then(a.de_evaluations.cmp(&b.de_evaluations))
                .then(a.seconds.total_cmp(&b.seconds))
        })
        .map(|(i, _)| i)
}

/// How the times were taken and the front drawn, for the Markdown.
pub fn front_rule_text() -> String {
    format!(
        "Times are the median of {MIN_TIMED_RUNS} to {MAX_TIMED_RUNS} runs of the frame (more for quick frames, within {TIMING_BUDGET_SECONDS} s a variant; fewer, down to one, for frames too slow for {MIN_TIMED_RUNS} runs in {SLOW_BUDGET_SECONDS} s). \
★ marks the Pareto front of median time against image RMSE (the chart draws the same front for mean depth error too), \
with times within {:.0}% of each other counted as the same cost and errors equal to three significant digits as the same error: a variant is off the front when another has less error \
at no more than {TIMING_NOISE}× its median time. Variants with equal error are one point: of those within {:.0}% of the fastest of them, \
or with its DE evaluation count (the same work), the star goes to the one with fewer DE evaluations, \
then to the scene's own settings, then to the faster. The reference is the yardstick, not a candidate.",
        100.0 * (TIMING_NOISE - 1.0),
        100.0 * (TIMING_NOISE - 1.0)
    )
}

/// The table as CSV, one row per variant, a column per field.
pub fn to_csv(rows: &[Measurement]) -> String {
    crate::output::csv::csv_text(rows)
}

/// The table as Markdown, with times relative to the scene's own settings.
pub fn to_markdown(report: &Report, title: &str) -> String {
    let rows = &report.rows;
    let r = &report.reference;
    let base = rows
        .iter()
        .find(|r| r.knob == "scene")
        .map(|r| r.seconds)
        .unwrap_or(1.0)
        .max(1e-9);
    let mut out = format!(
        "{title}\n\nReference: the scene's set ({} iterations, bailout {}), Analytic f64, hit threshold {}, fudge {}, {} steps, normal step {}, {} samples per pixel; depths by membership steps of 1/{} footprint. Against steps twice as long, its depths move by {:.2} px on average and {:.2}% of pixels change hit/miss: differences below that are within the reference's own uncertainty.\n\n| knob | setting | time (s) | × scene | DE evals | depth err mean (px) | depth err p99 (px) | hit/miss differ | overshoot | PSNR (dB) | Pareto |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|:-:|\n",
        r.fractal.iterations,
        r.fractal.bailout,
        r.quality.hit_threshold,
        r.quality.fudge,
        r.quality.max_steps,
        r.quality.normal_step,
        r.samples_per_pixel,
        (1.0 / REFERENCE_STEP).round(),
        report.convergence.depth_change_mean_px,
        100.0 * report.convergence.hit_change,
    );
    for r in rows {
        out += &format!(
            "| {} | {} | {:.3} | {:.2} | {} | {:.2} | {:.2} | {:.2}% | {:.2}% | {} | {} |\n",
            r.knob,
            r.setting,
            r.seconds,
            r.seconds / base,
            r.de_evaluations,
            r.depth_error_mean_px,
            r.depth_error_p99_px,
            100.0 * r.hit_mismatch,
            100.0 * r.overshoot,
            if r.psnr_db.is_finite() {
                format!("{:.1}", r.psnr_db)
            } else {
                "∞".into()
            },
            if r.pareto { "★" } else { "" }
        );
    }
    // After the table, so the reference paragraph above stays as it is.
    out += &format!("\n{}\n", front_rule_text());
    out += &format!(
        "\n{} ({}; a red ring marks {}).\n",
        chart::advice(rows, recommended(rows)),
        chart::star_rule(),
        chart::flag_rule()
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reference_has_no_depth_outside_a_fisheye_circle() {
        // A fisheye narrow enough that the bulb fills the whole image,
        // corners included: only the circle is the picture.
        let mut scene = Scene::default();
        scene.camera.projection = crate::camera::Projection::Fisheye { degrees: 4.0 };
        let (w, h) = (12, 8);
        let (depths, _) = reference_depths(&scene, w, h, 1.0);
        let camera = scene.camera.frame();
        for (i, depth) in depths.iter().enumerate() {
            let (x, y) = (i as u32 % w, i as u32 / w);
            let inside = camera.covers(x, y, w, h);
            assert_eq!(depth.is_some(), inside, "pixel ({x}, {y}): {depth:?}");
        }
    }

    #[test]
    fn depth_errors_of_known_hits() {
        // Five pixels, footprints 0.5, 1, 2, 1, 1: pixel 0 stops 1 footprint
        // short (0.5 before), pixel 1 3 footprints past (an overshoot),
        // pixel 2 exactly on, pixel 3 hits where the reference misses,
        // pixel 4 misses where the reference hits.
        let hits = [Some(1.5), Some(5.0), Some(4.0), Some(1.0), None];
        let reference = [Some(2.0), Some(2.0), Some(4.0), None, Some(3.0)];
        let e = depth_errors(&hits, &reference, &[0.5, 1.0, 2.0, 1.0, 1.0]);
        assert_eq!(e.mean_px, (1.0 + 3.0 + 0.0) / 3.0);
        assert_eq!(e.p99_px, 3.0);
        assert_eq!(e.hit_mismatch, 2.0 / 5.0);
        assert_eq!(e.overshoot, 1.0 / 5.0);
    }

    fn row(knob: &'static str, seconds: f64, rmse: f64) -> Measurement {
        Measurement {
            knob,
            setting: String::new(),
            seconds,
            // Work in proportion to time, so no two rows here are the same work.
            de_evaluations: (seconds * 1000.0) as u64,
            depth_error_mean_px: 0.0,
            depth_error_p99_px: 0.0,
            hit_mismatch: 0.0,
            overshoot: 0.0,
            image_rmse: rmse,
            psnr_db: psnr(rmse),
            pareto: false,
        }
    }

    #[test]
    fn a_flag_needs_overshoot_on_one_pixel_in_a_thousand() {
        let mut r = row("fudge", 1.0, 0.1);
        // Two pixels of a 160×90 frame: the scene's own settings at zoom frame 60.
        r.overshoot = 2.0 / 14400.0;
        assert!(!flagged(&r));
        r.overshoot = 0.0011;
        assert!(flagged(&r));
        // Hit/miss differences alone, as on every variant of S1: no flag.
        r.overshoot = 0.0;
        r.hit_mismatch = 0.03;
        assert!(!flagged(&r));
    }

    #[test]
    fn recommended_is_the_cheapest_within_sight_of_the_best_image() {
        let mut rows = vec![
            row("reference", 50.0, 0.0),
            row("scene", 1.0, 0.12),
            row("fast", 0.5, 0.2),
            row("best", 3.0, 0.09),
            // 0.4 dB worse than the best, cheaper: recommended.
            row("close", 2.0, 0.09 * 10f64.powf(0.4 / 20.0)),
            // 0.6 dB worse: too far.
            row("near", 1.5, 0.09 * 10f64.powf(0.6 / 20.0)),
            // Better and cheaper than all, but marches through the surface.
            row("broken", 0.8, 0.01),
        ];
        rows[6].overshoot = 0.05;
        assert_eq!(recommended(&rows), Some(4));
        // Within timing noise of the cheapest, the scene's own settings win.
        rows[1] = row("scene", 2.05, 0.09);
        assert_eq!(recommended(&rows), Some(1));
        for r in &mut rows {
            r.overshoot = 0.5;
        }
        assert_eq!(recommended(&rows), None);
    }

    #[test]
    fn pareto_front_keeps_only_undominated_points() {
        let mut rows = vec![
            row("a", 1.0, 0.1),
            row("b", 2.0, 0.05),
            row("c", 2.0, 0.2), // slower and worse than a
            row("d", 0.5, 0.3),
            row("e", 3.0, 0.05), // as good as b but slower
        ];
        // The reference (zero error) is the yardstick: never on the front, and
        // it does not push others off it.
        rows.push(row("reference", 50.0, 0.0));
        mark_pareto(&mut rows);
        let front: Vec<_> = rows.iter().filter(|r| r.pareto).map(|r| r.knob).collect();
        assert_eq!(front, ["a", "b", "d"]);
    }

    #[test]
    fn a_level_keeps_its_star_when_only_its_slower_member_is_beaten() {
        // A and B share an error; C, a little better, is within noise of
        // B's time but not of A's: A holds the level's star (picking B,
        // which has fewer evaluations, and then finding it beaten left the
        // level without one). A NaN error is on no front, and panics nothing.
        let point = |seconds, de_evaluations, error| {
            Some(FrontPoint {
                seconds,
                de_evaluations,
                error,
                is_scene: false,
            })
        };
        let front = pareto_front(&[
            point(1.00, 300, 0.1),
            point(1.02, 200, 0.1),
            point(1.04, 300, 0.09),
            point(0.5, 100, f64::NAN),
        ]);
        assert_eq!(front, [true, false, true, false]);
    }

    /// The front of the scene (1 s, 1000 evaluations, error 0.1) and one
    /// variant: which of the two are on it.
    fn front_with_scene(seconds: f64, de_evaluations: u64, error: f64) -> Vec<bool> {
        let point = |seconds, de_evaluations, error, is_scene| {
            Some(FrontPoint {
                seconds,
                de_evaluations,
                error,
                is_scene,
            })
        };
        pareto_front(&[
            None, // the reference
            point(1.0, 1000, 0.1, true),
            point(seconds, de_evaluations, error, false),
        ])
    }

    #[test]
    fn pareto_front_allows_for_timing_noise() {
        // The same work (same error, same evaluation count) at 0.97× or 0.85×
        // the time: the difference is noise, one star, the scene's.
        assert_eq!(front_with_scene(0.97, 1000, 0.1), [false, true, false]);
        assert_eq!(front_with_scene(0.85, 1000, 0.1), [false, true, false]);
        assert_eq!(front_with_scene(1.15, 1000, 0.1), [false, true, false]);
        // Same error within the 3% noise: the evaluation count decides.
        assert_eq!(front_with_scene(0.98, 990, 0.1), [false, false, true]);
        assert_eq!(front_with_scene(0.98, 1010, 0.1), [false, true, false]);
        assert_eq!(front_with_scene(1.02, 990, 0.1), [false, false, true]);
        // Faster beyond noise, with fewer evaluations to show for it: a real speed-up.
        assert_eq!(front_with_scene(0.85, 850, 0.1), [false, false, true]);
        // Less error at a cost within noise pushes the scene off...
        assert_eq!(front_with_scene(1.02, 1020, 0.099), [false, false, true]);
        // ...beyond noise, both stay: a trade.
        assert_eq!(front_with_scene(1.10, 1100, 0.099), [false, true, true]);
        // Worse and no cheaper: only the scene.
        assert_eq!(front_with_scene(1.0, 900, 0.2), [false, true, false]);
    }

    #[test]
    fn pareto_front_of_equal_errors_is_one_point_without_cycles() {
        // A ties B (2.5% apart, B fewer evaluations), B ties C (2.4%, C fewer),
        // but A is faster than C beyond noise: pair by pair each would push
        // another off. As a group, B stays: within 3% of the fastest (A), with
        // fewer evaluations than A; C is beyond noise of A.
        let point = |seconds, de_evaluations| {
            Some(FrontPoint {
                seconds,
                de_evaluations,
                error: 0.1,
                is_scene: false,
            })
        };
        let front = pareto_front(&[point(1.0, 300), point(1.025, 200), point(1.05, 100)]);
        assert_eq!(front, [false, true, false]);
    }

    #[test]
    fn pareto_front_compares_errors_to_three_digits() {
        // An image differing in the sixth digit, the same work, 0.8× the time
        // (noise): the scene keeps the star.
        assert_eq!(front_with_scene(0.8, 1000, 0.1000001), [false, true, false]);
        assert_eq!(front_with_scene(0.8, 1000, 0.0999999), [false, true, false]);
        // In the third digit it is less error.
        assert_eq!(front_with_scene(1.0, 1000, 0.0995), [false, false, true]);
        assert_eq!(significant(0.012345, 3), 0.0123);
        assert_eq!(significant(33.094, 3), 33.1);
        assert_eq!(significant(0.0, 3), 0.0);
    }

    #[test]
    fn markdown_says_how_the_front_was_computed() {
        let report = Report {
            rows: vec![row("reference", 5.0, 0.0), row("scene", 1.0, 0.1)],
            reference: reference_scene(&Scene::default()),
            convergence: Convergence {
                depth_change_mean_px: 0.0,
                hit_change: 0.0,
            },
        };
        let md = to_markdown(&report, "# t");
        assert!(md.contains(&format!(
            "median of {MIN_TIMED_RUNS} to {MAX_TIMED_RUNS} runs"
        )));
        assert!(
            md.contains("less error at no more than 1.03× its median time"),
            "{md}"
        );
        assert!(md.contains("within 3% of the fastest of them"));
        // Which setting to use, in words, as the chart's star says.
        assert!(md.contains("recommended: "), "{md}");
    }

    #[test]
    fn psnr_of_known_errors() {
        assert_eq!(psnr(0.0), f64::INFINITY);
        assert!((psnr(0.1) - 20.0).abs() < 1e-12);
        assert!((psnr(0.01) - 40.0).abs() < 1e-12);
    }

    #[test]
    fn variants_change_one_knob_each_and_are_distinct() {
        let scene = Scene::default();
        let all = variants(&scene);
        assert_eq!(all[0].knob, "reference");
        assert_eq!(all[1].scene, scene);
        for (i, v) in all.iter().enumerate().skip(2) {
            assert_ne!(v.scene, scene, "{} {}", v.knob, v.setting);
            for w in &all[i + 1..] {
                assert_ne!(v.scene, w.scene);
            }
        }
        // Every estimator in both precisions appears (the scene's own is the "scene" row).
        assert_eq!(all.iter().filter(|v| v.knob == "de").count(), 9);
    }
}
