//! Where hits land against the membership crossing, and how that crossing
//! moves with the resolution it is looked for at: the measurement behind
//! docs/surface.md. Not run by default (half a minute in release):
//! `cargo test --release --test it -- --ignored surface_against_membership --nocapture`.

use mandelreel::march::{march, Ray};
use mandelreel::math::{DVec3, Real};
use mandelreel::scene::Scene;
use mandelreel::timeline::Timeline;
use std::path::Path;

/// Steps of the membership references, in footprints.
const REFERENCES: [Real; 3] = [1.0 / 16.0, 1.0 / 64.0, 1.0 / 256.0];
/// Walk steps measured (0 trusts the estimate).
const WALKS: [Real; 4] = [0.0, 0.125, 0.5, 2.0];

fn scene(path: &str, frame: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
    let text = std::fs::read_to_string(&path).unwrap();
    Timeline::parse(&text, &path).unwrap().scene_at(frame)
}

/// The first point of the set along `ray` in steps of `step` footprints,
/// from `from` (before which the estimate, a lower bound, saw nothing).
fn crossing(scene: &Scene, ray: &Ray, from: Real, step: Real) -> Option<Real> {
    let mut t = from;
    for _ in 0..4_000_000 {
        let next = t + step * ray.footprint(t);
        if scene.fractal.contains(ray.at(next)) {
            return Some(next);
        }
        if next > 100.0 {
            return None;
        }
        t = next;
    }
    None
}

/// Whether a point of the set lies within `radius` of `p`, by 4000 samples
/// of the ball (finds what is thicker than about a thousandth of it).
fn set_within(scene: &Scene, p: DVec3, radius: Real, seed: u64) -> bool {
    let mut state = seed | 1;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as Real / (1u64 << 53) as Real * 2.0 - 1.0
    };
    (0..4000).any(|_| {
        let q = DVec3::new(next(), next(), next());
        q.length() <= 1.0 && scene.fractal.contains(p + q * radius)
    })
}

#[derive(Default)]
struct Tally {
    errors: Vec<Real>,
    past: usize,
}

impl Tally {
    fn add(&mut self, hit: Real, crossing: Real, footprint: Real) {
        let e = (hit - crossing) / footprint;
        self.past += (e > 1.0) as usize;
        self.errors.push(e.abs());
    }

    fn row(&mut self) -> String {
        self.errors.sort_by(|a, b| a.total_cmp(b));
        let n = self.errors.len().max(1);
        let mean = self.errors.iter().sum::<Real>() / n as Real;
        let p99 = self.errors.get(n * 99 / 100).copied().unwrap_or(0.0);
        let past = 100.0 * self.past as Real / n as Real;
        format!("{mean:.1} / {p99:.0} / {past:.1}%")
    }
}

fn measure(name: &str, path: &str, frame: u32) {
    let scene = scene(path, frame);
    let camera = scene.camera.frame();
    let (w, h) = (160u32, 90u32);
    let mut tallies: Vec<Vec<Tally>> = WALKS
        .iter()
        .map(|_| REFERENCES.iter().map(|_| Tally::default()).collect())
        .collect();
    let mut evaluations = vec![0u64; WALKS.len()];
    let (mut pixels, mut near) = (0usize, 0usize);
    for y in (0..h).step_by(4) {
        for x in (0..w).step_by(4) {
            let ray = camera.ray(x as Real + 0.5, y as Real + 0.5, w, h);
            let hits: Vec<Option<Real>> = WALKS
                .iter()
                .zip(&mut evaluations)
                .map(|(&step, spent)| {
                    let mut quality = scene.quality.clone();
                    quality.membership_step = step;
                    let m = march(&ray, &scene.fractal, &quality);
                    *spent += m.evaluations as u64;
                    m.hit.map(|h| h.t)
                })
                .collect();
            let Some(trusted) = hits[0] else { continue };
            pixels += 1;
            let footprint = ray.footprint(trusted);
            near += set_within(&scene, ray.at(trusted), footprint, pixels as u64) as usize;
            for (j, &step) in REFERENCES.iter().enumerate() {
                let Some(c) = crossing(&scene, &ray, 0.5 * trusted, step) else {
                    continue;
                };
                for (i, hit) in hits.iter().enumerate() {
                    if let Some(t) = hit {
                        tallies[i][j].add(*t, c, ray.footprint(c));
                    }
                }
            }
        }
    }
    println!(
        "\n{name}: {pixels} pixels hit; a point of the set within 1 footprint of the trusted hit: {:.1}%",
        100.0 * near as Real / pixels.max(1) as Real
    );
    for (i, step) in WALKS.iter().enumerate() {
        let cells: Vec<String> = tallies[i].iter_mut().map(Tally::row).collect();
        println!(
            "| {name} | {step} | {:.1} | {} |",
            evaluations[i] as Real / (w / 4 * h.div_ceil(4)) as Real,
            cells.join(" | ")
        );
    }
}

#[test]
#[ignore = "measurement for docs/surface.md"]
fn surface_against_membership() {
    for frame in [0, 60, 100, 119] {
        measure(&format!("zoom {frame}"), "timelines/zoom.ron", frame);
    }
    for frame in [0, 40, 80] {
        measure(
            &format!("julia_morph {frame}"),
            "timelines/julia_morph.ron",
            frame,
        );
    }
    for example in ["effects", "path_traced", "dof_motion_blur"] {
        measure(example, &format!("timelines/{example}.ron"), 0);
    }
    measure("S1", "timelines/bench/s1_plain.ron", 0);
}
