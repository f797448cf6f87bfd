//! The converged reference: the scene with every marching knob set high, and
//! hit depths found by membership stepping, which trusts no distance estimate.

use crate::fractal::{DeMethod, Precision};
use crate::march::march_by_membership;
use crate::math::Real;
use crate::scene::Scene;
use rayon::prelude::*;
use serde::Serialize;

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
    r.quality.confirm_hits = false;
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
    let min_step = 1e-6 * scene.camera.distance();
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
}
