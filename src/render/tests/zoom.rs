//! Deep zooms: how far each precision keeps the surface sharp.

use crate::fractal::Fractal;
use crate::march::*;
use crate::math::{DVec3, Real};

/// Hits (t and point) of an n×n block of pixels in the middle of a
/// 1920×1080 frame, with the camera `distance` from a surface point,
/// looking straight at it; with each ray's footprint at the hit.
/// Where the deep-zoom measurements look at the bulb: the surface
/// point on the ray from `origin` along `dir`.
const SURFACES: [(DVec3, DVec3); 2] = [
    (DVec3::new(0.1, 0.35, 2.0), DVec3::new(0.3, -0.2, -1.0)),
    (DVec3::new(-0.4, 0.2, 2.0), DVec3::new(0.2, -0.1, -1.0)),
];

fn block_hits_with_depth(
    precision: crate::fractal::Precision,
    distance: Real,
    n: u32,
) -> Vec<(Real, DVec3, Real)> {
    block_hits_at(SURFACES[0], precision, distance, n)
}

fn block_hits_at(
    (origin, dir): (DVec3, DVec3),
    precision: crate::fractal::Precision,
    distance: Real,
    n: u32,
) -> Vec<(Real, DVec3, Real)> {
    let f = Fractal {
        precision,
        iterations: 30,
        ..Fractal::default()
    };
    // The surface point on a fixed ray: membership steps of 1e-4, then
    // bisection to the last bit of f64.
    let dir = dir.normalize();
    let exact = Fractal {
        iterations: 30,
        ..Fractal::default()
    };
    let mut lo = 0.0;
    while !exact.contains(origin + dir * (lo + 1e-4)) {
        lo += 1e-4;
    }
    let mut hi = lo + 1e-4;
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if exact.contains(origin + dir * mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let target = origin + dir * lo;
    let camera = crate::camera::Camera {
        position: target - dir * distance,
        target,
        up: DVec3::Y,
        roll_degrees: 0.0,
        fov_degrees: 40.0,
        ..crate::camera::Camera::default()
    }
    .frame();
    let settings = MarchSettings::default();
    let mut hits = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let r = camera.ray(960.0 + x as Real, 540.0 + y as Real, 1920, 1080);
            if let Some(h) = march(&r, &f, &settings).hit {
                hits.push((h.t, h.point, r.footprint(h.t)));
            }
        }
    }
    hits
}

fn block_hits(precision: crate::fractal::Precision, distance: Real, n: u32) -> Vec<DVec3> {
    block_hits_with_depth(precision, distance, n)
        .into_iter()
        .map(|(_, p, _)| p)
        .collect()
}

fn distinct(points: &[DVec3]) -> usize {
    let mut v: Vec<[u64; 3]> = points
        .iter()
        .map(|p| p.to_array().map(f64::to_bits))
        .collect();
    v.sort();
    v.dedup();
    v.len()
}

#[test]
fn deep_zoom_in_f64_stays_sharp_to_1e_12() {
    // At 1e-12 from the surface, 1920 pixels wide, neighbouring pixels are
    // 3.6e-16 apart at the target: f64 still resolves each of them.
    for distance in [1e-4, 1e-8, 1e-12] {
        let with_depth = block_hits_with_depth(crate::fractal::Precision::F64, distance, 6);
        let hits: Vec<DVec3> = with_depth.iter().map(|h| h.1).collect();
        assert_eq!(hits.len(), 36, "misses at {distance}");
        assert!(hits.iter().all(|p| p.is_finite()));
        assert_eq!(distinct(&hits), 36, "blocky at {distance}");
        // And the depths follow the surface: within half a footprint
        // of a plane (a depth stuck at the camera or in one terrace
        // over a sloping block would not be).
        let off = depth_off_plane(&with_depth, 6);
        assert!(
            off < 0.5,
            "depths {off} footprints off a plane at {distance}"
        );
    }
    // The same test sees blockiness where it exists: f32 at 1e-8.
    let f32_hits = block_hits(crate::fractal::Precision::F32, 1e-8, 6);
    assert!(distinct(&f32_hits) < 36);
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]
        #[test]
        fn marcher_terminates_with_a_finite_result(
            ox in -3.0f64..3.0, oy in -3.0f64..3.0, oz in -3.0f64..3.0,
            dx in -1.0f64..1.0, dy in -1.0f64..1.0, dz in -1.0f64..1.0,
            pixel_angle in 1e-9f64..1e-1,
            power in 2.0f64..10.0,
            julia in proptest::option::of((-1.2f64..1.2, -1.2f64..1.2, -1.2f64..1.2)),
        ) {
            let dir = DVec3::new(dx, dy, dz);
            prop_assume!(dir.length() > 1e-3);
            let f = Fractal {
                power,
                julia: julia.map(|(a, b, c)| DVec3::new(a, b, c)),
                ..Fractal::default()
            };
            let settings = MarchSettings::default();
            let r = Ray { origin: DVec3::new(ox, oy, oz), dir: dir.normalize(), pixel_angle, start_footprint: 0.0 };
            let m = march(&r, &f, &settings);
            // Every step and bisection is bounded: 300 steps plus at most ~1100 bisections.
            prop_assert!(m.evaluations <= settings.max_steps + 1200);
            if let Some(hit) = m.hit {
                prop_assert!(hit.t.is_finite() && hit.t >= 0.0 && hit.point.is_finite());
                let (n, _) = normal(&r, &hit, &f, &settings);
                prop_assert!(n.is_finite() && (n.length() - 1.0).abs() < 1e-9);
            }
        }
    }
}

