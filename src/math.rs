//! Numeric foundations shared by every other module: the `Real` type used for
//! geometry (f64), the vector and colour types, and a few small guards that keep
//! NaN and infinity from leaking out of the hot path.

pub use glam::{DVec3, Vec3};

/// The floating-point type of all geometry and distance estimation.
pub type Real = f64;

/// Linear blend of two colours, `t` clamped to 0..=1.
pub fn mix(a: Vec3, b: Vec3, t: f32) -> Vec3 {
    a + (b - a) * t.clamp(0.0, 1.0)
}

/// Returns `v` normalised, or `fallback` when `v` is zero or not finite.
pub fn normalize_or(v: DVec3, fallback: DVec3) -> DVec3 {
    let len = v.length();
    if len.is_finite() && len > 1e-300 {
        v / len
    } else {
        fallback
    }
}

/// Replaces a non-finite colour channel by zero so no NaN reaches a pixel.
pub fn finite_or_zero(c: Vec3) -> Vec3 {
    Vec3::new(
        if c.x.is_finite() { c.x } else { 0.0 },
        if c.y.is_finite() { c.y } else { 0.0 },
        if c.z.is_finite() { c.z } else { 0.0 },
    )
}

/// Ray–sphere intersection (sphere centred on the origin). Returns the entry and
/// exit distances along the ray, entry clamped to 0 when the origin is inside.
pub fn sphere_interval(origin: DVec3, dir: DVec3, radius: Real) -> Option<(Real, Real)> {
    let b = origin.dot(dir);
    let c = origin.length_squared() - radius * radius;
    let disc = b * b - c;
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

/// Converts a linear-light value to the sRGB transfer curve (IEC 61966-2-1).
pub fn linear_to_srgb(x: f32) -> f32 {
    let x = if x.is_finite() {
        x.clamp(0.0, 1.0)
    } else {
        0.0
    };
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
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
    fn srgb_curve_end_points_and_midtone() {
        assert_eq!(linear_to_srgb(0.0), 0.0);
        assert!((linear_to_srgb(1.0) - 1.0).abs() < 1e-6);
        // 18% grey is about 46% in sRGB.
        assert!((linear_to_srgb(0.18) - 0.4613).abs() < 1e-3);
        assert_eq!(linear_to_srgb(f32::NAN), 0.0);
    }

    #[test]
    fn normalize_or_guards_zero_and_nan() {
        assert_eq!(normalize_or(DVec3::ZERO, DVec3::Y), DVec3::Y);
        assert_eq!(normalize_or(DVec3::splat(f64::NAN), DVec3::Y), DVec3::Y);
        assert!((normalize_or(DVec3::new(3.0, 4.0, 0.0), DVec3::Y).length() - 1.0).abs() < 1e-15);
    }
}
