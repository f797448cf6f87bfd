//! Small geometry helpers: guarded normalisation and the ray–sphere interval.

use super::{DVec3, Real};

/// Returns `v` normalised, or `fallback` when `v` is zero or not finite.
pub fn normalize_or(v: DVec3, fallback: DVec3) -> DVec3 {
    let v = lifted(v);
    let len = v.length();
    if len.is_finite() && len > 1e-300 {
        v / len
    } else {
        fallback
    }
}

/// Below this a vector's squared components leave f64's range (they
/// pass under 1e-308): a deep frame's offsets go to 1e-300.
const SQUARES_UNDERFLOW: Real = 1e-140;

/// `v` over its largest component where that is below
/// `SQUARES_UNDERFLOW`, so that its length can be taken; else `v`.
fn lifted(v: DVec3) -> DVec3 {
    let most = v.abs().max_element();
    if most > 0.0 && most < SQUARES_UNDERFLOW {
        v / most
    } else {
        v
    }
}

/// glam's `normalize`, also where the squares of `v` underflow (a deep
/// frame's offsets): the same bits wherever they do not.
pub fn direction(v: DVec3) -> DVec3 {
    lifted(v).normalize()
}

/// |v|, also where its squares underflow (a deep frame's offsets).
pub fn length(v: DVec3) -> Real {
    let most = v.abs().max_element();
    if most > 0.0 && most < SQUARES_UNDERFLOW {
        most * (v / most).length()
    } else {
        v.length()
    }
}

/// Ray–sphere intersection (sphere centred on the origin, `dir` of unit
/// length). Returns the entry and exit distances along the ray, entry
/// clamped to 0 when the origin is inside. The discriminant is r² less the
/// squared distance from the centre to the ray's line, not (o·d)² − |o|² + r²,
/// whose two large terms cancel r² away for a camera far from the sphere
/// (|o|² of 2e18 at a billion units holds nothing finer than 256).
pub fn sphere_interval(origin: DVec3, dir: DVec3, radius: Real) -> Option<(Real, Real)> {
    let b = origin.dot(dir);
    let disc = radius * radius - (origin - dir * b).length_squared();
    if disc < 0.0 {
        return None;
    }
    let root = disc.sqrt();
    let (t0, t1) = (-b - root, -b + root);
    if t1 < 0.0 {
        return None;
    }
    Some((t0.max(0.0), t1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_interval_from_outside_and_inside() {
        let (t0, t1) = sphere_interval(DVec3::new(0.0, 0.0, 5.0), -DVec3::Z, 1.0).unwrap();
        assert!((t0 - 4.0).abs() < 1e-12 && (t1 - 6.0).abs() < 1e-12);
        let (t0, t1) = sphere_interval(DVec3::ZERO, DVec3::X, 2.0).unwrap();
        assert_eq!(t0, 0.0);
        assert!((t1 - 2.0).abs() < 1e-12);
        assert!(sphere_interval(DVec3::new(0.0, 3.0, 5.0), -DVec3::Z, 1.0).is_none());
        assert!(sphere_interval(DVec3::new(0.0, 0.0, 5.0), DVec3::Z, 1.0).is_none());
    }

    #[test]
    fn sphere_interval_holds_for_a_camera_a_billion_units_away() {
        // Rays down -z from (0, h, 1e9): the line passes h from the centre,
        // so it crosses a sphere of radius 1.5 for h = 1 (over 2·√1.25) and
        // misses it for h = 1.6.
        let far = 1e9;
        let naive = |o: DVec3, d: DVec3, r: Real| {
            let b = o.dot(d);
            b * b - (o.length_squared() - r * r)
        };
        let (hit, miss) = (DVec3::new(0.0, 1.0, far), DVec3::new(0.0, 1.6, far));
        // (o·d)² − |o|² + r²: r² is lost beside |o|² = 1e18, for both rays.
        assert_eq!(naive(hit, -DVec3::Z, 1.5), 0.0);
        assert_eq!(naive(miss, -DVec3::Z, 1.5), 0.0);
        let (t0, t1) = sphere_interval(hit, -DVec3::Z, 1.5).unwrap();
        let half = 1.25f64.sqrt();
        assert!((t0 - (far - half)).abs() < 1e-6, "{t0}");
        assert!((t1 - (far + half)).abs() < 1e-6, "{t1}");
        assert!(sphere_interval(miss, -DVec3::Z, 1.5).is_none());
    }

    #[test]
    fn normalize_or_guards_zero_and_nan() {
        assert_eq!(normalize_or(DVec3::ZERO, DVec3::Y), DVec3::Y);
        assert_eq!(normalize_or(DVec3::splat(f64::NAN), DVec3::Y), DVec3::Y);
        assert!((normalize_or(DVec3::new(3.0, 4.0, 0.0), DVec3::Y).length() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn lengths_and_directions_hold_past_the_squares_range() {
        let v = DVec3::new(3e-300, 4e-300, 0.0);
        assert!((length(v) / 5e-300 - 1.0).abs() < 1e-15, "{}", length(v));
        let unit = normalize_or(v, DVec3::Y);
        assert!(
            (unit - DVec3::new(0.6, 0.8, 0.0)).length() < 1e-15,
            "{unit}"
        );
        // Where squares hold, the plain length to the bit.
        let w = DVec3::new(0.3, -0.2, 0.7);
        assert_eq!(length(w), w.length());
        assert_eq!(normalize_or(w, DVec3::Y), w / w.length());
        assert_eq!(direction(w), w.normalize());
        assert!((direction(v) - DVec3::new(0.6, 0.8, 0.0)).length() < 1e-15);
    }
}
