//! The path tracer: sampling, white furnaces, and paths together equal to alone.

use super::*;

#[test]
fn cosine_sampling_has_the_right_mean_cosine() {
    // E[cos θ] under the pdf cos θ/π is 2/3.
    let n = DVec3::new(0.3, -0.5, 0.8).normalize();
    let count = 20_000u64;
    let mut sum = 0.0;
    for i in 0..count {
        let d = cosine_direction(
            n,
            crate::math::sample_1d(1, 0, i, 0, 0),
            crate::math::sample_1d(1, 0, i, 0, 1),
        );
        assert!((d.length() - 1.0).abs() < 1e-12 && d.dot(n) >= 0.0);
        sum += d.dot(n);
    }
    assert!(
        (sum / count as f64 - 2.0 / 3.0).abs() < 0.01,
        "{}",
        sum / count as f64
    );
    // Cone samples stay within the cone.
    let half = 0.5f64.to_radians();
    for i in 0..1000u64 {
        let d = cone_direction(
            n,
            half,
            crate::math::sample_1d(2, 0, i, 0, 0),
            crate::math::sample_1d(2, 0, i, 0, 1),
        );
        assert!(d.dot(n) >= half.cos() - 1e-12);
    }
}

/// A Look whose albedo is `a` everywhere (no trap colouring, no occlusion).
fn grey(a: f32) -> Look {
    Look {
        base_colour: Vec3::splat(a),
        trap_x_colour: Vec3::splat(a),
        trap_y_colour: Vec3::splat(a),
        trap_z_colour: Vec3::splat(a),
        trap_occlusion: 0.0,
        light_colour: Vec3::ZERO,
        ..Look::default()
    }
}

fn furnace(look: &Look, fractal: &Fractal, samples: u64, bounces: u32) -> f64 {
    furnace_with(look, fractal, samples, bounces, None)
}

fn furnace_with(
    look: &Look,
    fractal: &Fractal,
    samples: u64,
    bounces: u32,
    environment: Option<&crate::environment::EnvironmentMap>,
) -> f64 {
    // Paths from points on the surface, under a sky of radiance 1 and no sun.
    let pt = PathTracing {
        max_bounces: bounces,
        sky: Sky::Constant(Vec3::ONE),
        ..PathTracing::default()
    };
    let settings = MarchSettings::default();
    let mut total = 0.0;
    let mut counts = StageCounts::default();
    let mut taken = 0;
    for i in 0..samples {
        // Start from where a ray from outside meets the surface.
        let u = |d: u32| crate::math::sample_1d(9, 1, i, 0, d);
        let from = DVec3::new(u(0) - 0.5, u(1) - 0.5, u(2) - 0.5).normalize() * 2.0;
        let ray = crate::march::Ray {
            origin: from,
            dir: -from.normalize(),
            pixel_angle: 1e-3,
            start_footprint: 0.0,
        };
        let Some(at) = surface_at(&ray, fractal, &settings) else {
            continue;
        };
        let random = |d: u32| crate::math::sample_1d(5, 2, i, 0, d);
        total += trace_path(
            look,
            &pt,
            fractal,
            &settings,
            &at,
            DVec3::Y,
            environment,
            &random,
            &mut counts,
        )
        .x as f64;
        taken += 1;
    }
    assert!(taken > samples / 2);
    total / taken as f64
}

