//! The Mandelbulb itself: the triplex power for each angle convention, the one
//! iteration driver (bailout, running derivative, orbit traps, Julia mode), and
//! the distance estimate built on it.
//!
//! Formulas: the spherical power and the scalar running derivative
//! `dr ← n·r^(n−1)·dr (+1 in Mandelbrot mode)` with `DE = ½·ln(r)·r/dr` follow
//! ../shared/seeds/002 (course notes, "distance estimation") and 001
//! (Christensen, "distance estimated 3D fractals"); the y-up convention and the
//! four orbit traps follow 000 (Quilez, "The algorithm" and "Coloring").

use crate::math::{DVec3, Real};
use serde::{Deserialize, Serialize};

/// Which spherical-coordinate convention defines the triplex power.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Formula {
    /// Quilez's y-up form: θ = acos(y/r), φ = atan2(x, z).
    Quilez,
    /// The White–Nylander z-up form: θ = acos(z/r), φ = atan2(y, x).
    WhiteNylander,
    /// The asin form Mandelbulber2's "Mandelbulb" formula uses: θ = asin(z/r), φ = atan2(y, x).
    Asin,
}

impl Formula {
    pub fn name(self) -> &'static str {
        match self {
            Formula::Quilez => "Quilez",
            Formula::WhiteNylander => "WhiteNylander",
            Formula::Asin => "Asin",
        }
    }
}

/// Parameters of the fractal for one frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Fractal {
    pub formula: Formula,
    /// The exponent n of the triplex power (any real; 8 is the classic bulb).
    pub power: Real,
    /// Maximum orbit length.
    pub iterations: u32,
    /// Escape radius; must exceed 1 so ln(r) is positive at escape.
    pub bailout: Real,
    /// `None` for the Mandelbrot mode (z₀ = c = p), `Some(k)` for the Julia set of constant k.
    pub julia: Option<DVec3>,
}

impl Default for Fractal {
    fn default() -> Self {
        Fractal {
            formula: Formula::Quilez,
            power: 8.0,
            iterations: 12,
            bailout: 4.0,
            julia: None,
        }
    }
}

/// Minimum distances of the orbit to the four traps of Quilez's colouring.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitTraps {
    /// Smallest |z|² over the orbit (the point trap at the origin).
    pub origin: Real,
    /// Smallest |z.x|, |z.y|, |z.z| (the planes x=0, y=0, z=0).
    pub planes: DVec3,
}

/// What one evaluation of the distance estimator returns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// Lower bound on the distance to the surface; 0 for points that never escape.
    pub distance: Real,
    pub traps: OrbitTraps,
    /// Iterations done before escape (equal to the limit when the orbit stayed bounded).
    pub iterations: u32,
    pub escaped: bool,
}

/// Raises the triplex number `z` (with length `r`, already computed) to the
/// power `n` in the given convention. The origin maps to itself.
#[inline]
pub fn triplex_power(formula: Formula, z: DVec3, r: Real, n: Real) -> DVec3 {
    if r <= 0.0 || !r.is_finite() {
        return DVec3::ZERO;
    }
    let rn = r.powf(n);
    match formula {
        Formula::Quilez => {
            let theta = (z.y / r).clamp(-1.0, 1.0).acos() * n;
            let phi = z.x.atan2(z.z) * n;
            let (st, ct) = theta.sin_cos();
            let (sp, cp) = phi.sin_cos();
            DVec3::new(st * sp, ct, st * cp) * rn
        }
        Formula::WhiteNylander => {
            let theta = (z.z / r).clamp(-1.0, 1.0).acos() * n;
            let phi = z.y.atan2(z.x) * n;
            let (st, ct) = theta.sin_cos();
            let (sp, cp) = phi.sin_cos();
            DVec3::new(st * cp, st * sp, ct) * rn
        }
        Formula::Asin => {
            let theta = (z.z / r).clamp(-1.0, 1.0).asin() * n;
            let phi = z.y.atan2(z.x) * n;
            let (st, ct) = theta.sin_cos();
            let (sp, cp) = phi.sin_cos();
            DVec3::new(ct * cp, ct * sp, st) * rn
        }
    }
}

