//! How close the estimate's hits come to the set on every example, judged
//! by membership alone (`march::judge`): the 3D distance from each hit to
//! the set, and a scan of each ray for set it passed through before the hit.
//! Optional arguments set every scene's `hit_threshold`, `membership_step`,
//! `over_relaxation`, `refine_steps`, `confirm_hits` (1 or 0) and `fudge`.
//! The measurement behind docs/surface.md:
//! `cargo run --release --example surface` (one and a half to three minutes
//! on two cores).

use mandelreel::march::judge::{distance_to_set, past_the_set};
use mandelreel::march::march;
use mandelreel::math::Real;
use mandelreel::scene::Scene;
use mandelreel::timeline::Timeline;
use rayon::prelude::*;
use std::path::Path;

/// Uniform samples of each ball searched for the set around a hit.
const SAMPLES: usize = 50_000;
/// Uniform samples of each ball around a hit that `SAMPLES` put more than a
/// footprint from the set.
const SAMPLES_FAR: usize = 1_000_000;
/// The overshoot scan's step, in footprints.
const SCAN_STEP: Real = 1.0 / 64.0;

fn scene(path: &str, frame: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
    let timeline = Timeline::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    timeline.scene_at(frame)
}

fn measure(name: &str, path: &str, frame: u32) {
    let mut scene = scene(path, frame);
    let arg = |i: usize| {
        std::env::args()
            .nth(i)
            .map(|a| a.parse::<Real>().expect("a number"))
    };
    if let Some(threshold) = arg(1) {
        scene.quality.hit_threshold = threshold;
    }
    if let Some(step) = arg(2) {
        scene.quality.membership_step = step;
    }
    if let Some(omega) = arg(3) {
        scene.quality.over_relaxation = omega;
    }
    if let Some(steps) = arg(4) {
        scene.quality.refine_steps = steps as u32;
    }
    if let Some(confirm) = arg(5) {
        scene.quality.confirm_hits = confirm != 0.0;
    }
    if let Some(fudge) = arg(6) {
        scene.quality.fudge = fudge;
    }
    let camera = scene.camera.frame();
    let (w, h, every) = (160u32, 90u32, 6u32);
    let pixels: Vec<(u32, u32)> = (0..h)
        .step_by(every as usize)
        .flat_map(|y| (0..w).step_by(every as usize).map(move |x| (x, y)))
        .collect();
    let rows: Vec<(Option<Real>, Real)> = pixels
        .par_iter()
        .filter_map(|&(x, y)| {
            let ray = camera.ray(x as Real + 0.5, y as Real + 0.5, w, h);
            let hit = march(&ray, &scene.fractal, &scene.quality).hit?;
            let footprint = ray.footprint(hit.t);
            let seed = u64::from(y * w + x);
            // A sample of 50,000 can miss a sheet or speck thinner than its
            // spacing; where it finds nothing within a footprint, look again
            // with `SAMPLES_FAR`, as the bound tightens with samples.
            let near = distance_to_set(&scene.fractal, hit.point, footprint, SAMPLES, seed);
            let distance = match near {
                Some(d) if d <= 1.0 => near,
                _ => {
                    let far =
                        distance_to_set(&scene.fractal, hit.point, footprint, SAMPLES_FAR, seed);
                    near.into_iter().chain(far).reduce(Real::min)
                }
            };
            Some((
                distance,
                past_the_set(&scene.fractal, &scene.quality, &ray, hit.t, SCAN_STEP),
            ))
        })
        .collect();
    let mut distances: Vec<Real> = rows
        .iter()
        .map(|(d, _)| d.unwrap_or(Real::INFINITY))
        .collect();
    distances.sort_by(|a, b| a.total_cmp(b));
    if distances.is_empty() {
        println!("| {name} | 0 | | | | | |");
        return;
    }
    let n = distances.len();
    let share =
        |limit: Real| 100.0 * distances.iter().filter(|&&d| d <= limit).count() as Real / n as Real;
    let past: Vec<Real> = rows.iter().map(|&(_, p)| p).filter(|&p| p > 0.0).collect();
    let deepest = past.iter().copied().fold(0.0, Real::max);
    println!(
        "| {name} | {} | {:.0}% | {:.1}% | {:.2} | {:.2} | {} ({deepest:.2}) |",
        distances.len(),
        share(1.0),
        share(2.0),
        distances[n / 2],
        distances[n - 1],
        past.len(),
    );
}

fn main() {
    println!("| scene | hits | within 1 fp | within 2 fp | median (fp) | worst (fp) | hits past the set (deepest, fp) |");
    println!("|---|---:|---:|---:|---:|---:|---|");
    for frame in [0, 60, 100, 119] {
        measure(&format!("zoom {frame}"), "timelines/zoom.ron", frame);
    }
    for frame in [0, 40, 80, 143] {
        measure(
            &format!("julia_morph {frame}"),
            "timelines/julia_morph.ron",
            frame,
        );
    }
    for frame in [0, 48] {
        measure(
            &format!("quaternion {frame}"),
            "timelines/quaternion.ron",
            frame,
        );
    }
    for example in ["effects", "path_traced", "dof_motion_blur"] {
        measure(example, &format!("timelines/{example}.ron"), 0);
    }
    measure("S1", "timelines/bench/s1_plain.ron", 0);
    measure("S3 7", "timelines/bench/s3_zoom.ron", 7);
}
