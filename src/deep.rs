//! Frames deeper than f64 resolves: which frames need perturbation, and the
//! scene such a frame renders as. A deep frame is measured from its
//! target (its anchor): the camera stands at its offset from the target,
//! every point the marcher visits is a small f64 offset from the anchor,
//! and the fractal's estimates follow a reference orbit iterated from the
//! anchor in high precision (`fractal::deep`). Frames that f64 resolves
//! render as they always have.

use crate::exact::big_point;
use crate::fractal::deep::Reference;
use crate::math::Real;
use crate::scene::Scene;
use std::sync::Arc;

/// A frame is deep where a pixel at its target is narrower than this share
/// of the target's coordinates: 2¹⁶ times f64's resolution there, so that
/// normals (differences of estimates half a pixel apart) keep 4 digits.
pub const DEEP_BELOW: Real = 1.0 / (1u64 << 36) as Real;

/// The least precision of a reference orbit, in bits.
const MIN_BITS: usize = 128;

/// The width of a pixel at the target, at `height` rows.
pub fn footprint(scene: &Scene, height: u32) -> Real {
    let c = &scene.camera;
    let pixel_angle = 2.0 * (c.fov_degrees.to_radians() * 0.5).tan() / height.max(1) as Real;
    c.relative_position().length() * pixel_angle
}

/// A pixel's width at the target over the size of the target's coordinates.
pub fn resolution(scene: &Scene, height: u32) -> Real {
    let size = scene
        .camera
        .target
        .abs()
        .max_element()
        .max(Real::MIN_POSITIVE);
    footprint(scene, height) / size
}

/// Whether the frame of `scene` at `height` rows is deep (`DEEP_BELOW`).
pub fn needed(scene: &Scene, height: u32) -> bool {
    resolution(scene, height) < DEEP_BELOW
}

/// The precision a deep frame's reference orbit takes: the target's
/// digits down to a pixel, and 64 bits more for the orbit's own rounding.
pub fn bits(scene: &Scene, height: u32) -> usize {
    let below = -resolution(scene, height).log2();
    (64 + below.max(0.0).ceil() as usize + 32).max(MIN_BITS)
}

/// The scene that frame renders as, where it is deep: measured from its
/// target, with the reference orbit set. `None` for a frame f64 resolves,
/// and for powers that are not whole, which perturbation does not cover
/// (they render in f64, and `info` says so).
pub fn prepare(scene: &Scene, height: u32) -> Option<Scene> {
    if !needed(scene, height) {
        return None;
    }
    let bits = bits(scene, height);
    let c = &scene.camera;
    let anchor = big_point(c.target, c.target_digits.as_ref(), bits);
    let reference = Reference::new(&scene.fractal, anchor, bits)?;
    let mut deep = scene.clone();
    deep.quality.centre = -reference.anchor;
    deep.camera.position = c.relative_position();
    deep.camera.target = crate::math::DVec3::ZERO;
    (deep.camera.position_digits, deep.camera.target_digits) = (None, None);
    deep.camera.offset = None;
    deep.fractal.deep = Some(Arc::new(reference));
    Some(deep)
}

/// `scenes` (a frame's instants) as they render at `height` rows: `None`
/// where none is deep, so the caller keeps its own.
pub fn prepare_all(scenes: &[Scene], height: u32) -> Option<Vec<Scene>> {
    let prepared: Vec<Option<Scene>> = scenes.iter().map(|s| prepare(s, height)).collect();
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