#[test]
fn paths_traced_together_match_paths_traced_alone() {
    // A row of camera samples on the bulb (misses among them), traced side
    // by side and one at a time: every radiance and count to the bit, with
    // a sun and an extra light, and with an uneven environment map too.
    let fractal = Fractal::default();
    let settings = MarchSettings::default();
    let look = Look {
        extra_lights: vec![Light {
            direction: DVec3::new(-1.0, 0.3, 0.2),
            colour: Vec3::new(0.4, 0.5, 0.9),
            intensity: 0.7,
        }],
        ..Look::default()
    };
    let starts: Vec<Option<SurfacePoint>> = (0..48)
        .map(|i| {
            let x = i as Real / 48.0 * 2.4 - 1.2;
            let ray = crate::march::Ray {
                origin: DVec3::new(x, 0.3, 2.6),
                dir: DVec3::new(0.0, -0.1, -1.0).normalize(),
                pixel_angle: 2e-3,
                start_footprint: 0.0,
            };
            surface_at(&ray, &fractal, &settings)
        })
        .collect();
    assert!(
        starts.iter().any(Option::is_none) && starts.iter().filter(|s| s.is_some()).count() > 20
    );
    let pixels: Vec<Vec3> = (0..128)
        .map(|i| Vec3::new(0.2 + (i % 7) as f32, 0.5, 0.1 * (i / 16) as f32))
        .collect();
    let map = crate::environment::EnvironmentMap::from_pixels(16, 8, pixels);
    for environment in [None, Some(&map)] {
        let pt = PathTracing {
            max_bounces: 6,
            ..PathTracing::default()
        };
        let random = |path: usize, d: u32| crate::math::sample_1d(3, 7, path as u64, 0, d);
        let mut together = PathScratch::default();
        trace_paths(
            &look,
            &pt,
            &fractal,
            &settings,
            &starts,
            DVec3::Y,
            environment,
            crate::shade::palette_table(&look, &fractal).as_ref(),
            &random,
            &mut together,
        );
        let mut bounced = 0;
        for (i, start) in starts.iter().enumerate() {
            let (radiance, counts) = together.out[i];
            let Some(at) = start else {
                assert_eq!(radiance, Vec3::ZERO);
                assert_eq!(counts.bounces + counts.sun_rays, 0);
                continue;
            };
            let mut alone = StageCounts::default();
            let single = trace_path(
                &look,
                &pt,
                &fractal,
                &settings,
                at,
                DVec3::Y,
                environment,
                &|d| random(i, d),
                &mut alone,
            );
            assert_eq!(
                radiance.to_array().map(f32::to_bits),
                single.to_array().map(f32::to_bits),
                "path {i}"
            );
            assert_eq!(
                (counts.bounces, counts.sun_rays),
                (alone.bounces, alone.sun_rays),
                "path {i}"
            );
            bounced += (counts.bounces > 0) as usize;
        }
        assert!(bounced > 20);
    }
}

#[test]
fn white_furnace_returns_the_albedo_on_a_convex_ball() {
    // On a convex ball every bounce escapes to the sky: radiance = albedo × 1,
    // exactly, on every path.
    let r = furnace(&grey(0.5), &unit_ball(), 200, 8);
    assert!((r - 0.5).abs() < 1e-3, "{r}");
}

#[test]
fn white_furnace_holds_with_a_uniform_environment_map() {
    // A map of radiance 1 everywhere, lit through map sampling and bounce
    // sampling combined by their weights: still the albedo on the ball,
    // now within Monte Carlo error.
    let map = crate::environment::EnvironmentMap::from_pixels(16, 8, vec![Vec3::ONE; 128]);
    let r = furnace_with(&grey(0.5), &unit_ball(), 4000, 8, Some(&map));
    assert!((r - 0.5).abs() < 0.02, "{r}");
}

#[test]
fn white_furnace_conserves_energy_in_the_bulb() {
    // Albedo 1 in a sky of radiance 1: however the paths wander in the
    // bulb's crevices, the expected radiance is 1 (Russian roulette keeps
    // it unbiased). 2000 paths: a few percent of Monte Carlo error.
    let r = furnace(&grey(1.0), &Fractal::default(), 2000, 64);
    assert!((r - 1.0).abs() < 0.05, "{r}");
    // A darker albedo a: a path escaping after k bounces brings a^k ≤ a, and
    // the crevices trap light, so 0 < radiance < a.
    let dark = furnace(&grey(0.6), &Fractal::default(), 2000, 64);
    assert!(dark > 0.2 && dark < 0.6, "{dark}");
}
