//! Unit tests of rendering: sampling, reuse, waves, effects and cones.

use super::*;
use crate::math::{Real, Vec3};

#[test]
fn a_reused_film_renders_each_frame_as_a_new_one_would() {
    // The film first holds another view at another size with every
    // layer, then values no frame gives, so anything left would show.
    let mut other = Scene::default();
    other.camera.position = crate::math::DVec3::new(0.4, -1.9, 1.2);
    let scene = Scene::default();
    let every = Layers {
        normal: true,
        albedo: true,
        traps: true,
    };
    let mut film = Film::default();
    render_frame_into(&mut film, &[other], 0, 44, 33, every, &|| {});
    let normal_only = Layers {
        normal: true,
        ..Layers::default()
    };
    // Every layer follows a frame that had it too, so each is reused.
    for (w, h, layers) in [
        (32, 24, Layers::default()),
        (40, 30, every),
        (24, 16, every),
        (48, 20, normal_only),
        (16, 12, every),
        (16, 12, every),
    ] {
        // Values no frame could give, in every element the film holds,
        // so a pixel finishing missed would show whatever it missed.
        film.colour.fill(Vec3::splat(-7.0));
        film.alpha.fill(-7.0);
        film.depth.fill(-7.0);
        film.evaluations.fill(7_777_777);
        for layer in [&mut film.normal, &mut film.albedo].into_iter().flatten() {
            layer.fill(Vec3::splat(-7.0));
        }
        if let Some(traps) = &mut film.traps {
            traps.fill([-7.0; 4]);
        }
        render_frame_into(
            &mut film,
            std::slice::from_ref(&scene),
            0,
            w,
            h,
            layers,
            &|| {},
        );
        let mut new = Film::default();
        let one = std::slice::from_ref(&scene);
        render_frame_into(&mut new, one, 0, w, h, layers, &|| {});
        assert!(film == new, "{w}x{h} {layers:?}");
        assert_eq!(film.colour.len(), (w * h) as usize);
        assert_eq!(film.normal.is_some(), layers.normal);
    }
}

#[test]
fn default_scene_shows_the_bulb_in_the_middle_and_background_in_corners() {
    let scene = Scene::default();
    let film = render_frame(&scene, 0, 32, 24, &|| {});
    let at = |x: u32, y: u32| (y * 32 + x) as usize;
    assert_eq!(film.alpha[at(16, 12)], 1.0);
    assert!(film.depth[at(16, 12)] < 3.0);
    assert_eq!(film.alpha[at(0, 0)], 0.0);
    assert_eq!(film.depth[at(0, 0)], BACKGROUND_DEPTH);
    assert!(film.colour.iter().all(|c| c.is_finite()));
    assert!(film.stats.de_evaluations > film.stats.samples);
    // Per-pixel counts add up to the frame's, and the bulb costs more than the sky.
    let per_pixel: u64 = film.evaluations.iter().map(|&e| e as u64).sum();
    assert_eq!(per_pixel, film.stats.de_evaluations);
    assert_eq!(
        film.stats.max_pixel_evaluations,
        *film.evaluations.iter().max().unwrap() as u64
    );
    assert!(film.evaluations[at(16, 12)] > film.evaluations[at(0, 0)]);
    assert_eq!(film.stats.samples, 32 * 24);
}

