//! Frames deeper than their arithmetic resolves: which frames need
//! perturbation, which asked for f32 but need f64, and the scene such a
//! frame renders as. A deep frame is measured from its
//! target (its anchor): the camera stands at its offset from the target,
//! every point the marcher visits is a small f64 offset from the anchor,
//! and the fractal's estimates follow a reference orbit iterated from the
//! anchor in high precision (`fractal::deep`). Frames that f64 resolves
//! render as they always have.

use crate::camera::Camera;
use crate::exact::{big_from_f64, big_point, decimal, Digits};
pub use crate::fractal::deep::Derivative;
use crate::fractal::deep::Reference;
use crate::fractal::Fractal;
use crate::math::{DVec3, Real};
use crate::scene::Scene;
use std::collections::VecDeque;
use std::sync::{Arc, Mutex, OnceLock};

/// A frame is deep where a pixel at its target is narrower than this share
/// of the target's coordinates (`F64_RESOLVES`).
pub use crate::fractal::deep::F64_RESOLVES as DEEP_BELOW;

/// A frame asking for f32 whose pixel at its target is finer than this
/// share of the target's coordinates renders in f64. Against f64 on
/// zoom.ron's target (160×90, 20 iterations) f32 frames keep 45 dB at
/// 1.6e-5 and fall to 34 dB at 1.6e-6 and 21 dB at 5e-7, as speckle.
pub const F32_RESOLVES: Real = 1.0 / (1u64 << 16) as Real;

/// Whether the frame of `scene` at `size` asks for f32 where f32 cannot
/// resolve its pixels (`F32_RESOLVES`), so it renders in f64.
pub fn f32_too_coarse(scene: &Scene, size: [u32; 2]) -> bool {
    scene.fractal.precision == crate::fractal::Precision::F32
        && resolution(scene, size) < F32_RESOLVES
}

/// Whether the frame of `scene` at `size` renders in f32: asked for, and
/// not finer than f32 resolves.
pub fn renders_in_f32(scene: &Scene, size: [u32; 2]) -> bool {
    scene.fractal.precision == crate::fractal::Precision::F32 && !f32_too_coarse(scene, size)
}

/// The closest a camera may come to its target: a frame's offsets are f64,
/// whose normal range ends at 2.2e-308, and a pixel there must keep a few
/// decades above that for its sub-pixel steps (normals, hit thresholds).
pub const DEEPEST: Real = 1e-302;

/// Steps a deep frame's rays get for each decade of its depth, over
/// `quality.max_steps`: a ray passing just by a structure steps a fixed
/// share of its distance from it, so crossing from a pixel's scale to the
/// bulb's takes steps in proportion to the decades between (`deep_zoom.ron`
/// needed about 1000 in all at 1e-30, and 4000 at 1e-100).
const STEPS_PER_DECADE: Real = 40.0;

/// `quality.max_steps` for a deep frame: the scene's own, and
/// `STEPS_PER_DECADE` for every decade of the target's size over a pixel.
pub fn max_steps(scene: &Scene, size: [u32; 2]) -> u32 {
    let decades = (1.0 / resolution(scene, size)).log10().clamp(0.0, 400.0);
    let more = (STEPS_PER_DECADE * decades).ceil() as u32;
    scene.quality.max_steps.saturating_add(more)
}

/// The march steps the frame of `scene` at `size` takes: `max_steps`
/// where it renders deep (needed, and a whole power), else the scene's own.
pub fn steps_of(scene: &Scene, size: [u32; 2]) -> u32 {
    let perturbed = needed(scene, size)
        && scene.fractal.perturbation
        && crate::fractal::whole_power(scene.fractal.power).is_some();
    if perturbed {
        max_steps(scene, size)
    } else {
        scene.quality.max_steps
    }
}

/// The hash a deep frame's file adds to its scene's: what rendering it by
/// perturbation means changes with it, as `RENDERER_REVISION` does for all.
pub const DEEP_REVISION: u32 = 3;

/// The least precision of a reference orbit, in bits.
const MIN_BITS: usize = 128;

/// The width of a pixel at the target in a `size` (width, height) image:
/// the angle the projection gives the view axis's pixel, at the target's
/// distance.
pub fn footprint(scene: &Scene, size: [u32; 2]) -> Real {
    let c = &scene.camera;
    c.distance() * c.axis_pixel_angle(size)
}

/// A pixel's width at the target over the size of the target's coordinates.
pub fn resolution(scene: &Scene, size: [u32; 2]) -> Real {
    let extent = scene
        .camera
        .target
        .abs()
        .max_element()
        .max(Real::MIN_POSITIVE);
    footprint(scene, size) / extent
}

/// Whether the frame of `scene` at `size` is deep (`DEEP_BELOW`).
pub fn needed(scene: &Scene, size: [u32; 2]) -> bool {
    resolution(scene, size) < DEEP_BELOW
}