/// Root-mean-square distance of hit depths from the plane that fits
/// them best over the pixel grid (`n`×`n`, row by row), in footprints:
/// how far a deep zoom's depths depart from the smooth surface they sample.
fn depth_off_plane(hits: &[(Real, DVec3, Real)], n: u32) -> Real {
    // Least squares of t = a + b·x + c·y over a full grid: x and y are
    // centred, so the three coefficients separate.
    let m = (n as Real - 1.0) / 2.0;
    let at = |i: usize| ((i as u32 % n) as Real - m, (i as u32 / n) as Real - m);
    let count = hits.len() as Real;
    let a = hits.iter().map(|h| h.0).sum::<Real>() / count;
    let sxx: Real = (0..hits.len()).map(|i| at(i).0.powi(2)).sum();
    let b = hits
        .iter()
        .enumerate()
        .map(|(i, h)| at(i).0 * h.0)
        .sum::<Real>()
        / sxx;
    let c = hits
        .iter()
        .enumerate()
        .map(|(i, h)| at(i).1 * h.0)
        .sum::<Real>()
        / sxx;
    let squares: Real = hits
        .iter()
        .enumerate()
        .map(|(i, h)| ((h.0 - a - b * at(i).0 - c * at(i).1) / h.2).powi(2))
        .sum();
    (squares / count).sqrt()
}

fn distinct_depths(hits: &[(Real, DVec3, Real)]) -> usize {
    let mut v: Vec<u64> = hits.iter().map(|h| h.0.to_bits()).collect();
    v.sort();
    v.dedup();
    v.len()
}

#[test]
#[ignore = "measurement for docs/stability.md: cargo test --release -- --ignored zoom_depth_limits --nocapture"]
fn zoom_depth_limits() {
    use crate::fractal::Precision;
    let distances = [
        1e-3, 1e-4, 1e-5, 1e-6, 1e-8, 1e-10, 1e-12, 5e-13, 2e-13, 1e-13, 5e-14, 2e-14, 1e-14,
        5e-15, 2e-15,
    ];
    for d in distances {
        let wide = block_hits_with_depth(Precision::F64, d, 8);
        let single = block_hits_with_depth(Precision::F32, d, 8);
        let median_off = |a: &[(Real, DVec3, Real)], b: &[(Real, DVec3, Real)]| {
            let mut e: Vec<Real> = a
                .iter()
                .zip(b)
                .map(|(a, b)| (a.0 - b.0).abs() / a.2)
                .collect();
            e.sort_by(|a, b| a.total_cmp(b));
            e.get(e.len() / 2).copied().unwrap_or(Real::NAN)
        };
        let other = |p| block_hits_at(SURFACES[1], p, d, 8);
        eprintln!(
            "{d:e} second surface: f32 depth off f64 by median {:.2} footprints",
            median_off(&other(Precision::F64), &other(Precision::F32))
        );
        let mut errors: Vec<Real> = wide
            .iter()
            .zip(&single)
            .map(|(a, b)| (a.0 - b.0).abs() / a.2)
            .collect();
        errors.sort_by(|a, b| a.total_cmp(b));
        let points: Vec<DVec3> = wide.iter().map(|h| h.1).collect();
        let plane = if wide.len() == 64 {
            format!("{:.2}", depth_off_plane(&wide, 8))
        } else {
            "-".into()
        };
        eprintln!(
            "{d:e}: f64 {} hits, {} distinct points, {} distinct depths, {plane} footprints off a plane; f32 depth off f64 by median {:.2} / max {:.2} footprints",
            wide.len(),
            distinct(&points),
            distinct_depths(&wide),
            errors.get(errors.len() / 2).copied().unwrap_or(Real::NAN),
            errors.last().copied().unwrap_or(Real::NAN),
        );
    }
}