#[test]
fn each_effect_alone_moves_only_its_stage_and_changes_the_image() {
    use crate::shade::{AmbientOcclusion, Effects, Fog, Glow, PathTracing, Shadows, Specular};
    let plain_scene = Scene::default();
    let plain = render_frame(&plain_scene, 0, 40, 30, &|| {});
    let counters = |s: &FrameStats| {
        [
            s.primary_evaluations,
            s.normal_evaluations,
            s.shadow_evaluations,
            s.occlusion_evaluations,
            s.bounce_evaluations,
            s.sun_evaluations,
        ]
    };
    // With every effect off nothing but marching and normals runs.
    let p = counters(&plain.stats);
    assert!(p[0] > 0 && p[1] > 0);
    assert_eq!((p[2], p[3], p[4], p[5]), (0, 0, 0, 0));
    assert_eq!(plain.stats.de_evaluations, p.iter().sum::<u64>());
    let cases: [(&str, Effects, [bool; 6]); 6] = [
        (
            "shadows",
            Effects {
                shadows: Some(Shadows::default()),
                ..Effects::default()
            },
            [false, false, true, false, false, false],
        ),
        (
            "ambient_occlusion",
            Effects {
                ambient_occlusion: Some(AmbientOcclusion::default()),
                ..Effects::default()
            },
            [false, false, false, true, false, false],
        ),
        (
            "specular",
            Effects {
                specular: Some(Specular::default()),
                ..Effects::default()
            },
            [false; 6],
        ),
        (
            "fog",
            Effects {
                fog: Some(Fog::default()),
                ..Effects::default()
            },
            [false; 6],
        ),
        (
            "glow",
            Effects {
                glow: Some(Glow::default()),
                ..Effects::default()
            },
            [false; 6],
        ),
        (
            "path_tracing",
            Effects {
                path_tracing: Some(PathTracing::default()),
                ..Effects::default()
            },
            [false, false, false, false, true, true],
        ),
    ];
    // Glow needs each camera ray's own nearest approach, so its rays march
    // alone, without cones: against the plain frame marched that way.
    let mut alone_scene = Scene::default();
    alone_scene.quality.cone_rays = 1;
    let alone_film = render_frame(&alone_scene, 0, 40, 30, &|| {});
    let alone = counters(&alone_film.stats);
    assert!(
        alone[0] > p[0],
        "cones save primary estimates: {alone:?} {p:?}"
    );
    for (name, effects, moves) in cases {
        let (p, plain) = match effects.glow {
            Some(_) => (alone, &alone_film),
            None => (p, &plain),
        };
        let scene = Scene {
            effects,
            ..Scene::default()
        };
        let film = render_frame(&scene, 0, 40, 30, &|| {});
        let c = counters(&film.stats);
        for k in 0..6 {
            if moves[k] {
                assert!(c[k] > p[k], "{name}: stage {k} should run");
            } else {
                assert_eq!(c[k], p[k], "{name}: stage {k} should not change");
            }
        }
        assert_eq!(film.stats.de_evaluations, c.iter().sum::<u64>());
        assert!(
            film.colour != plain.colour,
            "{name} changed nothing in the image"
        );
        assert!(film.colour.iter().all(|v| v.is_finite()));
    }
}

#[test]
fn depth_of_field_blurs_only_when_the_lens_is_open() {
    let sharp = Scene {
        samples_per_pixel: 4,
        ..Scene::default()
    };
    let mut blurred = sharp.clone();
    blurred.camera.aperture_radius = 0.15;
    blurred.camera.focus_distance = Some(1.0); // well in front of the bulb
    let a = render_frame(&sharp, 0, 32, 24, &|| {});
    let b = render_frame(&blurred, 0, 32, 24, &|| {});
    assert!(a.colour != b.colour);
    assert!(b.colour.iter().all(|c| c.is_finite()));
    // A zero aperture is the pinhole exactly, whatever the focus.
    let mut closed = sharp.clone();
    closed.camera.focus_distance = Some(1.0);
    assert!(render_frame(&closed, 0, 32, 24, &|| {}).colour == a.colour);
    // The lens costs marching only through its extra rays' paths: same sample count.
    assert_eq!(a.stats.samples, b.stats.samples);
}

