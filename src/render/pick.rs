//! The world-space point that the ray through one pixel hits: one camera
//! ray marched against one frame's fractal, for choosing a zoom target.

use crate::march::{march, normal};
use crate::scene::Scene;
use serde::Serialize;

/// What the ray through one pixel meets, as `pick --json` prints it.
#[derive(Serialize)]
pub struct Pick {
    pub frame: u32,
    pub pixel: [u32; 2],
    pub size: [u32; 2],
    pub ray_origin: [f64; 3],
    pub ray_direction: [f64; 3],
    pub hit: bool,
    pub point: Option<[f64; 3]>,
    pub distance: Option<f64>,
    pub normal: Option<[f64; 3]>,
    /// Width of the pixel's cone at the hit, or at the far side of the
    /// bounding sphere; none where the ray misses the sphere.
    pub pixel_footprint: Option<f64>,
    pub fractal: PickFractal,
}

/// The fractal the ray was marched against.
#[derive(Serialize)]
pub struct PickFractal {
    pub formula: &'static str,
    pub power: f64,
    pub iterations: u32,
    pub bailout: f64,
    pub julia: Option<[f64; 3]>,
}

/// Marches the ray through the centre of pixel (`x`, `y`) of a
/// `width`×`height` image of `scene`, frame `frame` of its film. The pixel
/// must be inside the image.
pub fn pick(scene: &Scene, frame: u32, [x, y]: [u32; 2], [width, height]: [u32; 2]) -> Pick {
    let camera = scene.camera.frame();
    let ray = camera.ray(x as f64 + 0.5, y as f64 + 0.5, width, height);
    let result = march(&ray, &scene.fractal, &scene.quality);
    let hit = result
        .hit
        .map(|h| (h, normal(&ray, &h, &scene.fractal, &scene.quality).0));
    let arr = |v: crate::math::DVec3| [v.x, v.y, v.z];
    Pick {
        frame,
        pixel: [x, y],
        size: [width, height],
        ray_origin: arr(ray.origin),
        ray_direction: arr(ray.dir),
        hit: hit.is_some(),
        point: hit.map(|(h, _)| arr(h.point)),
        distance: hit.map(|(h, _)| h.t),
        normal: hit.map(|(_, n)| arr(n)),
        pixel_footprint: hit
            .map(|(h, _)| h.t)
            .or_else(|| scene.quality.interval(&ray).map(|(_, far)| far))
            .map(|t| ray.footprint(t)),
        fractal: PickFractal {
            formula: scene.fractal.formula.name(),
            power: scene.fractal.power,
            iterations: scene.fractal.iterations,
            bailout: scene.fractal.bailout,
            julia: scene.fractal.julia.map(arr),
        },
    }
}