/// The precision a deep frame's reference orbit takes: the target's
/// digits down to a pixel, and 64 bits more for the orbit's own rounding.
pub fn bits(scene: &Scene, size: [u32; 2]) -> usize {
    let below = -resolution(scene, size).log2();
    // A resolution of 0 (validation keeps frames from it) would ask for ∞.
    (64 + below.clamp(0.0, 2048.0).ceil() as usize + 32).max(MIN_BITS)
}

/// The scene that frame renders as, where it is deep: measured from its
/// target, with the reference orbit set. `None` for a frame f64 resolves,
/// and for powers that are not whole, which perturbation does not cover
/// (they render in f64, and `info` says so).
pub fn prepare(scene: &Scene, size: [u32; 2]) -> Option<Scene> {
    prepare_with(scene, size, &References::default())
}

/// The scene a frame of `scene` at `size` renders as where it asks for f32
/// and f32 cannot resolve it (`f32_too_coarse`): the same in f64.
pub fn in_f64(scene: &Scene, size: [u32; 2]) -> Option<Scene> {
    f32_too_coarse(scene, size).then(|| {
        let mut f64 = scene.clone();
        f64.fractal.precision = crate::fractal::Precision::F64;
        f64
    })
}

/// `prepare`, taking the reference from `references` where one there has
/// the same target, fractal and precision (a motion-blurred frame's
/// instants, a film's frames at one precision), and adding the one it
/// builds.
pub fn prepare_with(scene: &Scene, size: [u32; 2], references: &References) -> Option<Scene> {
    if !needed(scene, size) || !scene.fractal.perturbation {
        return None;
    }
    let bits = bits(scene, size);
    let c = &scene.camera;
    let reference = references.get(&scene.fractal, c, bits)?;
    let mut deep = scene.clone();
    deep.quality.centre = -reference.anchor;
    deep.quality.max_steps = max_steps(scene, size);
    deep.camera.position = c.relative_position();
    deep.camera.target = DVec3::ZERO;
    (deep.camera.position_digits, deep.camera.target_digits) = (None, None);
    deep.camera.offset = None;
    deep.fractal.deep = Some(reference);
    // f32's range ends near 1e-38, and the offsets are what carry the depth.
    deep.fractal.precision = crate::fractal::Precision::F64;
    Some(deep)
}

/// Reference orbits already followed, by fractal, target and precision,
/// shared by clones: in planning, the frames of a film at one precision (a
/// deep zoom's for a third of a decade or so) share one, and in rendering,
/// a frame's instants do, so each high-precision orbit is followed once.
#[derive(Clone, Debug, Default)]
pub struct References(Arc<Mutex<VecDeque<Followed>>>);

/// One reference orbit and what it was followed from (`None` where the
/// power is not whole, or until the thread that first asked has followed
/// it: others asking meanwhile wait rather than follow it too).
#[derive(Debug)]
struct Followed {
    fractal: Fractal,
    target: DVec3,
    target_digits: Option<Digits>,
    bits: usize,
    reference: Arc<OnceLock<Option<Arc<Reference>>>>,
}

/// The references kept for each thread, the oldest dropped first: a
/// thread takes a film's frames in order, and each precision's run of
/// them in turn, so a few each hold every one still asked for, and no
/// more than a few times what the threads hold at once (a non-escaping
/// orbit of 2000 points is a megabyte). Past `KEPT_THREADS` threads the
/// total stays put: a miss costs a recomputation, never memory.
const KEPT_PER_THREAD: usize = 4;
const KEPT_THREADS: usize = 8;

impl References {
    /// The reference orbit of `fractal` from `camera`'s target in `bits`:
    /// followed once, then kept.
    fn get(&self, fractal: &Fractal, camera: &Camera, bits: usize) -> Option<Arc<Reference>> {
        let same = |f: &&Followed| {
            f.bits == bits
                && f.fractal == *fractal
                && f.target == camera.target
                && f.target_digits == camera.target_digits
        };
        let slot = {
            // A panic elsewhere while holding the lock leaves whole entries.
            let mut followed = self.0.lock().unwrap_or_else(|e| e.into_inner());
            match followed.iter().find(same) {
                Some(f) => f.reference.clone(),
                None => {
                    if followed.len()
                        >= KEPT_PER_THREAD * rayon::current_num_threads().min(KEPT_THREADS)
                    {
                        followed.pop_front();
                    }
                    let slot = Arc::new(OnceLock::new());
                    followed.push_back(Followed {
                        fractal: fractal.clone(),
                        target: camera.target,
                        target_digits: camera.target_digits.clone(),
                        bits,
                        reference: slot.clone(),
                    });
                    slot
                }
            }
        };
        // Followed outside the lock, so other references are not held up.
        slot.get_or_init(|| {
            let anchor = big_point(camera.target, camera.target_digits.as_ref(), bits);
            Reference::new(fractal, anchor, bits).map(Arc::new)
        })
        .clone()
    }
}

