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
    /// The hit as decimal digits, as many as place it to a thousandth of a
    /// pixel (more than f64 holds in a deep frame).
    pub point_digits: Option<[String; 3]>,
    /// Whether the frame is deep (`crate::deep`).
    pub deep: bool,
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
/// `width`×`height` image of `scene`, frame `frame` of its film, along the
/// ray its projection gives it. The pixel must be inside the image.
pub fn pick(scene: &Scene, frame: u32, [x, y]: [u32; 2], [width, height]: [u32; 2]) -> Pick {
    let rendered = crate::deep::rendered(scene, [width, height], &Default::default());
    let marched = rendered.as_ref().unwrap_or(scene);
    let deep = marched.fractal.deep.is_some();
    let camera = marched.camera.frame();
    let ray = camera.ray(x as f64 + 0.5, y as f64 + 0.5, width, height);
    let fractal = &marched.fractal;
    // Beyond a fisheye's circle the renderer marches nothing: nor does pick.
    let result = match camera.covers(x, y, width, height) {
        true => march(&ray, fractal, &marched.quality),
        false => crate::march::MarchResult::default(),
    };
    let hit = result
        .hit
        .map(|h| (h, normal(&ray, &h, fractal, &marched.quality).0));
    let arr = |v: crate::math::DVec3| [v.x, v.y, v.z];
    let footprint = hit
        .map(|(h, _)| h.t)
        .or_else(|| marched.quality.interval(&ray).map(|(_, far)| far))
        .map(|t| ray.footprint(t));
    let digits = hit.zip(footprint).map(|((h, _), f)| {
        let size = fractal.world(h.point).abs().max_element();
        let significant = crate::deep::digits_for(size, f);
        crate::deep::world_digits(scene, deep, h.point, significant)
    });
    Pick {
        frame,
        pixel: [x, y],
        size: [width, height],
        ray_origin: arr(fractal.world(ray.origin)),
        ray_direction: arr(ray.dir),
        hit: hit.is_some(),
        point: hit.map(|(h, _)| arr(fractal.world(h.point))),
        point_digits: digits,
        deep,
        distance: hit.map(|(h, _)| h.t),
        normal: hit.map(|(_, n)| arr(n)),
        pixel_footprint: footprint,
        fractal: PickFractal {
            formula: scene.fractal.formula.name(),
            power: scene.fractal.power,
            iterations: scene.fractal.iterations,
            bailout: scene.fractal.bailout,
            julia: scene.fractal.julia.map(arr),
        },
    }
}

/// One step of `refine`: the camera's distance from the target, and how
/// far beyond the target the centre ray met the surface.
#[derive(Serialize)]
pub struct RefineStep {
    pub camera_distance: f64,
    pub beyond_target: f64,
}

/// A target re-centred on the surface (`refine`), and the steps taken.
#[derive(Serialize)]
pub struct Refined {
    pub target: [String; 3],
    pub steps: Vec<RefineStep>,
}

/// How much closer each step of `refine` goes at most.
const REFINE_STEP: f64 = 1e-3;

/// The fewest of the last step's pixel footprints between the next camera
/// and the target: the target is placed only to within a footprint or so,
/// and a camera nearer than that may stand inside the set, or far from it.
const REFINE_CLEARANCE: f64 = 16.0;

/// The most steps `refine` takes: enough for 1e-300 when each step only
/// halves the distance (wide pixels).
const REFINE_MAX_STEPS: usize = 4096;

/// The most steps `refine` takes at the scene's own camera distance.
const REFINE_LAST_STEPS: usize = 16;

/// The most footprints `onto_the_set` looks past a hit.
const ONTO_THE_SET: f64 = 4.0;

/// `onto_the_set`'s membership step, in footprints.
const ONTO_STEP: f64 = 0.25;

