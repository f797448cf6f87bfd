//! How close a variant's hits come to the set in 3D: the median distance
//! from the hits of a grid of centre rays to the nearest point of the set,
//! judged by membership alone (`march::judge`), in footprints.

use crate::fractal::Fractal;
use crate::march::judge::distance_to_set;
use crate::march::{march, MarchSettings};
use crate::math::{median, Real};
use crate::scene::Scene;

/// Centre rays along each side of the grid.
const GRID: u32 = 12;
/// Uniform samples of each ball searched around a hit: fewer than
/// `examples/surface.rs` takes, so a looser upper bound, kept cheap as
/// every row of the sweep pays it.
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

/// `median_distance` of a sweep's variants, worked out once per marcher:
/// the variants of sampling and shading march as the scene does.
#[derive(Default)]
pub(super) struct Distances(std::cell::RefCell<Vec<(Fractal, MarchSettings, Option<f64>)>>);

impl Distances {
    /// `median_distance` of `scene`, or the one a variant marching alike had.
    pub(super) fn of(&self, scene: &Scene, set: &Fractal, width: u32, height: u32) -> Option<f64> {
        let alike = |(f, q, _): &&(Fractal, MarchSettings, Option<f64>)| {
            *f == scene.fractal && *q == scene.quality
        };
        if let Some((_, _, known)) = self.0.borrow().iter().find(alike) {
            return *known;
        }
        let found = median_distance(scene, set, width, height);
        let key = (scene.fractal.clone(), scene.quality.clone(), found);
        self.0.borrow_mut().push(key);
        found
    }
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
    fn a_variant_marching_as_another_is_judged_once() {
        let scene = Scene::default();
        let distances = Distances::default();
        let first = distances.of(&scene, &scene.fractal, 64, 36);
        let mut more_samples = scene.clone();
        more_samples.samples_per_pixel = 9;
        assert_eq!(distances.of(&more_samples, &scene.fractal, 64, 36), first);
        let mut coarse = scene.clone();
        coarse.quality.hit_threshold = 8.0;
        assert_ne!(distances.of(&coarse, &scene.fractal, 64, 36), first);
        assert_eq!(distances.0.borrow().len(), 2);
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
