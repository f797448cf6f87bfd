//! How deep a plain f64 zoom stays sharp, and how far f32 departs from it:
//! an 8×8 block of pixels in the middle of a 1920×1080 frame (40° field of
//! view), the camera at each distance from a surface point found by
//! membership alone, 30 iterations. The measurement behind
//! docs/stability.md's "How deep a zoom can go":
//! `cargo run --release --example zoom_depth` (a few seconds).

use mandelreel::camera::Camera;
use mandelreel::fractal::{Fractal, Precision};
use mandelreel::march::judge::{depth_off_plane, surface_along};
use mandelreel::march::{march, MarchSettings};
use mandelreel::math::{DVec3, Real};

/// Two places on the bulb: the surface point on the ray from each origin
/// along each direction.
const SURFACES: [(DVec3, DVec3); 2] = [
    (DVec3::new(0.1, 0.35, 2.0), DVec3::new(0.3, -0.2, -1.0)),
    (DVec3::new(-0.4, 0.2, 2.0), DVec3::new(0.2, -0.1, -1.0)),
];

const DISTANCES: [Real; 15] = [
    1e-3, 1e-4, 1e-5, 1e-6, 1e-8, 1e-10, 1e-12, 5e-13, 2e-13, 1e-13, 5e-14, 2e-14, 1e-14, 5e-15,
    2e-15,
];

/// A hit: its depth, point and the ray's footprint there.
type Hit = (Real, DVec3, Real);

/// The hits of the 8×8 block with the camera `distance` from `surface`.
fn block(surface: (DVec3, DVec3), precision: Precision, distance: Real) -> Vec<Hit> {
    let fractal = |precision| Fractal {
        precision,
        iterations: 30,
        ..Fractal::default()
    };
    let (origin, dir) = (surface.0, surface.1.normalize());
    let target = origin + dir * surface_along(&fractal(Precision::F64), origin, dir, 1e-4);
    let frame = Camera {
        position: target - dir * distance,
        target,
        up: DVec3::Y,
        fov_degrees: 40.0,
        ..Camera::default()
    }
    .frame();
    let (f, settings) = (fractal(precision), MarchSettings::default());
    (0..64)
        .filter_map(|i| {
            let ray = frame.ray(960.0 + (i % 8) as Real, 540.0 + (i / 8) as Real, 1920, 1080);
            let hit = march(&ray, &f, &settings).hit?;
            Some((hit.t, hit.point, ray.footprint(hit.t)))
        })
        .collect()
}

fn distinct<T: Ord>(mut keys: Vec<T>) -> usize {
    keys.sort();
    keys.dedup();
    keys.len()
}

/// The median and largest depth difference between two blocks, in footprints.
fn apart(a: &[Hit], b: &[Hit]) -> (Real, Real) {
    let mut e: Vec<Real> = a
        .iter()
        .zip(b)
        .map(|(a, b)| (a.0 - b.0).abs() / a.2)
        .collect();
    e.sort_by(|a, b| a.total_cmp(b));
    let median = e.get(e.len() / 2).copied().unwrap_or(Real::NAN);
    (median, e.last().copied().unwrap_or(Real::NAN))
}

fn main() {
    println!("| distance | f64 hits | distinct points | distinct depths | off a plane (fp) | f32 off f64, median / max (fp) | second surface: f32 off f64, median (fp) |");
    println!("|---|---:|---:|---:|---:|---:|---:|");
    for d in DISTANCES {
        let wide = block(SURFACES[0], Precision::F64, d);
        let (median, max) = apart(&wide, &block(SURFACES[0], Precision::F32, d));
        let (second, _) = apart(
            &block(SURFACES[1], Precision::F64, d),
            &block(SURFACES[1], Precision::F32, d),
        );
        let plane = if wide.len() == 64 {
            let depths: Vec<(Real, Real)> = wide.iter().map(|h| (h.0, h.2)).collect();
            format!("{:.2}", depth_off_plane(&depths, 8))
        } else {
            "–".into()
        };
        let points = distinct(
            wide.iter()
                .map(|h| h.1.to_array().map(f64::to_bits))
                .collect(),
        );
        let depths = distinct(wide.iter().map(|h| h.0.to_bits()).collect());
        println!(
            "| {d:e} | {} | {points} | {depths} | {plane} | {median:.2} / {max:.2} | {second:.2} |",
            wide.len()
        );
    }
}
