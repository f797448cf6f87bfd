//! `fractal.iterations: Auto`: each frame's count, chosen from its scene
//! alone where the scene is made, so every command (render, info, pick,
//! accuracy, the explorer) and every thread and resume sees the same. The
//! finest detail an orbit of k iterations draws is about 1/|dr_k|, so the
//! count is where |dr| first passes one over a pixel's width: at the
//! target, or where the target is not on the surface at this depth, at the
//! surface under the centre ray; and the user's margin more.

use crate::deep::{self, Derivative};
use crate::fractal::{AutoIterations, MAX_ITERATIONS};
use crate::math::Real;
use crate::scene::Scene;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

/// The fewest iterations `Auto` chooses: below this the bulb has not yet
/// taken its shape (at 3 it is a lumpy ball), whatever a pixel resolves.
pub const MIN_AUTO_ITERATIONS: u32 = 6;

/// How far the target's orbit is followed (as `deep::iterations_for`).
const MOST_ITERATIONS: u32 = 2000;

/// The orbit length the centre ray is marched with: generous, so the
/// surface it meets is the fractal's at any depth f64 reaches.
const CENTRE_ITERATIONS: u32 = 256;

/// What decided a frame's count.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Decided {
    /// The target's own orbit resolves a pixel.
    Target,
    /// The surface the centre ray meets does (the target is off the
    /// surface at this depth).
    Centre,
    /// Neither: the centre ray misses, and the floor holds.
    Floor,
}

impl Decided {
    pub fn name(self) -> &'static str {
        match self {
            Decided::Target => "target",
            Decided::Centre => "centre surface",
            Decided::Floor => "floor (nothing resolved)",
        }
    }
}

/// A frame's chosen count and what decided it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Resolved {
    pub count: u32,
    pub decided: Decided,
}

/// The count `auto` chooses for `scene` at `width`×`height`.
pub fn resolve(scene: &Scene, auto: AutoIterations, size: [u32; 2]) -> Resolved {
    resolve_with(scene, auto, size, &deep::References::default())
}

/// `resolve`, sharing the high-precision orbits of deep frames through
/// `references` with the other frames at the same precision.
fn resolve_with(
    scene: &Scene,
    auto: AutoIterations,
    size: [u32; 2],
    references: &deep::References,
) -> Resolved {
    let (passes, decided) = match target_passes(scene, size, references) {
        Derivative::Passes(n) => (Some(n), Decided::Target),
        _ => match centre_passes(scene, size, references) {
            Some(n) => (Some(n), Decided::Centre),
            None => (None, Decided::Floor),
        },
    };
    let count = passes
        .unwrap_or(0)
        .saturating_add(auto.margin)
        .clamp(MIN_AUTO_ITERATIONS, MAX_ITERATIONS);
    Resolved { count, decided }
}

/// What the target's orbit does at `scene`'s pixels (`target_passes`):
/// a target on the surface has a derivative that passes one over a pixel.
pub fn target_derivative(scene: &Scene, size: [u32; 2]) -> Derivative {
    target_passes(scene, size, &deep::References::default())
}

/// Where the target's orbit's derivative passes one over the pixel's
/// width at the target (the projection's pixel on the view's axis): in
/// high precision where the frame is deep.
fn target_passes(scene: &Scene, size: [u32; 2], references: &deep::References) -> Derivative {
    if deep::needed(scene, size) {
        if let Some(d) = deep::iterations_with(scene, size, references) {
            return d;
        }
    }
    let value = 1.0 / deep::footprint(scene, size);
    let f = &scene.fractal;
    f.derivative_passes(scene.camera.target, value, MOST_ITERATIONS)
}

/// Where the derivative passes one over a pixel at the surface the centre
/// ray meets, marched with `CENTRE_ITERATIONS` and four times the frame's
/// steps; `None` where it meets none. A deep frame's hit is a small offset
/// from the target that f64 cannot iterate alone: there the iterations its
/// orbit took to escape stand in (at a hit, within half a pixel of the
/// surface, the derivative has passed one over a pixel by its escape).
fn centre_passes(scene: &Scene, size: [u32; 2], references: &deep::References) -> Option<u32> {
    let mut probe = scene.clone();
    probe.fractal.iterations = CENTRE_ITERATIONS;
    probe.quality.max_steps = deep::steps_of(scene, size).saturating_mul(4);
    // Marched as the frame renders: deep, or in f64 in place of f32.
    let rendered = deep::rendered(&probe, size, references);
    let marched = rendered.as_ref().unwrap_or(&probe);
    // One eye's centre: a stereo image's centre is where its eyes meet.
    let [width, height] = scene.camera.eye_size(size);
    let mono = crate::camera::Camera {
        stereo: None,
        ..marched.camera.clone()
    };
    let (w, h) = (width as Real, height as Real);
    let ray = mono.frame().ray(w * 0.5, h * 0.5, width, height);
    let hit = crate::march::march(&ray, &marched.fractal, &marched.quality).hit?;
    if marched.fractal.deep.is_some() {
        return Some(hit.estimate.iterations);
    }
    let value = 1.0 / ray.footprint(hit.t);
    match probe
        .fractal
        .derivative_passes(hit.point, value, MOST_ITERATIONS)
    {
        Derivative::Passes(n) | Derivative::Escapes(n) => Some(n),
        Derivative::Stays => None,
    }
}

