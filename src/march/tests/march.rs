//! Sphere tracing: hits, misses, thresholds, and rays side by side.

use super::*;

#[test]
fn marching_many_side_by_side_is_bit_identical_to_one_at_a_time() {
    use crate::fractal::Formula;
    // Rays fanned over the bulb from two sides: hits, misses, grazing
    // rays, rays that never reach the bounding sphere; 61 of them, so
    // the last batch leaves lanes idle.
    let mut rays = vec![];
    for (k, origin) in [DVec3::new(0.3, -2.6, 0.4), DVec3::new(2.0, 0.5, -1.7)]
        .into_iter()
        .enumerate()
    {
        for i in 0..30 + k {
            let a = i as Real / 30.0;
            let dir = -origin + DVec3::new(4.0 * a - 2.0, 0.9 * (7.0 * a).sin(), 4.4 * a - 2.2);
            rays.push(ray(origin, dir));
        }
    }
    let bulb = |formula, power, julia| Fractal {
        formula,
        power,
        julia,
        ..Fractal::default()
    };
    let fractals = [
        bulb(Formula::Quilez, 8.0, None),
        bulb(Formula::Asin, 8.0, None),
        bulb(
            Formula::WhiteNylander,
            3.0,
            Some(DVec3::new(0.3, -0.5, 0.2)),
        ),
        bulb(Formula::Quilez, 7.5, None),
        Fractal::unit_ball(),
    ];
    // Whole-run results by confirm_hits, to see the check do something.
    let mut runs = [String::new(), String::new()];
    for (max_steps, confirm_hits) in [(300, false), (7, false), (300, true), (7, true)] {
        let settings = MarchSettings {
            max_steps,
            confirm_hits,
            ..MarchSettings::default()
        };
        for f in &fractals {
            let mut many = vec![MarchResult::default(); rays.len()];
            march_many(&rays, f, &settings, &mut many);
            runs[confirm_hits as usize] += &format!("{many:?}");
            let mut hits = 0;
            for (r, m) in rays.iter().zip(&many) {
                let one = march(r, f, &settings);
                assert_eq!(format!("{one:?}"), format!("{m:?}"), "{f:?} along {r:?}");
                hits += one.hit.is_some() as usize;
            }
            assert!(
                hits > 5 && hits < rays.len() - 5,
                "{hits} hits: too few misses or hits"
            );
            // The hits' normals four to a call, as one at a time (the
            // last call's spare lanes idle).
            let hit_rays: Vec<(usize, &Ray, &Hit)> = rays
                .iter()
                .zip(&many)
                .enumerate()
                .filter_map(|(i, (r, m))| Some((i, r, m.hit.as_ref()?)))
                .collect();
            let mut normals = vec![None; rays.len()];
            normals_many(hit_rays.iter().copied(), f, &settings, |i, ray, hit, n| {
                // Handed back with the ray and hit it was given with.
                assert!(std::ptr::eq(ray, &rays[i]));
                assert!(std::ptr::eq(hit, many[i].hit.as_ref().expect("a hit")));
                assert!(normals[i].replace(n).is_none(), "ray {i} twice")
            });
            for &(i, r, hit) in &hit_rays {
                let one = normal(r, hit, f, &settings);
                assert_eq!(
                    format!("{:?}", Some(one)),
                    format!("{:?}", normals[i]),
                    "{f:?}"
                );
            }
            assert_eq!(normals.iter().flatten().count(), hit_rays.len());
        }
    }
    assert_ne!(runs[0], runs[1], "confirming hits changed no march");
}

#[test]
fn hits_the_unit_ball_where_geometry_says() {
    let r = ray(DVec3::new(0.0, 0.0, 3.0), -DVec3::Z);
    let m = march(&r, &unit_ball(), &MarchSettings::default());
    let hit = m.hit.expect("ray through the centre hits");
    // The hit fires once the estimate is below half a footprint (1e-3 at t≈2);
    // the estimate is about half the true distance, so the hit lies within 2e-3.
    assert!(hit.t < 2.0 && hit.t > 2.0 - 2e-3, "t = {}", hit.t);
    let (n, _) = normal(&r, &hit, &unit_ball(), &MarchSettings::default());
    assert!(n.dot(DVec3::Z) > 0.99, "normal {n}");
}

