//! How close a variant's hits come to the set in 3D: the median distance
//! from the hits of a grid of centre rays to the nearest point of the set,
//! judged by membership alone (`march::judge`), in footprints.

use crate::fractal::Fractal;
use crate::march::judge::distance_to_set;
use crate::march::march;
use crate::math::{median, Real};
use crate::scene::Scene;

/// Centre rays along each side of the grid.
const GRID: u32 = 12;
/// Uniform samples of each ball searched around a hit: a bound within a
/// few hundredths of a footprint of 50,000's (docs/surface.md).
const SAMPLES: usize = 2_000;

/// The median 3D distance, in footprints, from the hits of `scene`'s
/// marcher to `set` (the reference's set), over a grid of centre rays of a
/// `width`×`height` frame; a hit with no point of the set within 8
/// footprints counts as farther than any. None for a deep frame, whose
/// points only perturbation resolves, or where no ray hits.
pub(super) fn median_distance(
    scene: &Scene,
    set: &Fractal,
    width: u32,
    height: u32,
) -> Option<f64> {
    if crate::deep::needed(scene, [width, height]) {
        return None;
    }
    let camera = scene.camera.frame();
    let mut distances: Vec<f64> = (0..GRID * GRID)
        .filter_map(|i| {
            let (gx, gy) = (i % GRID, i / GRID);
            let x = ((gx as Real + 0.5) / GRID as Real * width as Real).floor();
            let y = ((gy as Real + 0.5) / GRID as Real * height as Real).floor();
            let ray = camera.ray(x + 0.5, y + 0.5, width, height);
            let hit = march(&ray, &scene.fractal, &scene.quality).hit?;
            let footprint = ray.footprint(hit.t);
            let found = distance_to_set(set, hit.point, footprint, SAMPLES, u64::from(i));
            Some(found.unwrap_or(Real::INFINITY))
        })
        .collect();
    (!distances.is_empty()).then(|| median(&mut distances))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_coarser_threshold_stops_farther_from_the_set() {
        let scene = Scene::default();
        let fine = median_distance(&scene, &scene.fractal, 64, 36).expect("hits");
        let mut coarse = scene.clone();
        coarse.quality.hit_threshold = 8.0;
        let far = median_distance(&coarse, &scene.fractal, 64, 36).expect("hits");
        assert!(fine < 2.0 && far > 2.0 * fine, "{fine} against {far}");
    }

    #[test]
    fn a_deep_frame_is_not_judged() {
        let mut scene = Scene::default();
        scene.camera.target = crate::math::DVec3::new(0.0, -1.1, 0.0);
        scene.camera.position = scene.camera.target + crate::math::DVec3::new(0.0, 0.0, 1e-20);
        assert!(crate::deep::needed(&scene, [64, 36]));
        assert_eq!(median_distance(&scene, &scene.fractal, 64, 36), None);
    }
}
