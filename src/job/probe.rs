//! What a frame costs, measured: `info` renders frame 0 as thumbnails of
//! growing size, with and without its effects, counting the estimates.

use crate::job::warnings::iteration_weight;
use crate::render::FrameStats;
use crate::timeline::Timeline;
use std::time::Instant;

/// The side of the largest thumbnail `info` measures a frame's cost on.
pub const PROBE_SIDE: u32 = 64;
/// The most samples per pixel a thumbnail takes.
const PROBE_SAMPLES: u32 = 16;
/// Orbit iterations the first thumbnail may take at the very worst (every
/// march to its last step, every orbit to its last iteration): under a
/// second on one core.
const PROBE_WORST_ITERATIONS: u64 = 25_000_000;
/// Orbit iterations a larger thumbnail may be expected to take, from the
/// orbits the one before it took: about half a second on two cores.
const PROBE_ITERATIONS: u64 = 30_000_000;
/// Seconds a thumbnail may take, on all the pool's threads, for the next,
/// four times as large, to be rendered: where orbits are slower than their
/// weight says.
const PROBE_STAGE_SECONDS: f64 = 0.1;

/// Frame 0 rendered small by `cost_probe`, as declared (`with`) and with
/// every effect off.
pub struct Probe {
    pub width: u32,
    pub height: u32,
    pub samples: u32,
    pub with: FrameStats,
    pub without: FrameStats,
}

/// A frame's size scaled to fit in `side`×`side` pixels, aspect kept, at
/// least 1×1 (a tall, narrow frame makes a tall, narrow thumbnail, not a
/// 64-pixel-wide one thousands of pixels high).
pub fn thumbnail_size(width: u32, height: u32, side: u32) -> (u32, u32) {
    let long = width.max(height) as u64;
    let scale = |n: u32| ((n as u64 * side as u64) / long).max(1) as u32;
    (scale(width), scale(height))
}

/// `s` with the march steps its frame takes at `size`, which a deep
/// frame raises (`deep::steps_of`): at the film's size, the most it can.
pub fn deep_steps(s: &crate::scene::Scene, size: [u32; 2]) -> crate::scene::Scene {
    let mut s = s.clone();
    s.quality.max_steps = crate::deep::steps_of(&s, size);
    s
}

/// The most orbits one camera sample of `s` can compute: its march to the
/// last step and bisection (about 1 100 at most) and a normal; each
/// light's shadow march; every occlusion sample; each bounce's march,
/// normal and march towards each light. Gradient estimators take five
/// orbits an estimate; checking hits (`confirm_hits`) four more a step.
pub fn worst_orbits_per_sample(s: &crate::scene::Scene) -> u64 {
    // At most one check a step: a ray that failed one takes a step before
    // the next, and a bisected hit is not checked.
    let check = if s.quality.confirm_hits { 4 } else { 0 };
    let march = s.quality.max_steps as u64 * (1 + check) + 1_200 + 6;
    let lights = 1 + s.look.extra_lights.len() as u64;
    let e = &s.effects;
    let shadows = e
        .shadows
        .as_ref()
        .map_or(0, |sh| lights * sh.max_steps as u64);
    let occlusion = e
        .ambient_occlusion
        .as_ref()
        .map_or(0, |ao| ao.samples as u64);
    let bounces = e
        .path_tracing
        .as_ref()
        .map_or(0, |pt| pt.max_bounces as u64 * (1 + lights) * march);
    let orbits = match s.fractal.de {
        crate::fractal::DeMethod::Analytic | crate::fractal::DeMethod::Jacobian => 1,
        _ => 5,
    };
    (march + shadows + occlusion + bounces) * orbits
}