#[test]
fn misses_when_ray_passes_beside() {
    let r = ray(DVec3::new(0.0, 1.2, 3.0), -DVec3::Z);
    let m = march(&r, &unit_ball(), &MarchSettings::default());
    assert!(m.hit.is_none());
    assert!(m.evaluations > 0);
    let away = ray(DVec3::new(0.0, 0.0, 3.0), DVec3::Z);
    assert_eq!(
        march(&away, &unit_ball(), &MarchSettings::default()).evaluations,
        0
    );
}

#[test]
fn hit_threshold_scales_with_footprint() {
    let far = ray(DVec3::new(0.0, 0.0, 3.0), -DVec3::Z);
    assert!((far.footprint(2.0) - 2e-3).abs() < 1e-15);
    // The marcher stops further from the surface when pixels are wider:
    // the gap to the unit sphere is below the threshold in each case and
    // the coarse pixel stops well before the fine one.
    let settings = MarchSettings::default();
    let gap = |pixel_angle: Real| {
        let r = Ray { pixel_angle, ..far };
        2.0 - march(&r, &unit_ball(), &settings).hit.unwrap().t
    };
    let (coarse, fine) = (gap(1e-1), gap(1e-5));
    assert!(
        coarse < 2.0 * settings.hit_threshold * 0.2 && coarse > 1e-3,
        "{coarse}"
    );
    assert!(
        fine < 2.0 * settings.hit_threshold * 2e-5 && fine >= 0.0,
        "{fine}"
    );
}

#[test]
fn over_relaxation_never_steps_through_the_surface() {
    // Rays from all around at every angle of incidence, down to grazing:
    // whatever the relaxation, the hit is the sphere's first crossing
    // within the threshold, and grazing misses stay misses.
    let ball = unit_ball();
    let mut spent = Vec::new();
    for omega in [1.0, 1.2, 1.5, 1.9] {
        let mut evaluations = 0;
        let settings = MarchSettings {
            over_relaxation: omega,
            ..MarchSettings::default()
        };
        for i in 0..200 {
            let offset = i as Real / 200.0 * 1.1; // impact parameter 0 … 1.1
            let origin = DVec3::new(offset, 0.0, 3.0);
            let r = ray(origin, -DVec3::Z);
            let m = march(&r, &ball, &settings);
            evaluations += m.evaluations;
            if offset < 1.0 {
                let exact = 3.0 - (1.0 - offset * offset).sqrt();
                let hit = m
                    .hit
                    .unwrap_or_else(|| panic!("ω={omega}, b={offset}: missed"));
                // The estimate is half the true distance near this sphere
                // (½·r·ln r / |dz|), so hits stop within twice the threshold.
                let tolerance = 2.0 * settings.hit_threshold * r.footprint(exact);
                // Within that of the surface, on the near side.
                let gap = hit.point.length() - 1.0;
                assert!(
                    gap.abs() <= tolerance && hit.t <= exact + tolerance,
                    "ω={omega}, b={offset}: t={} exact={exact} gap={gap}",
                    hit.t
                );
            } else if offset > 1.02 {
                // Beyond a few footprints of the silhouette (within it a
                // grazing ray may legitimately stop).
                assert!(m.hit.is_none(), "ω={omega}, b={offset}");
            }
        }
        spent.push(evaluations);
    }
    // And the default pays: fewer estimates (on this smooth sphere larger
    // factors take back too many steps to gain).
    assert!(spent[1] < spent[0], "{spent:?}");
}

#[test]
fn camera_inside_the_set_hits_at_once_and_never_steps_back() {
    // Naive: inside, ln(r) with r < 1 makes ½·ln r·r/dr negative, a step backwards.
    let r_inside: Real = 0.5;
    assert!(0.5 * r_inside.ln() * r_inside < 0.0);
    let f = Fractal::default();
    let r = ray(DVec3::new(0.0, 0.1, 0.0), DVec3::Z);
    let m = march(&r, &f, &MarchSettings::default());
    let hit = m.hit.expect("a ray from inside hits");
    assert_eq!(hit.t, 0.0);
    assert_eq!(m.evaluations, 1);
}