/// The scene a frame of `scene` at `size` renders as, where it differs:
/// deep (`prepare_with`; its fractal then has `deep` set), or in f64 in
/// place of f32 (`in_f64`).
pub fn rendered(scene: &Scene, size: [u32; 2], references: &References) -> Option<Scene> {
    prepare_with(scene, size, references).or_else(|| in_f64(scene, size))
}

/// `scenes` (a frame's instants) as they render at `size` (`rendered`):
/// `None` where each renders as it is, so the caller keeps its own.
/// Instants that share a target and fractal share one reference orbit.
pub fn prepare_all(scenes: &[Scene], size: [u32; 2]) -> Option<Vec<Scene>> {
    let references = References::default();
    let prepared: Vec<Option<Scene>> = scenes
        .iter()
        .map(|s| rendered(s, size, &references))
        .collect();
    if prepared.iter().all(Option::is_none) {
        return None;
    }
    Some(
        prepared
            .into_iter()
            .zip(scenes)
            .map(|(deep, scene)| deep.unwrap_or_else(|| scene.clone()))
            .collect(),
    )
}

/// The world position of a point `local` to the frame of `scene` (measured
/// from the target where `deep`, as `prepare` measures it, else the world
/// itself), as decimal digits: `significant` of them.
pub fn world_digits(scene: &Scene, deep: bool, local: DVec3, significant: usize) -> [String; 3] {
    let bits = significant * 4 + 64;
    let c = &scene.camera;
    let base = if deep {
        big_point(c.target, c.target_digits.as_ref(), bits)
    } else {
        big_point(DVec3::ZERO, None, bits)
    };
    [0, 1, 2].map(|i| decimal(&(&base[i] + &big_from_f64(local[i], bits)), significant))
}

/// Significant digits that place a point of size `size` to a thousandth
/// of `footprint`: at least 12.
pub fn digits_for(size: Real, footprint: Real) -> usize {
    let decades = (size.max(Real::MIN_POSITIVE) / footprint.max(Real::MIN_POSITIVE)).log10();
    (decades.max(0.0).ceil() as usize + 4).max(12)
}

/// Iterations that resolve detail down to a pixel at the target: those
/// after which the running derivative of the target's own orbit (computed
/// from its high-precision reference, up to `MOST_ITERATIONS`) passes one
/// over the pixel's width, since the finest detail an iteration count draws
/// is about 1/dr; or what the target's orbit does instead. `None` for a
/// power that is not whole.
pub fn iterations_for(scene: &Scene, size: [u32; 2]) -> Option<Derivative> {
    iterations_with(scene, size, &References::default())
}

/// `iterations_for`, following the orbit once for every frame of
/// `references` at the same precision.
pub fn iterations_with(
    scene: &Scene,
    size: [u32; 2],
    references: &References,
) -> Option<Derivative> {
    let mut probe = scene.fractal.clone();
    probe.iterations = MOST_ITERATIONS;
    let reference = references.get(&probe, &scene.camera, bits(scene, size))?;
    Some(reference.derivative_passes(&probe, 1.0 / footprint(scene, size)))
}

/// How far `iterations_for` looks.
const MOST_ITERATIONS: u32 = 2000;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Projection;

    /// A scene looking down −z at the bulb's tip from `distance`.
    fn scene(projection: Projection, distance: Real) -> Scene {
        let mut s = Scene::default();
        s.camera.target = DVec3::new(0.0, 0.65, 0.0);
        s.camera.position = s.camera.target + DVec3::new(0.0, 0.0, distance);
        s.camera.projection = projection;
        s
    }

    #[test]
    fn a_fisheyes_footprint_is_its_own_pixel_angle_at_the_target() {
        let (distance, size) = (1e-3, [64, 48]);
        let fisheye = scene(Projection::Fisheye { degrees: 180.0 }, distance);
        // 180° over the inscribed circle's 48-pixel diameter.
        let want = std::f64::consts::PI / 48.0 * distance;
        let got = footprint(&fisheye, size);
        assert!((got - want).abs() < 1e-15 * want, "{got} vs {want}");
        let pinhole = footprint(&scene(Projection::Perspective, distance), size);
        assert!(
            (pinhole - want).abs() > 0.1 * want,
            "{pinhole} is the perspective's"
        );
    }

    #[test]
    fn which_frames_are_deep_follows_the_projection() {
        // At this depth a 45° perspective's pixel is below `DEEP_BELOW`
        // of the target, an equirectangular's (360° across) is not.
        let size = [64, 32];
        let distance = 0.65 * DEEP_BELOW * 32.0 / (2.0 * (22.5f64).to_radians().tan()) * 0.9;
        assert!(needed(&scene(Projection::Perspective, distance), size));
        let equirect = scene(Projection::Equirectangular, distance);
        assert!(!needed(&equirect, size));
        // Deeper, where precision is above its floor, it takes fewer bits.
        let deeper = |p| bits(&scene(p, distance * 1e-20), size);
        assert!(deeper(Projection::Equirectangular) < deeper(Projection::Perspective));
    }
}
