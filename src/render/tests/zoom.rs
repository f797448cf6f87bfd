//! Deep zooms: how far each precision keeps the surface sharp.

use crate::fractal::Fractal;
use crate::march::*;
use crate::math::{DVec3, Real};

/// Where the deep-zoom test looks at the bulb: the surface point on the
/// ray from this origin along this direction.
const SURFACE: (DVec3, DVec3) = (DVec3::new(0.1, 0.35, 2.0), DVec3::new(0.3, -0.2, -1.0));

/// Hits (t, point and the ray's footprint there) of an n×n block of pixels
/// in the middle of a 1920×1080 frame, with the camera `distance` from the
/// surface point, looking straight at it.
fn block_hits_with_depth(
    precision: crate::fractal::Precision,
    distance: Real,
    n: u32,
) -> Vec<(Real, DVec3, Real)> {
    let f = Fractal {
        precision,
        iterations: 30,
        ..Fractal::default()
    };
    let (origin, dir) = (SURFACE.0, SURFACE.1.normalize());
    let exact = Fractal {
        iterations: 30,
        ..Fractal::default()
    };
    let target = origin + dir * judge::surface_along(&exact, origin, dir, 1e-4);
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
        let depths: Vec<(Real, Real)> = with_depth.iter().map(|h| (h.0, h.2)).collect();
        let off = judge::depth_off_plane(&depths, 6);
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