#[test]
fn rays_out_of_steps_are_hits_every_time() {
    // Two steps are too few to reach the bulb from the sphere: the decision
    // must be the same hit on every call (no speckle, no flicker).
    let settings = MarchSettings {
        max_steps: 2,
        ..MarchSettings::default()
    };
    let f = Fractal::default();
    let r = ray(DVec3::new(0.2, 0.3, 3.0), -DVec3::Z);
    let result = march(&r, &f, &settings);
    assert!(result.out_of_steps, "and is counted as out of steps");
    let first = result.hit.expect("out of steps counts as a hit");
    // With steps enough, the same ray's hit is a true one.
    assert!(!march(&r, &f, &MarchSettings::default()).out_of_steps);
    for _ in 0..5 {
        assert_eq!(march(&r, &f, &settings).hit.unwrap().t, first.t);
    }
    assert!(first.t.is_finite() && first.point.is_finite());
}

#[test]
fn confirming_hits_is_left_out_of_the_settings_hash_when_off() {
    // Frames are hashed from the serialised scene: a setting at its
    // default must not change every frame's hash.
    let off = ron::to_string(&MarchSettings::default()).unwrap();
    assert!(!off.contains("confirm_hits"), "{off}");
    let on = MarchSettings {
        confirm_hits: true,
        ..MarchSettings::default()
    };
    assert!(ron::to_string(&on).unwrap().contains("confirm_hits:true"));
}

/// Rays fanned across the bulb's limb, where the analytic estimate
/// understates on grazing rays and potential checks fail; each marched
/// with the check off and on, at every `max_steps` from 1 to 59.
fn limb_marches() -> Vec<(usize, Ray, u32, MarchResult, MarchResult)> {
    let origin = DVec3::new(0.2, -2.8, 0.5);
    let fractal = Fractal::default();
    let mut out = vec![];
    for i in 0..120 {
        let a = i as Real / 120.0;
        let r = ray(
            origin,
            -origin + DVec3::new(2.4 * a - 1.2, 0.0, 0.6 * (5.0 * a).sin()),
        );
        for max_steps in 1..60 {
            let settings = |confirm_hits| MarchSettings {
                max_steps,
                confirm_hits,
                ..MarchSettings::default()
            };
            let off = march(&r, &fractal, &settings(false));
            let on = march(&r, &fractal, &settings(true));
            out.push((i, r, max_steps, off, on));
        }
    }
    out
}

#[test]
fn a_ray_out_of_steps_after_a_failed_check_stops_at_the_hit_it_failed() {
    let (mut cases, mut stopped_back) = (0, 0);
    for (i, r, max_steps, off, on) in limb_marches() {
        let (Some(off_hit), Some(on_hit)) = (&off.hit, &on.hit) else {
            continue;
        };
        if off.out_of_steps || !on.out_of_steps {
            continue;
        }
        // The check failed the hit `off` stopped at and the ray went
        // on: out of steps, it stops there or at a nearer point after.
        cases += 1;
        let threshold = MarchSettings::default().hit_threshold * r.footprint(on_hit.t);
        assert!(
            on_hit.t <= off_hit.t || on_hit.estimate.distance < threshold,
            "ray {i} at {max_steps} steps stopped at {} past its hit at {}",
            on_hit.t,
            off_hit.t
        );
        stopped_back += (on_hit.t == off_hit.t) as usize;
    }
    assert!(stopped_back > 0, "{cases} rays out of steps after a check");
}

#[test]
fn a_hit_at_the_last_step_is_not_checked() {
    let marches = limb_marches();
    let (mut last_step_hits, mut checkable) = (0, 0);
    for pair in marches.windows(2) {
        let ((_, _, _, before, _), (i, r, max_steps, off, on)) = (&pair[0], &pair[1]);
        // `off` hit at its last allowed step: one step fewer ran out.
        let at_last =
            *max_steps > 1 && before.out_of_steps && off.hit.is_some() && !off.out_of_steps;
        if at_last {
            last_step_hits += 1;
            // One the check would take up at any earlier step.
            let hit = off.hit.expect("a hit");
            let coarse = REFINED * MarchSettings::default().hit_threshold * r.footprint(hit.t);
            checkable += (hit.estimate.distance >= coarse) as usize;
            assert_eq!(
                format!("{off:?}"),
                format!("{on:?}"),
                "ray {i} at {max_steps} steps"
            );
        }
    }
    assert!(
        checkable > 5,
        "{checkable} of {last_step_hits} hits at the last step to check"
    );
}