/// Re-centres `scene`'s target on the surface: from a thousandth of the
/// target's size away (`from_afar`), or else one step above the scene's own
/// camera distance, then closer each step down to that distance, the
/// camera looks along its own direction at the target and the target moves
/// to where the centre ray meets the surface. Each hit is within a pixel of
/// the surface at that depth, so the last places the target as finely as
/// the scene's pixels. Each step's scene takes the iterations `recount`
/// gives it (`iterations: Auto` follows the target and the camera, as the
/// frame's own count will). `Err` says at which distance the centre ray
/// missed, or the camera was inside the set.
pub fn refine(
    scene: &Scene,
    image_size: [u32; 2],
    from_afar: bool,
    recount: &dyn Fn(&Scene) -> u32,
) -> Result<Refined, String> {
    let relative = scene.camera.relative_position();
    let (last, away) = (
        crate::math::length(relative),
        crate::math::direction(relative),
    );
    let size = scene.camera.target.abs().max_element();
    let afar = (REFINE_STEP * size).max(last);
    let mut distance = match from_afar {
        true => afar,
        false => (last / closer(scene.camera.axis_pixel_angle(image_size))).min(afar),
    };
    let mut s = scene.clone();
    // The centre ray of one eye at the camera itself: the view's axis, in
    // an image of an eye's size, whose pixels those of the frame are.
    let [width, height] = s.camera.eye_size(image_size);
    s.camera.stereo = None;
    let mut steps = Vec::new();
    // Steps taken at the scene's own distance.
    let mut at_last = 0;
    loop {
        let c = &mut s.camera;
        c.offset = Some(away * distance);
        c.position = c.target + away * distance;
        c.position_digits = None;
        s.fractal.iterations = recount(&s);
        let rendered = crate::deep::rendered(&s, [width, height], &Default::default());
        let marched = rendered.as_ref().unwrap_or(&s);
        let deep = marched.fractal.deep.is_some();
        let ray =
            marched
                .camera
                .frame()
                .ray(width as f64 * 0.5, height as f64 * 0.5, width, height);
        let hit = march(&ray, &marched.fractal, &marched.quality)
            .hit
            .ok_or_else(|| {
                format!("the centre ray missed the fractal with the camera {distance:.3e} from the target")
            })?;
        if hit.t <= 0.0 {
            return Err(format!(
                "the camera, {distance:.3e} from the target, is inside the fractal"
            ));
        }
        let footprint = ray.footprint(hit.t);
        let t = hit.t + onto_the_set(&ray, hit.t, marched);
        let point = ray.at(t);
        let significant = crate::deep::digits_for(size, footprint);
        let digits = crate::deep::world_digits(&s, deep, point, significant);
        s.camera.target = marched.fractal.world(point);
        s.camera.target_digits = Some(std::sync::Arc::new(digits));
        steps.push(RefineStep {
            camera_distance: distance,
            beyond_target: t - distance,
        });
        // Done where the frame's own camera saw the surface at the target,
        // not where a hit far off moved the target away from it.
        if distance <= last && (t - distance).abs() <= ONTO_THE_SET * footprint {
            break;
        }
        at_last += usize::from(distance <= last);
        if steps.len() >= REFINE_MAX_STEPS || at_last >= REFINE_LAST_STEPS {
            return Err(format!(
                "the surface did not settle under the centre ray with the camera {distance:.3e} from the target"
            ));
        }
        // The target is as good as the footprint where it was hit: the next
        // camera stays that many footprints clear of it.
        distance = (t * closer(ray.pixel_angle)).max(last);
    }
    let target = s
        .camera
        .target_digits
        .as_deref()
        .cloned()
        .unwrap_or_default();
    Ok(Refined { target, steps })
}

/// How much closer `refine`'s next step goes, for pixels of `pixel_angle`.
fn closer(pixel_angle: f64) -> f64 {
    REFINE_STEP.max(REFINE_CLEARANCE * pixel_angle).min(0.5)
}

/// How far past `t` along `ray` the set begins, found by membership within
/// `ONTO_THE_SET` footprints (0 where it does not): the estimate stops a ray
/// a little short of the surface, and a target that short would leave the
/// next, closer camera far from it. No further: a ray that grazes a tip or
/// a cusp meets the set's inside only far beyond, off the surface it saw.
fn onto_the_set(ray: &crate::march::Ray, t: f64, scene: &Scene) -> f64 {
    let from = crate::march::Ray {
        origin: ray.at(t),
        start_footprint: ray.footprint(t),
        ..*ray
    };
    let (crossing, _) = crate::march::march_by_membership(
        &from,
        &scene.fractal,
        &scene.quality,
        ONTO_STEP,
        0.0,
        (ONTO_THE_SET / ONTO_STEP) as u32,
    );
    crossing.unwrap_or(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{Stereo, StereoLayout};

    #[test]
    fn refine_of_a_stereo_pair_works_at_one_eyes_size() {
        // The default view: its centre ray meets the bulb.
        let mono = Scene::default();
        let stereo = Stereo {
            eye_separation: 0.03,
            layout: StereoLayout::TopBottom,
        };
        let mut pair = mono.clone();
        pair.camera.stereo = Some(stereo);
        let same = |s: &Scene| s.fractal.iterations;
        let one = refine(&mono, [64, 48], true, &same);
        assert!(one.is_ok(), "{:?}", one.err());
        let two = refine(&pair, [64, 96], true, &same);
        let json = |r: Result<Refined, String>| r.map(|r| serde_json::to_string(&r).ok());
        assert_eq!(json(two), json(one));
    }
}
