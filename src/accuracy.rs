//! What accuracy costs in time: `mandelreel accuracy` renders one frame of a
//! user's own scene as a reference that trusts no distance estimate, then
//! sweeps every quality knob, distance estimator and precision one at a time
//! around the scene's settings and measures, for each, the wall time, the
//! orbits computed, the depth error against the reference and the image error.
//!
//! The reference has two parts: hit depths found by membership stepping and
//! bisection (`march::march_by_membership`), and a shaded image of the same
//! fractal with every marching knob set high (`reference_scene`).

use crate::error::{Error, Result};
use crate::fractal::{DeMethod, Precision};
use crate::march::march_by_membership;
use crate::math::{linear_to_srgb, Real};
use crate::render::{render_frame, Film};
use crate::scene::Scene;
use rayon::prelude::*;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

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
    /// On the Pareto front of time against image error: no other variant is
    /// both faster and closer to the reference.
    pub pareto: bool,
}

/// The scene's own set (its iterations and bailout: they define which
/// points are in it) with every marching knob set high: the reference. The
/// analytic estimator in f64, trusted (no membership walk, which goes
/// through the thin parts of the set: docs/surface.md) down to hit
/// threshold ÷ 8, fudge ≤ 0.5, no over-relaxation, every ray marched alone
/// (no cones), 8× the steps, normal step ÷ 4 and at least 16 samples per
/// pixel.
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
            s.samples_per_pixel = n
        });
    }
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
/// miss), stepping `step_fraction` of a footprint, with the tests spent.
pub fn reference_depths(
    scene: &Scene,
    width: u32,
    height: u32,
    step_fraction: Real,
) -> (Vec<Option<Real>>, u64) {
    let camera = scene.camera.frame();
    // Never step finer than a millionth of the camera–target distance: bounds the
    // work for rays that start right on the surface in deep zooms.
    let min_step = 1e-6 * (scene.camera.position - scene.camera.target).length();
    let rows: Vec<(Vec<Option<Real>>, u64)> = (0..height)
        .into_par_iter()
        .map(|y| {
            let mut tests = 0u64;
            let row = (0..width)
                .map(|x| {
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
    film.colour
        .iter()
        .flat_map(|c| [c.x, c.y, c.z])
        .map(|x| linear_to_srgb(look.display(x)))
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

fn psnr(rmse: f64) -> f64 {
    if rmse == 0.0 {
        f64::INFINITY
    } else {
        -20.0 * rmse.log10()
    }
}

/// Renders `scene` and returns the film with its wall time. Quick renders
/// are repeated until a quarter second has passed (at most 20 times) and the
/// fastest run is kept, so small frames still give stable timings.
fn timed_render(scene: &Scene, frame_index: u32, width: u32, height: u32) -> (Film, f64) {
    let mut best = f64::INFINITY;
    let mut film = None;
    let started = Instant::now();
    for _ in 0..20 {
        let t0 = Instant::now();
        let f = render_frame(scene, frame_index, width, height, &|| {});
        best = best.min(t0.elapsed().as_secs_f64());
        film = Some(f);
        if started.elapsed().as_secs_f64() > 0.25 {
            break;
        }
    }
    (film.expect("rendered at least once"), best)
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
    let all = variants(scene);
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

/// Marks the variants no other variant beats on both time and image error.
/// The reference is the yardstick, not a candidate, and is never marked.
pub fn mark_pareto(rows: &mut [Measurement]) {
    let candidate = |r: &Measurement| r.knob != "reference";
    let points: Vec<Option<(f64, f64)>> = rows
        .iter()
        .map(|r| candidate(r).then_some((r.seconds, r.image_rmse)))
        .collect();
    for (i, row) in rows.iter_mut().enumerate() {
        let Some((t, e)) = points[i] else {
            row.pareto = false;
            continue;
        };
        row.pareto = !points.iter().enumerate().any(|(j, p)| {
            p.is_some_and(|(tj, ej)| j != i && tj <= t && ej <= e && (tj < t || ej < e))
        });
    }
}

/// The table as CSV, one row per variant, a column per field.
pub fn to_csv(rows: &[Measurement]) -> String {
    crate::output::csv_text(rows)
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
    out
}

static FONT: &[u8] = include_bytes!("../assets/fonts/DejaVuSansMono.ttf");

/// Draws image error against time, one series per knob, Pareto front marked,
/// and writes it as a PNG.
pub fn write_chart(rows: &[Measurement], title: &str, path: &Path) -> Result<()> {
    use plotters::prelude::*;
    let chart_error = |e: String| Error::Image {
        path: path.to_path_buf(),
        message: e,
    };
    // Registering twice is harmless; a bad font would be a build error in practice.
    plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
        .map_err(|_| chart_error("the embedded font is unreadable".into()))?;
    let (w, h) = (1000u32, 640u32);
    let mut pixels = vec![255u8; (w * h * 3) as usize];
    // Log axes. The reference (zero error by definition) is not plotted.
    let measured: Vec<&Measurement> = rows.iter().filter(|r| r.knob != "reference").collect();
    let positive = |v: f64| v.is_finite() && v > 0.0;
    let times: Vec<f64> = measured
        .iter()
        .map(|r| r.seconds)
        .filter(|&v| positive(v))
        .collect();
    let errors: Vec<f64> = measured
        .iter()
        .map(|r| r.image_rmse)
        .filter(|&v| positive(v))
        .collect();
    let range = |v: &[f64], fallback: (f64, f64)| {
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(0.0, f64::max);
        if lo.is_finite() && hi > 0.0 {
            (lo * 0.7, hi * 1.4)
        } else {
            fallback
        }
    };
    let (t_min, t_max) = range(&times, (1e-3, 1.0));
    let (e_min, e_max) = range(&errors, (1e-4, 1.0));
    let floor = e_min;
    {
        let root = BitMapBackend::with_buffer(&mut pixels, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| chart_error(e.to_string()))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(64)
            .build_cartesian_2d((t_min..t_max).log_scale(), (e_min..e_max).log_scale())
            .map_err(|e| chart_error(e.to_string()))?;
        chart
            .configure_mesh()
            .x_desc("wall time per frame (s)")
            .x_labels(8)
            .y_labels(8)
            .x_label_formatter(&|v| format!("{v:.3}"))
            .y_label_formatter(&|v| format!("{v:.3}"))
            .y_desc("image RMSE vs reference (sRGB)")
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| chart_error(e.to_string()))?;
        let mut knobs: Vec<&'static str> = measured.iter().map(|r| r.knob).collect();
        knobs.dedup();
        knobs.sort();
        knobs.dedup();
        for (k, knob) in knobs.iter().enumerate() {
            let colour = Palette99::pick(k).to_rgba();
            let series: Vec<(f64, f64)> = measured
                .iter()
                .filter(|r| r.knob == *knob)
                .map(|r| (r.seconds.max(t_min), r.image_rmse.max(floor)))
                .collect();
            chart
                .draw_series(series.iter().map(|&p| Circle::new(p, 5, colour.filled())))
                .map_err(|e| chart_error(e.to_string()))?
                .label(*knob)
                .legend(move |(x, y)| Circle::new((x + 10, y), 5, colour.filled()));
        }
        let mut front: Vec<(f64, f64)> = measured
            .iter()
            .filter(|r| r.pareto)
            .map(|r| (r.seconds.max(t_min), r.image_rmse.max(floor)))
            .collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart
            .draw_series(LineSeries::new(front.clone(), BLACK.stroke_width(2)))
            .map_err(|e| chart_error(e.to_string()))?
            .label("Pareto front")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(2)));
        chart
            .draw_series(
                front
                    .iter()
                    .map(|&p| Circle::new(p, 7, BLACK.stroke_width(2))),
            )
            .map_err(|e| chart_error(e.to_string()))?;
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| chart_error(e.to_string()))?;
        root.present().map_err(|e| chart_error(e.to_string()))?;
    }
    let image = image::RgbImage::from_raw(w, h, pixels).expect("buffer matches the chart size");
    crate::output::write_atomic(path, |w, _| {
        image
            .write_to(w, image::ImageFormat::Png)
            .map_err(|e| chart_error(e.to_string()))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

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
            de_evaluations: 0,
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
