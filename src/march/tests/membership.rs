//! The membership reference and the walk that lands on its crossing.

use super::*;

#[test]
fn membership_reference_finds_the_unit_sphere() {
    let r = ray(DVec3::new(0.0, 0.0, 3.0), -DVec3::Z);
    let (t, tests) = march_by_membership(
        &r,
        &unit_ball(),
        &MarchSettings::default(),
        0.25,
        1e-9,
        1_000_000,
    );
    let t = t.unwrap();
    // Quarter-footprint steps from the sphere (t = 1.5) to t = 2 number
    // ln(2/1.5)/(0.25·1e-3) ≈ 1151, then about 11 bisections.
    assert!((1140..1180).contains(&tests), "{tests} tests");
    // Bisected to a thousandth of the 2e-3 footprint, from the outside.
    assert!(t <= 2.0 && t > 2.0 - 2e-6, "{t}");
    let beside = ray(DVec3::new(0.0, 1.2, 3.0), -DVec3::Z);
    assert!(march_by_membership(
        &beside,
        &unit_ball(),
        &MarchSettings::default(),
        0.25,
        1e-9,
        1_000_000
    )
    .0
    .is_none());
}

#[test]
fn overshooting_steps_are_caught_by_membership() {
    // A fudge of 3 makes every step overshoot, as an estimator that
    // overestimates would. On the unit ball the exact answer is known: every
    // hit must lie outside the ball and within the hit threshold of it.
    let settings = MarchSettings {
        fudge: 3.0,
        ..MarchSettings::default()
    };
    let mut hits = 0;
    for i in 0..40 {
        let a = i as Real * 0.37;
        let origin = DVec3::new(a.cos() * 2.5, (a * 0.7).sin(), a.sin() * 2.5);
        let r = ray(
            origin,
            -origin + DVec3::new(0.0, 0.3 * (a * 3.0).sin(), 0.0),
        );
        if let Some(hit) = march(&r, &unit_ball(), &settings).hit {
            let gap = hit.point.length() - 1.0;
            let limit = settings.hit_threshold * r.footprint(hit.t);
            assert!(
                gap > 0.0 && gap <= limit * 1.0001,
                "ray {i}: gap {gap}, limit {limit}"
            );
            hits += 1;
        }
    }
    assert!(hits > 30);
}

#[test]
fn no_method_stops_past_the_membership_crossing() {
    // Random rays at the bulb: whatever the estimator, the hit may come early
    // (a pixel cone grazing a feature in front) but never more than one
    // footprint past where the centre ray really enters the set.
    use crate::fractal::DeMethod;
    let settings = MarchSettings::default();
    for de in DeMethod::ALL {
        let f = Fractal {
            de,
            ..Fractal::default()
        };
        let mut checked = 0;
        for i in 0..60u64 {
            let u = |d: u32| crate::math::sample_1d(99, 0, i, 0, d);
            let origin = DVec3::new(u(0) - 0.5, u(1) - 0.5, u(2) - 0.5).normalize() * 2.5;
            let aim = DVec3::new(u(3) - 0.5, u(4) - 0.5, u(5) - 0.5) * 0.8;
            let r = Ray {
                origin,
                dir: (aim - origin).normalize(),
                pixel_angle: 2e-3,
                start_footprint: 0.0,
            };
            let (reference, _) = march_by_membership(&r, &f, &settings, 0.125, 1e-9, 1_000_000);
            if let (Some(hit), Some(t)) = (march(&r, &f, &settings).hit, reference) {
                assert!(
                    hit.t <= t + r.footprint(t),
                    "{de:?} ray {i}: hit {} past crossing {t}",
                    hit.t
                );
                checked += 1;
            }
        }
        assert!(checked > 20, "{de:?}: only {checked} rays hit");
    }
}

#[test]
fn membership_walk_lands_on_the_crossing_the_estimate_stops_short_of() {
    // Near the bulb's surface the estimate understates the distance, so a
    // ray that trusts it stops where no point of the set is within its
    // hit threshold further on. Walking by membership, every hit has a
    // point of the set within hit_threshold footprints further along
    // the ray: the crossing it was bisected from.
    let f = Fractal::default();
    let trusting = MarchSettings::default();
    let walking = MarchSettings {
        membership_step: 0.25,
        ..MarchSettings::default()
    };
    let (mut trusted_on, mut walked_on, mut hits) = (0, 0, 0);
    for i in 0..200u64 {
        let u = |d: u32| crate::math::sample_1d(7, 0, i, 0, d);
        let origin = DVec3::new(u(0) - 0.5, u(1) - 0.5, u(2) - 0.5).normalize() * 2.5;
        let aim = DVec3::new(u(3) - 0.5, u(4) - 0.5, u(5) - 0.5) * 0.8;
        let r = Ray {
            origin,
            dir: (aim - origin).normalize(),
            pixel_angle: 1e-3,
            start_footprint: 0.0,
        };
        // A point of the set within the threshold further on, sampled
        // finely: the crossing may be a sheet far thinner than a footprint.
        let on = |hit: Option<Hit>, settings: &MarchSettings| {
            hit.is_some_and(|h| {
                let reach = settings.hit_threshold * r.footprint(h.t);
                (1..=256).any(|k| f.contains(r.at(h.t + reach * k as Real / 256.0)))
            })
        };
        let (a, b) = (march(&r, &f, &trusting).hit, march(&r, &f, &walking).hit);
        hits += b.is_some() as u32;
        trusted_on += on(a, &trusting) as u32;
        walked_on += on(b, &walking) as u32;
    }
    assert!(hits > 50, "{hits} hits");
    assert_eq!(walked_on, hits, "every walked hit is on a crossing");
    assert!(
        trusted_on < hits / 2,
        "{trusted_on} of {hits} trusted hits on one"
    );
}

#[test]
fn membership_walk_never_stops_outside_the_set_it_reached() {
    // On the unit ball the walk ends within hit_threshold footprints
    // short of the sphere, from outside, for any walk step; and a ray
    // passing beside it, however near, misses (no threshold fattens it).
    for step in [0.05, 0.5, 4.0] {
        let settings = MarchSettings {
            membership_step: step,
            ..MarchSettings::default()
        };
        for i in 0..50 {
            let b = i as Real / 50.0 * 0.999;
            let r = ray(DVec3::new(b, 0.0, 3.0), -DVec3::Z);
            let hit = march(&r, &unit_ball(), &settings).hit.expect("hits");
            let gap = hit.point.length() - 1.0;
            let limit = settings.hit_threshold * r.footprint(hit.t);
            assert!(
                gap > 0.0 && gap <= limit * 1.0001,
                "step {step}, b {b}: gap {gap}"
            );
        }
        let beside = ray(DVec3::new(1.0 + 1e-3, 0.0, 3.0), -DVec3::Z);
        assert!(march(&beside, &unit_ball(), &settings).hit.is_none());
    }
    // Half a footprint off the sphere, the estimate alone calls it a hit.
    let beside = ray(DVec3::new(1.0 + 1e-3, 0.0, 3.0), -DVec3::Z);
    assert!(march(&beside, &unit_ball(), &MarchSettings::default())
        .hit
        .is_some());
}