impl Fractal {
    /// Iterates the orbit of `p` and returns the scalar-derivative distance estimate.
    /// Pure and allocation-free: this is the innermost loop of every render.
    pub fn estimate(&self, p: DVec3) -> Estimate {
        let n = self.power;
        let (c, plus_one) = match self.julia {
            Some(k) => (k, 0.0),
            None => (p, 1.0),
        };
        let mut z = p;
        let mut dr: Real = 1.0;
        let mut r = z.length();
        let mut traps = OrbitTraps {
            origin: Real::INFINITY,
            planes: DVec3::splat(Real::INFINITY),
        };
        let mut i = 0;
        while i < self.iterations {
            if r > self.bailout {
                break;
            }
            traps.origin = traps.origin.min(r * r);
            traps.planes = traps.planes.min(z.abs());
            // Running derivative of |z| before z is replaced.
            dr = n * r.powf(n - 1.0) * dr + plus_one;
            z = triplex_power(self.formula, z, r, n) + c;
            r = z.length();
            i += 1;
        }
        let escaped = r > self.bailout;
        if traps.origin == Real::INFINITY {
            // The point was outside the bailout from the start.
            traps.origin = r * r;
            traps.planes = z.abs();
        }
        let distance = if escaped {
            let d = 0.5 * r.ln() * r / dr;
            if d.is_finite() {
                d.max(0.0)
            } else {
                // r overflowed: the point is far outside, any large step is safe
                // because the marcher is clamped to the bounding sphere.
                Real::MAX
            }
        } else {
            0.0
        };
        Estimate {
            distance,
            traps,
            iterations: i,
            escaped,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bulb(formula: Formula) -> Fractal {
        Fractal {
            formula,
            ..Fractal::default()
        }
    }

    #[test]
    fn power_two_is_complex_squaring_on_each_conventions_meridian() {
        // Each convention reduces to complex squaring on one half-plane through its pole axis
        // (the asin form on its whole equator). a > 0 keeps us on the half-plane φ = 0.
        let (a, b) = (0.3, -0.7);
        let sq = |z: DVec3, f: Formula| triplex_power(f, z, z.length(), 2.0);
        // White–Nylander: (x > 0, 0, z) with z the real part, x the imaginary.
        let w = sq(DVec3::new(a, 0.0, b), Formula::WhiteNylander);
        assert!(
            (w - DVec3::new(2.0 * a * b, 0.0, b * b - a * a)).length() < 1e-12,
            "{w}"
        );
        // Quilez: (0, y, z > 0) with y the real part, z the imaginary.
        let w = sq(DVec3::new(0.0, b, a), Formula::Quilez);
        assert!(
            (w - DVec3::new(0.0, b * b - a * a, 2.0 * a * b)).length() < 1e-12,
            "{w}"
        );
        // Asin: the plane z = 0, x real and y imaginary.
        let w = sq(DVec3::new(a, b, 0.0), Formula::Asin);
        assert!(
            (w - DVec3::new(a * a - b * b, 2.0 * a * b, 0.0)).length() < 1e-12,
            "{w}"
        );
    }

    #[test]
    fn power_scales_length_by_r_to_the_n() {
        let z = DVec3::new(0.4, 0.5, -0.6);
        for f in [Formula::Quilez, Formula::WhiteNylander, Formula::Asin] {
            let w = triplex_power(f, z, z.length(), 8.0);
            assert!((w.length() - z.length().powi(8)).abs() < 1e-12);
        }
    }

    #[test]
    fn origin_is_inside_the_mandelbrot_bulb() {
        for f in [Formula::Quilez, Formula::WhiteNylander, Formula::Asin] {
            let e = bulb(f).estimate(DVec3::ZERO);
            assert!(!e.escaped);
            assert_eq!(e.distance, 0.0);
        }
    }

    #[test]
    fn distance_outside_is_positive_finite_and_a_lower_bound() {
        // Near the bulb the estimate is a safe step: positive, and no larger than
        // R, the distance to the origin, which is inside. (Far away, beyond the
        // bounding sphere the marcher never leaves, the scalar estimate grows
        // like ½·R·ln R and is no longer a bound; there it must only stay finite.)
        for f in [Formula::Quilez, Formula::WhiteNylander, Formula::Asin] {
            let far = bulb(f).estimate(DVec3::new(0.0, 10.0, 0.0));
            assert!(far.distance.is_finite() && far.distance > 0.0);
            for &radius in &[1.3, 2.0, 3.0] {
                for dir in [
                    DVec3::X,
                    DVec3::Y,
                    DVec3::Z,
                    DVec3::new(1.0, -2.0, 0.5).normalize(),
                ] {
                    let e = bulb(f).estimate(dir * radius);
                    assert!(e.escaped, "{f:?} at {radius}");
                    assert!(e.distance.is_finite() && e.distance > 0.0);
                    assert!(e.distance < radius, "{f:?} r={radius} de={}", e.distance);
                }
            }
        }
    }

    #[test]
    fn far_away_estimate_grows_with_distance() {
        let f = bulb(Formula::Quilez);
        let near = f.estimate(DVec3::new(0.0, 0.0, 2.0)).distance;
        let far = f.estimate(DVec3::new(0.0, 0.0, 3.5)).distance;
        assert!(far > near);
    }

    #[test]
    fn julia_mode_differs_from_mandelbrot_mode() {
        let p = DVec3::new(0.6, 0.3, 0.4);
        let m = bulb(Formula::Quilez).estimate(p);
        let j = Fractal {
            julia: Some(DVec3::new(0.8, -0.3, 0.1)),
            ..bulb(Formula::Quilez)
        }
        .estimate(p);
        assert_ne!(m.distance, j.distance);
        // A Julia set with c = 0 is the unit ball: inside below radius 1, escaping above it.
        let unit = Fractal {
            julia: Some(DVec3::ZERO),
            iterations: 30,
            ..bulb(Formula::Quilez)
        };
        assert!(!unit.estimate(DVec3::new(0.0, 0.99, 0.0)).escaped);
        let outside = unit.estimate(DVec3::new(0.0, 1.05, 0.0));
        assert!(outside.escaped);
        // The true distance to the unit sphere is 0.05; the ½ in the estimate makes it
        // a lower bound that is within a factor of two of the truth.
        assert!(
            outside.distance <= 0.05 && outside.distance > 0.025,
            "{}",
            outside.distance
        );
    }

    #[test]
    fn conventions_are_rotations_of_each_other() {
        // Quilez's y-up bulb is the White–Nylander bulb with its axes relabelled:
        // WN (x, y, z) is Quilez (y, z, x). Check membership agrees point by point.
        let q = bulb(Formula::Quilez);
        let w = bulb(Formula::WhiteNylander);
        let mut agree = 0;
        let total = 200;
        for i in 0..total {
            let t = i as f64 * 0.618_033_988_7;
            let p = DVec3::new((t * 3.1).sin(), (t * 1.7).cos(), (t * 2.3).sin()) * 1.1;
            let pq = DVec3::new(p.y, p.z, p.x);
            if q.estimate(pq).escaped == w.estimate(p).escaped {
                agree += 1;
            }
        }
        assert_eq!(agree, total);
    }
}