#[test]
fn cones_in_blocks_find_the_pixels_rays_alone_find() {
    // A width that blocks of 4 do not divide and a last band of two
    // rows (54 = 4·13 + 2): each pixel's hit and depth, with its rays marched in 4×4
    // cones, against every ray alone. A pixel's sums taken from
    // another pixel's ray would move the silhouette. At hit thresholds
    // past one footprint too, where a ray alone stops that much sooner:
    // cones that went on to a footprint missed the rays' hits (at 20,
    // 1135 of 5184 pixels disagreed at 96×54) and set the depth tens of
    // footprints too deep; a depth is then as good as the threshold.
    let (w, h) = (97, 54);
    for (threshold, within, share) in [(0.5, 2.0, 95), (5.0, 5.0, 90), (20.0, 20.0, 90)] {
        let mut blocks = Scene::default();
        blocks.quality.hit_threshold = threshold;
        let mut alone = blocks.clone();
        alone.quality.cone_rays = 1;
        assert_eq!(crate::march::cone_block(blocks.cone_rays()), (4, 4));
        let (a, b) = (
            render_frame(&alone, 0, w, h, &|| {}),
            render_frame(&blocks, 0, w, h, &|| {}),
        );
        let pixel_angle = (blocks.camera.fov_degrees.to_radians() / h as Real) as f32;
        let (mut hits, mut agree, mut near) = (0, 0, 0);
        for i in 0..(w * h) as usize {
            agree += (a.alpha[i] == b.alpha[i]) as usize;
            if a.alpha[i] > 0.0 && b.alpha[i] > 0.0 {
                hits += 1;
                let footprint = a.depth[i] * pixel_angle;
                near += ((a.depth[i] - b.depth[i]).abs() <= within * footprint) as usize;
            }
        }
        let n = (w * h) as usize;
        assert!(hits > n / 4, "{threshold}: {hits} hits of {n}");
        assert!(
            agree * 100 >= n * 98,
            "{threshold}: {agree} of {n} agree on hit or miss"
        );
        assert!(
            near * 100 >= hits * share,
            "{threshold}: {near} of {hits} hits within {within} footprints"
        );
        if threshold < 1.0 {
            assert!(b.stats.primary_evaluations < a.stats.primary_evaluations);
        }
    }
}

#[test]
fn a_frame_rendered_in_waves_equals_one_rendered_at_once() {
    let scene = Scene {
        samples_per_pixel: 6,
        effects: crate::shade::Effects {
            path_tracing: Some(Default::default()),
            ..Default::default()
        },
        ..Scene::default()
    };
    let layers = Layers {
        normal: true,
        albedo: true,
        traps: true,
    };
    let scenes = std::slice::from_ref(&scene);
    // Enough rows that every thread takes several.
    let (w, h) = (12, 130);
    let mut at_once = Film::default();
    render_frame_into(&mut at_once, scenes, 3, w, h, layers, &|| {});
    let mut acc = Accumulation::new(w, h, layers);
    for until in [1, 2, 5, 6] {
        render_samples(scenes, 3, &mut acc, until, &|| {});
    }
    let waves = acc.finish(6);
    assert!(waves.colour == at_once.colour && waves.depth == at_once.depth);
    assert!(waves.normal == at_once.normal && waves.traps == at_once.traps);
    assert_eq!(waves.stats, at_once.stats);
    assert!(waves.albedo == at_once.albedo && waves.alpha == at_once.alpha);
    assert_eq!(waves.evaluations, at_once.evaluations);
    assert_eq!(at_once.colour.len(), (w * h) as usize);
}

mod zoom;

#[test]
fn a_fisheye_frames_memory_estimate_holds_its_film() {
    let mut scene = Scene::default();
    scene.camera.projection = crate::camera::Projection::Fisheye { degrees: 180.0 };
    let (w, h) = (16, 12);
    let film = render_frame(&scene, 0, w, h, &|| {});
    let coverage = film.coverage.as_ref().expect("a fisheye film has coverage");
    let held = 12 * film.colour.len()
        + 4 * (film.alpha.len() + film.depth.len() + film.evaluations.len() + coverage.len());
    // A PNG's encoding takes 4 bytes a pixel beside the film.
    let png = 4 * (w * h) as u64;
    let estimate = frame_bytes([w, h], Layers::default(), false, Sums::None, true);
    assert!(held as u64 + png <= estimate, "{held} + {png} > {estimate}");
}
