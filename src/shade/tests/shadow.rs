//! Shadows and occlusion: known answers, and side by side equal to alone.

use super::*;

#[test]
fn occlusion_packed_across_points_is_each_points_own() {
    // Real surface points, their samples packed across points (a call
    // holding the end of one point's samples and the start of the
    // next's), against each point alone, bit for bit.
    let fractal = Fractal::default();
    let settings = MarchSettings::default();
    let points = bulb_points(40, 5, &fractal, &settings);
    assert!(points.len() > 10, "{} surface points", points.len());
    for samples in [1, 3, 5, 16, 21] {
        let ao = AmbientOcclusion {
            samples,
            radius: 0.2,
            ..AmbientOcclusion::default()
        };
        let mut packed = vec![None; points.len()];
        let sites = points
            .iter()
            .enumerate()
            .map(|(i, at)| (i, at.point, at.normal, at.t, at.footprint));
        occlusions(&fractal, &ao, sites, |i, out| {
            assert!(packed[i].replace(out).is_none(), "point {i} twice")
        });
        // The documented sum, one scalar estimate at a time.
        let by_hand = |at: &SurfacePoint| {
            let (mut blocked, mut weights, mut weight, mut spent) = (0.0, 0.0, 1.0, 0);
            for k in 1..=samples {
                let d = ao.radius * at.t * k as Real / samples as Real;
                let e = fractal.estimate(at.point + at.normal * d, at.footprint);
                spent += e.orbits as u64;
                blocked += weight * ((d - 2.0 * e.distance) / d).clamp(0.0, 1.0);
                weights += weight;
                weight *= 0.6;
            }
            let ambient = 1.0 - ao.strength as Real * blocked / weights;
            (ambient.clamp(0.0, 1.0) as f32, spent)
        };
        let mut occluded = 0;
        for (at, packed) in points.iter().zip(&packed) {
            let (a, spent) = occlusion(&fractal, &ao, at.point, at.normal, at.t, at.footprint);
            let (b, packed_spent) = packed.expect("every point");
            assert_eq!(
                (a.to_bits(), spent),
                (b.to_bits(), packed_spent),
                "{samples}"
            );
            let (c, hand_spent) = by_hand(at);
            assert_eq!((a.to_bits(), spent), (c.to_bits(), hand_spent), "{samples}");
            occluded += (a < 0.99) as usize;
        }
        assert!(occluded > 2, "{occluded} occluded with {samples} samples");
    }
}

#[test]
fn shadow_rays_walked_side_by_side_match_one_at_a_time() {
    // Surface points on the bulb lit by three lights, some facing away:
    // `shade` with its own shadow rays against `shade_with` fed the
    // outcomes `walk_many` found for `shadow_walks`, bit for bit.
    let fractal = Fractal::default();
    let settings = MarchSettings::default();
    let mut look = Look::default();
    for (direction, intensity) in [(DVec3::new(-1.0, 0.2, 0.3), 0.5), (DVec3::NEG_Y, 0.3)] {
        look.extra_lights.push(Light {
            direction,
            intensity,
            ..Light::default()
        });
    }
    let effects = Effects {
        shadows: Some(Shadows {
            max_steps: 40,
            ..Shadows::default()
        }),
        ..Effects::default()
    };
    // Real surface points: where rays from around the bulb meet it.
    let points = bulb_points(80, 3, &fractal, &settings);
    let walks: Vec<_> = points
        .iter()
        .flat_map(|at| look.shadow_walks(&effects, &settings, at))
        .collect();
    let mut outcomes = vec![(f32::NAN, 0); walks.len()];
    crate::march::walk_many(walks, &fractal, &settings, |i, out| outcomes[i] = out);
    let mut outcomes = outcomes.into_iter();
    let (mut shaded, mut partly) = (0, 0);
    for at in &points {
        let (mut one, mut many) = (StageCounts::default(), StageCounts::default());
        let alone = look.shade(&effects, &fractal, &settings, at, &mut one);
        let mut next = std::iter::from_fn(|| {
            let out = outcomes.next().expect("an outcome per walk");
            shaded += (out.0 < 1.0) as u32;
            partly += (out.0 > 0.0 && out.0 < 1.0) as u32;
            Some(out)
        });
        let batched = look.shade_with(&effects, at, &mut many, &mut next, None);
        assert_eq!(
            alone.to_array().map(f32::to_bits),
            batched.to_array().map(f32::to_bits)
        );
        assert_eq!(one, many);
    }
    assert!(outcomes.next().is_none(), "a walk no light asked for");
    assert!(
        shaded > 10 && partly > 3,
        "{shaded} shaded, {partly} in penumbra"
    );
}

#[test]
fn shadow_is_one_in_the_open_and_zero_behind_the_ball() {
    let settings = MarchSettings::default();
    for softness in [0.0, 16.0] {
        let sh = Shadows {
            softness,
            ..Shadows::default()
        };
        // On top of the ball, light from above: open sky.
        let (open, spent) = shadow(
            &unit_ball(),
            &settings,
            &sh,
            DVec3::new(0.0, 1.01, 0.0),
            DVec3::Y,
            1e-3,
        );
        assert_eq!(open, 1.0, "softness {softness}");
        assert!(spent > 0);
        // Below the ball, light from above: blocked.
        let (blocked, _) = shadow(
            &unit_ball(),
            &settings,
            &sh,
            DVec3::new(0.0, -1.01, 0.0),
            DVec3::Y,
            1e-3,
        );
        assert_eq!(blocked, 0.0, "softness {softness}");
    }
    // A ray that grazes the ball is in the penumbra: strictly between.
    let sh = Shadows::default();
    let (partial, _) = shadow(
        &unit_ball(),
        &settings,
        &sh,
        DVec3::new(1.02, -1.0, 0.0),
        DVec3::Y,
        1e-3,
    );
    assert!(partial > 0.0 && partial < 1.0, "{partial}");
}

#[test]
fn occlusion_is_one_in_the_open_and_less_in_a_crevice() {
    let ao = AmbientOcclusion::default();
    // On the ball's surface facing out, nothing is near: fully open.
    let (open, spent) = occlusion(
        &unit_ball(),
        &ao,
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::Y,
        1.0,
        1e-3,
    );
    assert!(open > 0.999, "{open}");
    assert_eq!(spent, ao.samples as u64);
    // Facing into the ball, the field closes in on every sample.
    let (closed, _) = occlusion(
        &unit_ball(),
        &ao,
        DVec3::new(0.0, 1.0, 0.0),
        -DVec3::Y,
        1.0,
        1e-3,
    );
    assert!(closed < 0.2, "{closed}");
}
