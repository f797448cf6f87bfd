//! The sweep: which knobs and settings are tried around the scene's own, and
//! `measure`, which renders each and measures it against the reference.

use super::front::mark_pareto;
use super::metrics::{compare, depth_errors, film_hits, footprints_at, psnr, srgb, Errors};
use super::reference::{reference_depths, reference_scene, Convergence, REFERENCE_STEP};
use super::surface::Distances;
use super::timing::timed_render;
use super::{Measurement, Report};
use crate::fractal::{DeMethod, Precision};
use crate::math::Real;
use crate::render::render_frame;
use crate::scene::Scene;
use std::time::Instant;

/// One setting to measure: the scene with one knob changed.
#[derive(Clone, Debug)]
pub struct Variant {
    /// The knob varied (`iterations`, `de`, …), or `reference` / `scene`.
    pub knob: &'static str,
    /// Its value in this variant.
    pub setting: String,
    pub scene: Scene,
}

fn scaled(v: u32, f: Real) -> u32 {
    ((v as Real * f).round() as u32).max(1)
}

/// The sweep: the reference, the scene itself, then one knob at a time.
pub fn variants(scene: &Scene) -> Vec<Variant> {
    let mut out = vec![
        Variant {
            knob: "reference",
            setting: "membership depth + high-quality shading".into(),
            scene: reference_scene(scene),
        },
        Variant {
            knob: "scene",
            setting: "as in the timeline".into(),
            scene: scene.clone(),
        },
    ];
    let mut add = |knob: &'static str, setting: String, change: &dyn Fn(&mut Scene)| {
        let mut s = scene.clone();
        change(&mut s);
        if s != *scene && !out.iter().any(|v| v.scene == s) {
            out.push(Variant {
                knob,
                setting,
                scene: s,
            });
        }
    };
    let f = &scene.fractal;
    let q = &scene.quality;
    for k in [0.25, 0.5, 0.75, 1.5] {
        let n = scaled(f.iterations, k);
        add("iterations", n.to_string(), &|s| s.fractal.iterations = n);
    }
    for b in [2.0, 16.0, 256.0] {
        add("bailout", format!("{b}"), &|s| s.fractal.bailout = b);
    }
    for k in [4.0, 2.0, 0.5, 0.25] {
        let v = q.hit_threshold * k;
        add("hit_threshold", format!("{v}"), &|s| {
            s.quality.hit_threshold = v
        });
    }
    for v in [0.0, 0.125, 0.25, 0.5, 1.0, 2.0] {
        add("membership_step", format!("{v}"), &|s| {
            s.quality.membership_step = v
        });
    }
    for v in [0.5, 0.7, 0.9, 1.0] {
        add("fudge", format!("{v}"), &|s| s.quality.fudge = v);
    }
    for v in [1.0, 1.2, 1.5, 1.8] {
        add("over_relaxation", format!("{v}"), &|s| {
            s.quality.over_relaxation = v
        });
    }
    for v in [1, 4, 8, 16, 64] {
        add("cone_rays", v.to_string(), &|s| s.quality.cone_rays = v);
    }
    for v in [0, 1, 2, 4] {
        add("refine_steps", v.to_string(), &|s| {
            s.quality.refine_steps = v
        });
    }
    let confirm = !q.confirm_hits;
    add("confirm_hits", confirm.to_string(), &|s| {
        s.quality.confirm_hits = confirm
    });
    for k in [0.25, 0.5, 2.0] {
        let v = scaled(q.max_steps, k);
        add("max_steps", v.to_string(), &|s| s.quality.max_steps = v);
    }
    for k in [4.0, 0.25] {
        let v = q.normal_step * k;
        add("normal_step", format!("{v}"), &|s| {
            s.quality.normal_step = v
        });
    }
    for n in [1, 4, 9, 16] {
        add("samples_per_pixel", n.to_string(), &|s| {
            s.samples_per_pixel = n;
            s.adaptive = None;
        });
    }
    for noise in [0.04, 0.02, 0.01] {
        add("adaptive", format!("noise {noise} (at most 16)"), &|s| {
            s.samples_per_pixel = 16;
            s.adaptive = Some(crate::scene::Adaptive { first: 2, noise });
        });
    }
    add("perturbation", "off: f64 alone".into(), &|s| {
        s.fractal.perturbation = false
    });
    for precision in [Precision::F64, Precision::F32] {
        for de in DeMethod::ALL {
            add("de", format!("{} {}", de.name(), precision.name()), &|s| {
                s.fractal.de = de;
                s.fractal.precision = precision;
            });
        }
    }
    out
}