/// Each frame's resolved count, kept by the timeline so that a frame's
/// high-precision orbit is followed once however often its scene is made
/// (validation, the plan, hashes, `info`): a thread that asks while
/// another resolves the same instant waits for its answer.
#[derive(Clone, Debug, Default)]
pub(super) struct Counts {
    /// By frame index: a long film's frames are looked up by every pass
    /// over it, in order, without a lock or a hash.
    frames: Arc<[OnceLock<Resolved>]>,
    /// Instants of no frame of the film (before it, or after its end),
    /// by their time's bits.
    others: Arc<Mutex<HashMap<u64, Arc<OnceLock<Resolved>>>>>,
}

impl Counts {
    /// Room for the counts of `frame_count` frames.
    pub(super) fn new(frame_count: u32) -> Counts {
        Counts {
            frames: (0..frame_count).map(|_| OnceLock::new()).collect(),
            others: Default::default(),
        }
    }

    /// The count at time `time_seconds`, frame `frame_index`'s own time
    /// where given, whose scene is `scene`: resolved once (sharing orbits
    /// through `references`), then kept.
    pub(super) fn at(
        &self,
        (time_seconds, frame_index): (Real, Option<usize>),
        scene: &Scene,
        auto: AutoIterations,
        size: [u32; 2],
        references: &deep::References,
    ) -> Resolved {
        let resolve = || resolve_with(scene, auto, size, references);
        if let Some(slot) = frame_index.and_then(|i| self.frames.get(i)) {
            return *slot.get_or_init(resolve);
        }
        let slot = {
            // A panic elsewhere while holding the lock leaves whole entries.
            let mut others = self.others.lock().unwrap_or_else(|e| e.into_inner());
            others.entry(time_seconds.to_bits()).or_default().clone()
        };
        *slot.get_or_init(resolve)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DVec3;

    /// On the y axis Quilez's power-8 map sends y to y⁸ (θ is 0 or π, and
    /// 8θ a whole turn): the orbit of (0, c, 0) is y ↦ y⁸ + c and its
    /// derivative dr ↦ 8|y|⁷·dr + 1, iterated here apart from the kernel.
    fn axis_passes(c: Real, footprint: Real, bailout: Real) -> u32 {
        let (mut y, mut dr) = (c, 1.0);
        for i in 0.. {
            if dr * footprint >= 1.0 {
                return i;
            }
            assert!(y.abs() <= bailout, "the test's orbit escapes first");
            dr = 8.0 * y.abs().powi(7) * dr + 1.0;
            y = y.powi(8) + c;
        }
        unreachable!()
    }

    #[test]
    fn auto_is_where_the_targets_derivative_resolves_a_pixel_plus_the_margin() {
        let (width, height) = (64, 48);
        for (c, distance, margin) in [(0.66, 0.5, 2), (0.6505, 0.01, 0), (0.7, 2.0, 5)] {
            let mut scene = Scene::default();
            scene.camera.target = DVec3::new(0.0, c, 0.0);
            scene.camera.position = scene.camera.target + DVec3::new(0.0, 0.0, distance);
            let pixel = 2.0 * (scene.camera.fov_degrees.to_radians() / 2.0).tan() / height as Real;
            let passes = axis_passes(c, distance * pixel, scene.fractal.bailout);
            let auto = AutoIterations { margin };
            let r = resolve(&scene, auto, [width, height]);
            assert_eq!(r.decided, Decided::Target, "c = {c}");
            let want = (passes + margin).max(MIN_AUTO_ITERATIONS);
            assert_eq!(r.count, want, "c = {c}, passes at {passes}");
            assert!(
                passes + margin > MIN_AUTO_ITERATIONS,
                "the floor decides c = {c}"
            );
        }
    }

    #[test]
    fn a_fisheyes_count_resolves_its_own_pixel() {
        // 180° across a 48-row circle: π/48 a pixel, not the perspective's.
        let (c, distance) = (0.6505, 0.01);
        let mut scene = Scene::default();
        scene.camera.target = DVec3::new(0.0, c, 0.0);
        scene.camera.position = scene.camera.target + DVec3::new(0.0, 0.0, distance);
        scene.camera.projection = crate::camera::Projection::Fisheye { degrees: 180.0 };
        let pixel = std::f64::consts::PI / 48.0;
        let passes = axis_passes(c, distance * pixel, scene.fractal.bailout);
        let r = resolve(&scene, AutoIterations { margin: 0 }, [64, 48]);
        assert_eq!(r.decided, Decided::Target);
        assert_eq!(r.count, passes.max(MIN_AUTO_ITERATIONS));
    }

    #[test]
    fn a_target_inside_the_set_takes_the_surface_under_the_centre_ray() {
        // The origin's orbit stays at 0: its derivative never grows.
        let mut scene = Scene::default();
        scene.camera.target = DVec3::ZERO;
        scene.camera.position = DVec3::new(0.0, 0.0, 3.0);
        let r = resolve(&scene, AutoIterations { margin: 1 }, [64, 48]);
        assert_eq!(r.decided, Decided::Centre);
    }
}
