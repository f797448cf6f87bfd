//! Shadow bundles: the shared march changes no ray's light beyond a
//! hair, never lights a ray that is blocked, and saves estimates.

use super::*;
use crate::march::walk_many;

/// Where a 4×4 block of camera rays around `dir` from `origin` meets the
/// bulb, one ray per pixel of angle `pixel`.
fn block_points(origin: DVec3, dir: DVec3, pixel: Real, fractal: &Fractal) -> Vec<SurfacePoint> {
    let settings = MarchSettings::default();
    let right = dir.cross(DVec3::Y).normalize();
    let up = right.cross(dir);
    (0..16)
        .filter_map(|k| {
            let (x, y) = ((k % 4) as Real - 1.5, (k / 4) as Real - 1.5);
            let ray = crate::march::Ray {
                origin,
                dir: (dir + (right * x + up * y) * pixel).normalize(),
                pixel_angle: pixel,
                start_footprint: 0.0,
            };
            surface_at(&ray, fractal, &settings)
        })
        .collect()
}

/// Each shadow ray's outcome (light, estimates spent).
type Outcomes = Vec<(f32, u64)>;

/// Shadow walks as `Look::shadow_walks` lists them.
type Walks = Vec<Result<ShadowWalk, (f32, u64)>>;

/// The shadow walks of `blocks` and each block's range of them.
fn block_walks(
    blocks: &[Vec<SurfacePoint>],
    look: &Look,
    effects: &Effects,
) -> (Walks, Vec<std::ops::Range<usize>>) {
    let settings = MarchSettings::default();
    let (mut walks, mut groups) = (Vec::new(), Vec::new());
    for block in blocks {
        let first = walks.len();
        walks.extend(
            block
                .iter()
                .flat_map(|at| look.shadow_walks(effects, &settings, at)),
        );
        groups.push(first..walks.len());
    }
    (walks, groups)
}

/// `walks`' outcomes walked alone, and bundled by `groups`.
fn alone_and_bundled(
    walks: &[Result<ShadowWalk, (f32, u64)>],
    groups: Vec<std::ops::Range<usize>>,
    fractal: &Fractal,
) -> (Outcomes, Outcomes) {
    let settings = MarchSettings::default();
    let mut alone = vec![(f32::NAN, 0); walks.len()];
    walk_many(walks.iter().copied(), fractal, &settings, |i, out| {
        alone[i] = out
    });
    let mut bundled = vec![(f32::NAN, 0); walks.len()];
    let mut scratch = BundleScratch::default();
    walk_shadows(
        walks,
        groups.into_iter(),
        fractal,
        &settings,
        &mut bundled,
        &mut scratch,
    );
    (alone, bundled)
}

/// Estimates spent in all.
fn cost(outcomes: &[(f32, u64)]) -> u64 {
    outcomes.iter().map(|o| o.1).sum()
}

#[test]
fn bundled_shadows_light_each_ray_as_it_would_alone_for_fewer_estimates() {
    // Blocks of neighbouring hits all round the bulb, under a light from
    // above and another low from the side (some facing away).
    let fractal = Fractal::default();
    let mut look = Look::default();
    look.extra_lights.push(Light {
        direction: DVec3::new(-1.0, 0.1, 0.4),
        ..Light::default()
    });
    let effects = Effects {
        shadows: Some(Shadows::default()),
        ..Effects::default()
    };
    let blocks: Vec<_> = crate::math::shell_points(60, 2.5..2.6, 7)
        .into_iter()
        .map(|origin| {
            let dir = (DVec3::new(0.1, -0.2, 0.15) - origin).normalize();
            block_points(origin, dir, 2e-4, &fractal)
        })
        .collect();
    let (walks, groups) = block_walks(&blocks, &look, &effects);
    let (alone, bundled) = alone_and_bundled(&walks, groups, &fractal);
    assert!(alone.len() > 600, "{} shadow rays", alone.len());
    let (mut worst, mut blocked, mut lit) = (0.0f32, 0, 0);
    for (a, b) in alone.iter().zip(&bundled) {
        assert!(b.0.is_finite(), "every ray answered");
        worst = worst.max((a.0 - b.0).abs());
        if a.0 == 0.0 {
            blocked += 1;
            assert_eq!(b.0, 0.0, "a blocked ray stays blocked");
        }
        lit += (a.0 == 1.0) as u32;
    }
    assert!(worst <= 0.05, "light moved by {worst}");
    assert!(blocked > 20 && lit > 100, "{blocked} blocked, {lit} lit");
    let saved = cost(&bundled) as f64 / cost(&alone) as f64;
    assert!(
        saved < 0.9,
        "bundled rays spent {saved:.2} of alone's estimates"
    );
}

#[test]
fn a_bundle_passing_the_ball_keeps_its_shadow_and_its_penumbra() {
    // Parallel rays from points on a plane under the unit ball, light
    // straight up: those under the ball are blocked, those beside it lit,
    // and those near its rim in between, bundled or alone.
    let fractal = unit_ball();
    let settings = MarchSettings::default();
    let sh = Shadows::default();
    let footprint = 2e-3;
    let mut walks = Vec::new();
    let mut groups = Vec::new();
    for bx in -40..40 {
        let first = walks.len();
        for k in 0..16 {
            let x = (bx * 4 + k % 4) as Real * footprint * 4.0;
            let z = (k / 4) as Real * footprint;
            let from = DVec3::new(x, -1.2, z);
            walks.push(ShadowWalk::start(&settings, &sh, from, DVec3::Y, footprint));
        }
        groups.push(first..walks.len());
    }
    let mut alone = vec![(f32::NAN, 0); walks.len()];
    walk_many(walks.iter().copied(), &fractal, &settings, |i, out| {
        alone[i] = out
    });
    let mut bundled = vec![(f32::NAN, 0); walks.len()];
    let mut scratch = BundleScratch::default();
    walk_shadows(
        &walks,
        groups.into_iter(),
        &fractal,
        &settings,
        &mut bundled,
        &mut scratch,
    );
    let class = |l: f32| (l == 0.0, l == 1.0);
    let mut penumbra = 0;
    for (a, b) in alone.iter().zip(&bundled) {
        assert_eq!(class(a.0), class(b.0), "{a:?} alone, {b:?} bundled");
        assert!((a.0 - b.0).abs() <= 0.05, "{a:?} alone, {b:?} bundled");
        penumbra += (a.0 > 0.0 && a.0 < 1.0) as u32;
    }
    assert!(penumbra > 10, "{penumbra} rays in the penumbra");
    assert!(cost(&bundled) < cost(&alone), "the bundles shared no march");
}