/// Frame 0 of `t` as thumbnails of growing size, so that `info` answers
/// at once whatever the timeline asks: the first small enough that even
/// its worst case stays within `PROBE_WORST_ITERATIONS`, then each twice
/// as wide while the orbits the last one took, scaled up, stay within
/// `PROBE_ITERATIONS`, up to `PROBE_SIDE`. None if one sample alone could
/// take more.
pub fn cost_probe(t: &Timeline) -> Option<Probe> {
    let mut samples = t.base.samples_per_pixel.min(PROBE_SAMPLES);
    let scenes = |samples: u32| t.clone().with_samples(Some(samples)).scenes_for_frame(0);
    let first = &scenes(1)[0];
    let iterations = first.fractal.iterations as u64 * iteration_weight(&first.fractal);
    let per_sample = worst_orbits_per_sample(&deep_steps(first, [t.width, t.height])) * iterations;
    let pixels = |side: u32| {
        let (w, h) = thumbnail_size(t.width, t.height, side);
        w as u64 * h as u64
    };
    let mut side = 8;
    while side > 1 && pixels(side) * samples as u64 * per_sample > PROBE_WORST_ITERATIONS {
        side /= 2;
    }
    while samples > 1 && samples as u64 * per_sample > PROBE_WORST_ITERATIONS {
        samples /= 2;
    }
    if per_sample > PROBE_WORST_ITERATIONS {
        return None;
    }
    // Frame 0's instants and iterations (a track may animate them) at the
    // thumbnail's samples.
    let scenes = scenes(samples);
    let iterations = scenes
        .iter()
        .map(|s| s.fractal.iterations as u64 * iteration_weight(&s.fractal))
        .max()?;
    let render = |scenes: &[crate::scene::Scene], side: u32| {
        let (w, h) = thumbnail_size(t.width, t.height, side);
        let mut film = crate::render::Film::default();
        let layers = crate::render::Layers::default();
        crate::render::render_frame_into(&mut film, scenes, 0, w, h, layers, &|| {});
        film.stats
    };
    let mut started = Stopwatch::start();
    let mut with = render(&scenes, side);
    while side < PROBE_SIDE {
        let grown = with.de_evaluations * pixels(side * 2) / pixels(side).max(1);
        let slow = started.seconds_per_thread() > PROBE_STAGE_SECONDS;
        if slow || grown.saturating_mul(iterations) > PROBE_ITERATIONS {
            break;
        }
        side *= 2;
        started = Stopwatch::start();
        with = render(&scenes, side);
    }
    let plain: Vec<_> = scenes
        .iter()
        .map(|s| crate::scene::Scene {
            effects: crate::shade::Effects {
                motion_blur: s.effects.motion_blur.clone(),
                ..Default::default()
            },
            ..s.clone()
        })
        .collect();
    let (width, height) = thumbnail_size(t.width, t.height, side);
    Some(Probe {
        width,
        height,
        samples,
        with,
        without: render(&plain, side),
    })
}

/// How long a thumbnail took: the processor time this process used, per
/// thread of the pool (a tiny thumbnail that leaves threads idle reads
/// short), so that other programs' load barely moves `info`'s thumbnail;
/// the wall clock where the system does not say.
struct Stopwatch {
    wall: Instant,
    cpu: Option<f64>,
}

impl Stopwatch {
    fn start() -> Stopwatch {
        Stopwatch {
            wall: Instant::now(),
            cpu: crate::host::cpu_seconds(),
        }
    }

    fn seconds_per_thread(&self) -> f64 {
        match (self.cpu, crate::host::cpu_seconds()) {
            (Some(then), Some(now)) => (now - then) / rayon::current_num_threads() as f64,
            _ => self.wall.elapsed().as_secs_f64(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cost_thumbnails_keep_the_aspect_within_64_pixels_a_side() {
        // A tall, narrow frame's thumbnail is 64 high, not 64 wide and
        // two million high: no frame's has more than 64×64 pixels.
        assert_eq!(thumbnail_size(320, 180, 64), (64, 36));
        assert_eq!(thumbnail_size(48, 27, 64), (64, 36));
        assert_eq!(thumbnail_size(1, 32_768, 64), (1, 64));
        assert_eq!(thumbnail_size(1, 135, 64), (1, 64));
        assert_eq!(thumbnail_size(32_768, 1, 8), (8, 1));
        for (w, h) in [(1, 1), (3, 32_768), (32_768, 32_768), (777, 5)] {
            let (tw, th) = thumbnail_size(w, h, PROBE_SIDE);
            assert!((1..=PROBE_SIDE).contains(&tw) && (1..=PROBE_SIDE).contains(&th));
        }
    }

    #[test]
    fn checking_hits_adds_four_orbits_a_step_to_the_worst_case_and_none_to_bisection() {
        let mut s = crate::scene::Scene::default();
        s.effects.path_tracing = None;
        let off = worst_orbits_per_sample(&s);
        s.quality.confirm_hits = true;
        let on = worst_orbits_per_sample(&s);
        assert_eq!(on - off, 4 * s.quality.max_steps as u64);
    }
}