/// `variants` of `scene` for a frame at `size`: perturbation only where
/// the frame is deep, `confirm_hits` only where the check can run, and
/// each saying where it renders in f64 instead of f32.
pub fn sweep_for(scene: &Scene, size: [u32; 2]) -> Vec<Variant> {
    // Perturbation is a knob only where the frame is deep.
    let deep = crate::deep::needed(scene, size)
        && crate::fractal::whole_power(scene.fractal.power).is_some();
    // The potential check runs only where `Fractal::plain_analytic` allows
    // it, on rays that walk by the estimate, where its stencil resolves
    // (taken at the target, where the frame looks).
    let resolves =
        crate::march::check_resolves(crate::deep::footprint(scene, size), scene.camera.target);
    let checkable =
        resolves && scene.fractal.plain_analytic() && scene.quality.membership_step <= 0.0;
    variants(scene)
        .into_iter()
        .filter(|v| deep || v.knob != "perturbation")
        .filter(|v| checkable || v.knob != "confirm_hits")
        .map(|mut v| {
            if crate::deep::f32_too_coarse(&v.scene, size) {
                v.setting += " (renders in f64: f32 cannot resolve these pixels)";
            }
            v
        })
        .collect()
}

/// Runs the whole sweep on frame `frame_index` of `scene` at `width`×`height`.
/// `progress` hears each variant's name before it is rendered.
pub fn measure(
    scene: &Scene,
    frame_index: u32,
    width: u32,
    height: u32,
    progress: &dyn Fn(usize, usize, &Variant),
) -> Report {
    let all = sweep_for(scene, [width, height]);
    let reference = &all[0].scene;
    progress(0, all.len(), &all[0]);
    let started = Instant::now();
    let (reference_depth, tests) = reference_depths(reference, width, height, REFERENCE_STEP);
    let reference_film = render_frame(reference, frame_index, width, height, &|| {});
    let reference_seconds = started.elapsed().as_secs_f64();
    let reference_image = srgb(&reference_film, &scene.look);
    let footprint_at_reference = footprints_at(scene, width, height, &reference_depth);

    // The same depths at twice the step: how far the reference itself has settled.
    let (coarse, _) = reference_depths(reference, width, height, 2.0 * REFERENCE_STEP);
    let settled = depth_errors(&coarse, &reference_depth, &footprint_at_reference);
    let convergence = Convergence {
        depth_change_mean_px: settled.mean_px,
        hit_change: settled.hit_mismatch,
    };

    let distances = Distances::default();
    let measurement = |variant: &Variant, seconds: f64, evaluations: u64, e: Errors| Measurement {
        knob: variant.knob,
        setting: variant.setting.clone(),
        seconds,
        de_evaluations: evaluations,
        depth_error_mean_px: e.depth.mean_px,
        depth_error_p99_px: e.depth.p99_px,
        hit_mismatch: e.depth.hit_mismatch,
        overshoot: e.depth.overshoot,
        image_rmse: e.rmse,
        psnr_db: psnr(e.rmse),
        surface_distance_px: distances.of(&variant.scene, &reference.fractal, width, height),
        pareto: false,
    };
    // The reference against itself, through the same comparison as every variant.
    let own = compare(
        &reference_depth,
        &reference_image,
        &reference_image,
        &reference_depth,
        &footprint_at_reference,
    );
    let mut rows = vec![measurement(
        &all[0],
        reference_seconds,
        tests + reference_film.stats.de_evaluations,
        own,
    )];
    for (i, variant) in all.iter().enumerate().skip(1) {
        progress(i, all.len(), variant);
        let (film, seconds) = timed_render(&variant.scene, frame_index, width, height);
        let e = compare(
            &film_hits(&film),
            &srgb(&film, &scene.look),
            &reference_image,
            &reference_depth,
            &footprint_at_reference,
        );
        rows.push(measurement(variant, seconds, film.stats.de_evaluations, e));
    }
    mark_pareto(&mut rows);
    Report {
        rows,
        reference: reference.clone(),
        convergence,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DVec3;

    #[test]
    fn variants_change_one_knob_each_and_are_distinct() {
        let scene = Scene::default();
        let all = variants(&scene);
        assert_eq!(all[0].knob, "reference");
        assert_eq!(all[1].scene, scene);
        for (i, v) in all.iter().enumerate().skip(2) {
            assert_ne!(v.scene, scene, "{} {}", v.knob, v.setting);
            for w in &all[i + 1..] {
                assert_ne!(v.scene, w.scene);
            }
        }
        // Every estimator in both precisions appears (the scene's own is the "scene" row).
        assert_eq!(all.iter().filter(|v| v.knob == "de").count(), 9);
    }

    /// The default scene looking at (0, 0, 1) from `distance` along z.
    fn scene_at(distance: Real) -> Scene {
        let mut scene = Scene::default();
        scene.camera.target = DVec3::Z;
        scene.camera.position = DVec3::Z * (1.0 + distance);
        scene
    }

    #[test]
    fn the_check_of_hits_is_swept_only_where_its_stencil_resolves() {
        let size = [1024, 576];
        let rows = |distance: Real| {
            sweep_for(&scene_at(distance), size)
                .iter()
                .filter(|v| v.knob == "confirm_hits")
                .count()
        };
        assert_eq!(rows(1.0), 1);
        // A pixel of 3e-8 at the target: not deep (under 2^-26 of the
        // target's size, 1.5e-8, is), but finer than the stencil takes,
        // so the row would repeat "scene".
        let footprint = crate::deep::footprint(&scene_at(2e-5), size);
        assert!((2e-8..4e-8).contains(&footprint), "{footprint}");
        assert!(!crate::deep::needed(&scene_at(2e-5), size));
        assert_eq!(rows(2e-5), 0);
    }
}
