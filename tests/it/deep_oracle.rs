//! An independent high-precision oracle for the Mandelbulb distance estimate
//! and plain sphere tracing, in `dashu_float` binary floats of a chosen
//! precision, so that deep zooms (features of 1e-30 and below) can be checked
//! against something that does not share mandelreel's f64 rounding or code.
//!
//! Written from the mathematical definition only; nothing here calls
//! mandelreel's fractal code (its tests below compare with it):
//!
//! - The triplex power zⁿ in three angle conventions (Quilez:
//!   θ = acos(y/r), φ = atan2(x, z); White–Nylander: θ = acos(z/r),
//!   φ = atan2(y, x); Asin: θ = asin(z/r), φ = atan2(y, x)), without
//!   trigonometry: cos nθ + i·sin nθ is (cos θ + i·sin θ)ⁿ, with cos θ and
//!   sin θ read off the coordinates divided by r, and likewise for φ. On the
//!   pole axis (ρ = 0) φ = 0; the origin maps to the origin.
//! - The orbit z₀ = p, z ← zⁿ + c (c = p, or the Julia constant), with the
//!   running derivative dr ← n·|z|ⁿ⁻¹·dr + 1 (+ 0 in Julia mode), dr₀ = 1.
//!   The orbit has escaped after k iterations when |z_k|² > bailout² is
//!   first seen at k, tested for k = 0..=iterations (the last test after
//!   the last iteration, as mandelreel also counts it); else it is inside.
//! - The estimate ½·ln(r)·r/dr (escaped after k ≥ 1; ln taken in f64),
//!   0 inside, the distance to the bailout ball (|p| − bailout) where p is
//!   outside it before iterating (k = 0), and ∞ where dr = 0 (a Julia
//!   orbit through the origin). None of mandelreel's safety bounds (far
//!   from the set, near Julia's critical point) is applied: compare at
//!   points within 2 of the origin.
//!
//! `estimate` and `estimate_along` take a point as decimal strings plus an
//! f64 offset (plus dir·t), summed in high precision, so a test can probe
//! a 1e-30 neighbourhood of a point given to 40 digits; `march` sphere-traces
//! with every point formed that way; `point_at` prints such a point back
//! as decimals, to rebase a deeper search on it.

use dashu_float::round::mode::HalfAway;
use dashu_float::{DBig, FBig};
use mandelreel::fractal::Formula;
use std::str::FromStr;

/// The oracle's number: a binary float, round half away from zero.
type Hp = FBig<HalfAway, 2>;

/// The fractal, as the oracle sees it.
#[derive(Clone, Debug)]
pub struct OracleFractal {
    pub formula: Formula,
    /// The whole exponent n ≥ 2.
    pub power: u32,
    pub iterations: u32,
    pub bailout: f64,
    /// The Julia constant as decimal strings; `None` for the Mandelbrot mode.
    pub julia: Option<[String; 3]>,
    /// Binary digits of every high-precision value.
    pub bits: usize,
}

/// `x` exactly, carried at `bits` binary digits.
fn hp_f64(x: f64, bits: usize) -> Hp {
    Hp::try_from(x)
        .unwrap_or_else(|e| panic!("{x} is not a finite number ({e:?})"))
        .with_precision(bits)
        .value()
}

/// The decimal `s` (any number of digits, an exponent allowed) rounded to
/// `bits` binary digits.
fn hp_str(s: &str, bits: usize) -> Hp {
    DBig::from_str(s.trim())
        .unwrap_or_else(|e| panic!("{s:?} is not a decimal number ({e:?})"))
        .with_base_and_precision::<2>(bits)
        .value()
}

fn is_zero(x: &Hp) -> bool {
    *x == Hp::ZERO
}

/// (re + i·im)ⁿ by binary powering, n ≥ 1.
fn complex_pow(re: &Hp, im: &Hp, n: u32) -> (Hp, Hp) {
    assert!(n >= 1);
    let mul = |(a, b): &(Hp, Hp), (c, d): &(Hp, Hp)| (a * c - b * d, a * d + b * c);
    let mut base = (re.clone(), im.clone());
    let mut result: Option<(Hp, Hp)> = None;
    let mut k = n;
    loop {
        if k & 1 == 1 {
            result = Some(match result {
                None => base.clone(),
                Some(r) => mul(&r, &base),
            });
        }
        k >>= 1;
        if k == 0 {
            break;
        }
        base = mul(&base, &base);
    }
    result.expect("n ≥ 1")
}

/// xⁿ for n ≥ 0 (`one` is 1 at the working precision), by binary powering.
fn real_pow(x: &Hp, n: u32, one: &Hp) -> Hp {
    let (mut result, mut base, mut k) = (one.clone(), x.clone(), n);
    while k > 0 {
        if k & 1 == 1 {
            result = &result * &base;
        }
        k >>= 1;
        if k > 0 {
            base = &base * &base;
        }
    }
    result
}

/// The Hamilton product of quaternions (real part first).
fn hamilton(a: &[Hp; 4], b: &[Hp; 4]) -> [Hp; 4] {
    let [a0, a1, a2, a3] = a;
    let [b0, b1, b2, b3] = b;
    [
        a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
        a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
        a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
        a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0,
    ]
}

/// zⁿ for the quaternion x + y·i + z·j + 0·k, by n − 1 Hamilton products:
/// its k part stays 0, which the oracle checks.
fn quaternion_power(z: &[Hp; 3], n: u32, bits: usize) -> [Hp; 3] {
    let q = [z[0].clone(), z[1].clone(), z[2].clone(), hp_f64(0.0, bits)];
    let mut out = q.clone();
    for _ in 1..n {
        out = hamilton(&out, &q);
    }
    let [a, b, c, d] = out;
    // Exactly 0 but for rounding: i·j products cancel.
    let (k2, size2) = (&d * &d, &a * &a + &b * &b + &c * &c);
    assert!(
        k2 <= size2 * hp_f64(1e-60, bits),
        "the quaternion left the slice k = 0: {d:?} against {z:?}"
    );
    [a, b, c]
}

/// zⁿ in `formula`'s convention, without trigonometry.
fn hp_power(formula: Formula, z: &[Hp; 3], n: u32, bits: usize) -> [Hp; 3] {
    if formula == Formula::Quaternion {
        return quaternion_power(z, n, bits);
    }
    let [x, y, w] = z;
    let zero = hp_f64(0.0, bits);
    let one = hp_f64(1.0, bits);
    // The polar coordinate and the pair (cos-part, sin-part) of the azimuth:
    // Quilez φ = atan2(x, z): cos φ = z/ρ, sin φ = x/ρ; the z-up forms
    // φ = atan2(y, x): cos φ = x/ρ, sin φ = y/ρ.
    let (pole, ec, es) = match formula {
        Formula::Quilez => (y, w, x),
        Formula::WhiteNylander | Formula::Asin => (w, x, y),
        Formula::Quaternion => unreachable!("taken by quaternion_power"),
    };
    let rho2 = ec * ec + es * es;
    let r2 = &rho2 + pole * pole;
    if is_zero(&r2) {
        return [zero.clone(), zero.clone(), zero];
    }
    let r = r2.sqrt();
    let rho = rho2.sqrt();
    let (cos_phi, sin_phi) = if is_zero(&rho2) {
        (one.clone(), zero.clone())
    } else {
        (ec / &rho, es / &rho)
    };
    let (cos_theta, sin_theta) = match formula {
        // θ = acos(pole/r) in [0, π]: sin θ = ρ/r ≥ 0.
        Formula::Quilez | Formula::WhiteNylander => (pole / &r, &rho / &r),
        // θ = asin(pole/r) in [−π/2, π/2]: cos θ = ρ/r ≥ 0.
        Formula::Asin => (&rho / &r, pole / &r),
        Formula::Quaternion => unreachable!("taken by quaternion_power"),
    };
    let (cnt, snt) = complex_pow(&cos_theta, &sin_theta, n);
    let (cnp, snp) = complex_pow(&cos_phi, &sin_phi, n);
    let rn = real_pow(&r, n, &one);
    match formula {
        Formula::Quilez => [&snt * &snp * &rn, &cnt * &rn, &snt * &cnp * &rn],
        Formula::WhiteNylander => [&snt * &cnp * &rn, &snt * &snp * &rn, &cnt * &rn],
        Formula::Asin => [&cnt * &cnp * &rn, &cnt * &snp * &rn, &snt * &rn],
        Formula::Quaternion => unreachable!("taken by quaternion_power"),
    }
}

/// zⁿ in f64 through the oracle: for comparing with mandelreel's f64 power.
pub fn power_f64(formula: Formula, z: [f64; 3], n: u32, bits: usize) -> [f64; 3] {
    let hp = z.map(|v| hp_f64(v, bits));
    hp_power(formula, &hp, n, bits).map(|v| v.to_f64().value())
}

fn norm2(z: &[Hp; 3]) -> Hp {
    &z[0] * &z[0] + &z[1] * &z[1] + &z[2] * &z[2]
}

/// The estimate at a high-precision point.
fn estimate_hp(f: &OracleFractal, p: &[Hp; 3]) -> (f64, u32, bool) {
    assert!(f.power >= 2, "the oracle takes whole powers n ≥ 2");
    let bits = f.bits;
    let one = hp_f64(1.0, bits);
    let n = hp_f64(f.power as f64, bits);
    let (c, plus) = match &f.julia {
        Some(k) => (k.clone().map(|s| hp_str(&s, bits)), hp_f64(0.0, bits)),
        None => (p.clone(), one.clone()),
    };
    let bailout = hp_f64(f.bailout, bits);
    let bail2 = &bailout * &bailout;
    let mut z = p.clone();
    let mut dr = one.clone();
    let mut k = 0;
    loop {
        let r2 = norm2(&z);
        if r2 > bail2 {
            let r = r2.sqrt();
            let distance = if k == 0 {
                (&r - &bailout).to_f64().value().max(0.0)
            } else if dr == Hp::ZERO {
                // Julia mode's critical point: z = 0 stretches nothing.
                f64::INFINITY
            } else {
                let rf = r.to_f64().value();
                0.5 * rf.ln() * (&r / &dr).to_f64().value()
            };
            return (distance, k, true);
        }
        if k == f.iterations {
            return (0.0, k, false);
        }
        let r = r2.sqrt();
        dr = &n * real_pow(&r, f.power - 1, &one) * &dr + &plus;
        let w = hp_power(f.formula, &z, f.power, bits);
        z = [&w[0] + &c[0], &w[1] + &c[1], &w[2] + &c[2]];
        k += 1;
    }
}

/// base + offset in high precision.
fn hp_point(base: &[String; 3], offset: [f64; 3], bits: usize) -> [Hp; 3] {
    [0, 1, 2].map(|i| hp_str(&base[i], bits) + hp_f64(offset[i], bits))
}

/// The estimate at `point` + `offset` (decimal strings plus f64, summed in
/// high precision): (distance, iterations done, escaped).
pub fn estimate(f: &OracleFractal, point: &[String; 3], offset: [f64; 3]) -> (f64, u32, bool) {
    estimate_hp(f, &hp_point(point, offset, f.bits))
}

/// The estimate at base + offset + dir·t, the point formed in high
/// precision as `march` forms it.
pub fn estimate_along(
    f: &OracleFractal,
    base: &[String; 3],
    offset: [f64; 3],
    dir: [f64; 3],
    t: f64,
) -> (f64, u32, bool) {
    let origin = hp_point(base, offset, f.bits);
    let t = hp_f64(t, f.bits);
    let p = [0, 1, 2].map(|i| &origin[i] + hp_f64(dir[i], f.bits) * &t);
    estimate_hp(f, &p)
}

/// Plain sphere tracing (no over-relaxation, fudge 1) along
/// origin + dir·t, origin = `base` + `offset`, from `t_start`: t += estimate
/// until the estimate falls under `hit_threshold`·t·`pixel_angle` (a hit
/// at that t), or a miss (`None`) once t passes `t_max` or after
/// `max_steps` estimates. t and every point are high precision. Unlike
/// mandelreel's `march::march`: no floor under the footprint (it has 1e-15),
/// no bisection after an overshoot (an inside point estimates 0, a hit
/// there), and running out of steps is a miss (there, a hit).
#[allow(clippy::too_many_arguments)]
pub fn march(
    f: &OracleFractal,
    base: &[String; 3],
    offset: [f64; 3],
    dir: [f64; 3],
    t_start: f64,
    t_max: f64,
    pixel_angle: f64,
    hit_threshold: f64,
    max_steps: u32,
) -> Option<f64> {
    let bits = f.bits;
    let origin = hp_point(base, offset, bits);
    let dir = dir.map(|v| hp_f64(v, bits));
    let mut t = hp_f64(t_start, bits);
    for _ in 0..max_steps {
        let p = [0, 1, 2].map(|i| &origin[i] + &dir[i] * &t);
        let (d, _, _) = estimate_hp(f, &p);
        let tf = t.to_f64().value();
        if d < hit_threshold * tf * pixel_angle {
            return Some(tf);
        }
        if !d.is_finite() {
            return None;
        }
        t += hp_f64(d, bits);
        if t.to_f64().value() > t_max {
            return None;
        }
    }
    None
}

/// The point base + offset + dir·t as decimal strings of `digits`
/// significant digits (computed at 256 bits or more).
pub fn point_at(
    base: &[String; 3],
    offset: [f64; 3],
    dir: [f64; 3],
    t: f64,
    digits: usize,
) -> [String; 3] {
    let bits = 256.max(digits * 4);
    let origin = hp_point(base, offset, bits);
    let t = hp_f64(t, bits);
    [0, 1, 2].map(|i| {
        let v = &origin[i] + hp_f64(dir[i], bits) * &t;
        let decimal = v.to_decimal().value().with_precision(digits).value();
        format!("{decimal}")
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use mandelreel::fractal::{triplex_power_trig, Fractal};
    use mandelreel::march::{MarchSettings, Ray};

    const FORMULAS: [Formula; 4] = Formula::ALL;

    /// xorshift64*: uniform in [−1, 1).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            let bits = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
            bits as f64 / (1u64 << 52) as f64 - 1.0
        }
        fn unit(&mut self) -> [f64; 3] {
            loop {
                let v = [self.next(), self.next(), self.next()];
                let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                if l > 0.1 && l <= 1.0 {
                    return v.map(|c| c / l);
                }
            }
        }
    }

    fn zero_strings() -> [String; 3] {
        ["0".to_string(), "0".to_string(), "0".to_string()]
    }

    fn length(v: [f64; 3]) -> f64 {
        (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
    }

    fn add(a: [f64; 3], b: [f64; 3], s: f64) -> [f64; 3] {
        [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]]
    }

    /// mandelreel's f64 fractal matching `f` (Julia constant read as f64).
    fn reel(f: &OracleFractal) -> Fractal {
        Fractal {
            formula: f.formula,
            power: f.power as f64,
            iterations: f.iterations,
            bailout: f.bailout,
            julia: f.julia.as_ref().map(|k| {
                let v = k.clone().map(|s| s.parse::<f64>().unwrap());
                glam::DVec3::from_array(v)
            }),
            ..Default::default()
        }
    }

    /// The oracle's power against mandelreel's trigonometric one at random
    /// points of all sizes, and on the pole axis; and the conventions must
    /// differ from one another (so the comparison can tell them apart).
    #[test]
    fn power_matches_trigonometric_form() {
        let mut rng = Rng(0x1234_5678_9abc_def1);
        for formula in FORMULAS {
            for n in [2u32, 3, 8] {
                let mut points: Vec<[f64; 3]> = (0..60)
                    .map(|_| {
                        let scale = 10f64.powf(rng.next());
                        [rng.next(), rng.next(), rng.next()].map(|c| c * scale)
                    })
                    .collect();
                // The pole axis, both ways, where φ = 0.
                let pole = match formula {
                    Formula::Quilez => 1,
                    Formula::Quaternion => 0,
                    Formula::WhiteNylander | Formula::Asin => 2,
                };
                for s in [0.7, -0.7] {
                    let mut p = [0.0; 3];
                    p[pole] = s;
                    points.push(p);
                }
                for z in points {
                    let r = length(z);
                    let want = triplex_power_trig(formula, z, r, n as f64);
                    let got = power_f64(formula, z, n, 160);
                    let rn = r.powi(n as i32);
                    for i in 0..3 {
                        let err = (got[i] - want[i]).abs() / rn;
                        assert!(
                            err < 1e-12,
                            "{formula:?} n={n} z={z:?}: oracle {got:?}, trig {want:?} (rel {err:e})"
                        );
                    }
                }
            }
        }
        // Conventions tell apart: the same point, Quilez vs the z-up forms.
        let z = [0.3, -0.4, 0.5];
        let q = power_f64(Formula::Quilez, z, 8, 128);
        let w = power_f64(Formula::WhiteNylander, z, 8, 128);
        let a = power_f64(Formula::Asin, z, 8, 128);
        assert!((0..3).any(|i| (q[i] - w[i]).abs() > 1e-3));
        assert!((0..3).any(|i| (a[i] - w[i]).abs() > 1e-3));
        let h = power_f64(Formula::Quaternion, z, 8, 128);
        assert!((0..3).any(|i| (h[i] - q[i]).abs() > 1e-3));
        // The origin maps to the origin.
        assert_eq!(power_f64(Formula::Asin, [0.0; 3], 8, 128), [0.0; 3]);
    }

    /// Beside the quaternion's real axis its whole power keeps every
    /// component to f64's precision, as the Hamilton products do, where an
    /// angle by acos would lose the imaginary part.
    #[test]
    fn the_quaternion_power_beside_its_real_axis_matches_hamilton_products() {
        use mandelreel::fractal::triplex_power_int;
        for off in [1e-5, 1e-7, 1e-9, 1e-12, 1e-30] {
            for n in [2u32, 3, 8] {
                for z in [[0.5, 0.5 * off, 0.0], [-1.3, 0.6 * off, -0.8 * off]] {
                    let want = power_f64(Formula::Quaternion, z, n, 256);
                    let got = triplex_power_int(Formula::Quaternion, z, n).expect("off the axis");
                    for i in 0..3 {
                        let error = (got[i] - want[i]).abs();
                        assert!(
                            error <= 1e-14 * want[i].abs(),
                            "n {n} at {z:?}: {got:?} against {want:?}"
                        );
                    }
                }
            }
        }
    }

    /// Mandelbrot mode beside the real axis: the orbit of x + iε escapes
    /// when the complex one does (the real axis holds the Mandelbrot set's
    /// own cut), however small ε is.
    #[test]
    fn the_quaternion_mandelbrot_set_beside_its_real_axis_is_the_complex_one() {
        let f = Fractal {
            formula: Formula::Quaternion,
            power: 2.0,
            iterations: 200,
            bailout: 4.0,
            ..Default::default()
        };
        for off in [1e-6, 1e-8, 1e-9, 1e-12] {
            let (x, y) = (-1.9, off);
            let (mut a, mut b, mut escaped) = (x, y, 0);
            for k in 1..=200 {
                (a, b) = (a * a - b * b + x, 2.0 * a * b + y);
                if a * a + b * b > 16.0 {
                    escaped = k;
                    break;
                }
            }
            assert!(escaped > 0, "the complex orbit of {x} + {y}i stays");
            let e = f.estimate(glam::DVec3::new(x, y, 0.0), 1e-3);
            assert!(e.escaped, "{x} + {y}i: the quaternion orbit stays");
            assert_eq!(e.iterations, escaped, "{x} + {y}i");
        }
    }

    /// Decimal input: a point given as a long decimal equals its f64 part
    /// plus the rest as offset, and `point_at` prints what it was given.
    #[test]
    fn decimal_points_round_trip() {
        let f = OracleFractal {
            formula: Formula::Quilez,
            power: 8,
            iterations: 12,
            bailout: 4.0,
            julia: None,
            bits: 192,
        };
        let base = [
            "0.5030443677251234567890123456789012345".to_string(),
            "-0.25".to_string(),
            "1e-3".to_string(),
        ];
        let moved = point_at(&base, [1e-30, 0.0, 0.0], [0.0, 1.0, 0.0], 0.125, 40);
        assert_eq!(moved[1].parse::<f64>().unwrap(), -0.125);
        assert!(
            moved[0].starts_with("0.5030443677251234567890123456799012345"),
            "{moved:?}"
        );
        assert_eq!(moved[2].parse::<f64>().unwrap(), 1e-3);
        let a = estimate(&f, &moved, [0.0; 3]);
        let b = estimate(&f, &base, [1e-30, 0.125, 0.0]);
        assert_eq!(a.1, b.1);
        assert!((a.0 - b.0).abs() <= 1e-12 * a.0.abs(), "{a:?} vs {b:?}");
    }

    /// Points near the surface (found with mandelreel's `contains` along
    /// random rays from a point of the set): `(point, scale)` a few 1e-3 out
    /// and a few in.
    fn near_surface(f: &Fractal, inside: [f64; 3], rng: &mut Rng, count: usize) -> Vec<[f64; 3]> {
        let mut out = Vec::new();
        while out.len() < count {
            let u = rng.unit();
            assert!(f.contains(glam::DVec3::from_array(inside)));
            let (mut lo, mut hi) = (0.0, 2.0);
            if f.contains(glam::DVec3::from_array(add(inside, u, hi))) {
                continue;
            }
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if f.contains(glam::DVec3::from_array(add(inside, u, mid))) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            for delta in [2e-3, 5e-3, 1e-2, -2e-3] {
                out.push(add(inside, u, hi + delta));
            }
        }
        out
    }

    /// At ordinary depth the oracle and mandelreel's f64 estimate agree to
    /// 1e-9 relative (and on iterations and escape), in every convention,
    /// Mandelbrot and Julia mode.
    #[test]
    fn estimate_matches_mandelreel_near_surface() {
        let mut rng = Rng(0xdead_beef_cafe_f00d);
        let mut worst: f64 = 0.0;
        for formula in FORMULAS {
            let julias = [None, Some(["0.3", "-0.5", "0.2"].map(String::from))];
            for julia in julias {
                let f = OracleFractal {
                    formula,
                    power: 8,
                    iterations: 12,
                    bailout: 4.0,
                    julia: julia.clone(),
                    bits: 128,
                };
                let m = reel(&f);
                let inside = match &julia {
                    Some(_) => [0.3, -0.5, 0.2],
                    None => [0.0; 3],
                };
                let points = near_surface(&m, inside, &mut rng, 16);
                let mut escaped = 0;
                for p in points {
                    let e = m.estimate(glam::DVec3::from_array(p), 1e-3);
                    let (d, k, esc) = estimate(&f, &zero_strings(), p);
                    let what = format!("{formula:?} julia={julia:?} p={p:?}");
                    assert_eq!((k, esc), (e.iterations, e.escaped), "{what}");
                    let rel = (d - e.distance).abs() / e.distance.abs().max(1e-300);
                    assert!(
                        d == e.distance || rel < 1e-9,
                        "{what}: oracle {d}, mandelreel {} (rel {rel:e})",
                        e.distance
                    );
                    if esc {
                        escaped += 1;
                        worst = worst.max(rel);
                        assert!(d > 0.0, "{what}");
                    }
                }
                assert!(escaped >= 8, "{formula:?} {julia:?}: few escaped points");
            }
        }
        eprintln!("worst relative difference of the estimates: {worst:e}");
    }

    /// The oracle's plain march hits where mandelreel's does (over-relaxation
    /// off, one ray per cone), within one footprint, on rays at the bulb.
    #[test]
    fn march_matches_mandelreel() {
        let mut rng = Rng(0x0123_4567_89ab_cdef);
        let settings = MarchSettings {
            over_relaxation: 1.0,
            cone_rays: 1,
            ..Default::default()
        };
        let pixel_angle = 1e-3;
        for formula in FORMULAS {
            let f = OracleFractal {
                formula,
                power: 8,
                iterations: 12,
                bailout: 4.0,
                julia: None,
                bits: 128,
            };
            let m = reel(&f);
            for _ in 0..3 {
                let origin = rng.unit().map(|c| c * 3.0);
                let aim = [rng.next(), rng.next(), rng.next()].map(|c| c * 0.3);
                let to = add(aim, origin, -1.0);
                let dir = to.map(|c| c / length(to));
                let ray = Ray {
                    origin: glam::DVec3::from_array(origin),
                    dir: glam::DVec3::from_array(dir),
                    pixel_angle,
                    start_footprint: 0.0,
                };
                let (t_in, t_out) = settings.interval(&ray).expect("aimed at the bulb");
                let reel_t = mandelreel::march::march(&ray, &m, &settings)
                    .hit
                    .map(|h| h.t);
                let base = origin.map(|c| format!("{c:.60}"));
                let oracle_t = march(
                    &f,
                    &base,
                    [0.0; 3],
                    dir,
                    t_in,
                    t_out,
                    pixel_angle,
                    settings.hit_threshold,
                    settings.max_steps,
                );
                let what = format!("{formula:?} origin {origin:?} dir {dir:?}");
                match (reel_t, oracle_t) {
                    (Some(a), Some(b)) => {
                        assert!(
                            (a - b).abs() <= a * pixel_angle,
                            "{what}: mandelreel t={a}, oracle t={b}"
                        );
                        // The oracle's hit is on the surface to its threshold.
                        let p = add(origin, dir, b);
                        let (d, _, _) = estimate(&f, &zero_strings(), p);
                        assert!(d < settings.hit_threshold * b * pixel_angle, "{what}");
                    }
                    (None, None) => {}
                    other => panic!("{what}: mandelreel/oracle {other:?}"),
                }
            }
        }
    }

    /// At depth: a point of the 40-iteration bulb's boundary located to
    /// 1e-40 by bisecting the oracle's escape flag (rebasing the decimal
    /// point with `point_at` every 30 halvings); the bracket and the
    /// estimates 1e-30 and 1e-26 outside it are the same at 192, 256 and
    /// 320 bits.
    #[test]
    fn deep_neighbourhood_is_resolved() {
        let mut rng = Rng(0x5eed_0000_0000_0025);
        let f = OracleFractal {
            formula: Formula::Quilez,
            power: 8,
            iterations: 40,
            bailout: 4.0,
            julia: None,
            bits: 256,
        };
        let m = reel(&f);
        let escapes =
            |base: &[String; 3], u: [f64; 3], s: f64| estimate_along(&f, base, [0.0; 3], u, s).2;
        let mut checked = 0;
        while checked < 1 {
            let u = rng.unit();
            // The f64 crossing, then the oracle's within 1e-6 of it.
            let (mut lo, mut hi) = (0.0, 2.0);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if m.contains(glam::DVec3::from_array(u.map(|c| c * mid))) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let mut base = u.map(|c| format!("{:.60}", c * hi));
            let (mut lo, mut hi) = (-1e-6, 1e-6);
            if escapes(&base, u, lo) || !escapes(&base, u, hi) {
                continue;
            }
            for _level in 0..4 {
                for _ in 0..30 {
                    let mid = 0.5 * (lo + hi);
                    if escapes(&base, u, mid) {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                base = point_at(&base, [0.0; 3], u, lo, 60);
                (lo, hi) = (0.0, hi - lo);
                assert!(!escapes(&base, u, lo) && escapes(&base, u, hi));
            }
            assert!(hi < 1e-40, "bracket {hi:e}");
            // The bracket is the same at 192 and 320 bits.
            for bits in [192, 320] {
                let g = OracleFractal { bits, ..f.clone() };
                let at = |s: f64| estimate_along(&g, &base, [0.0; 3], u, s).2;
                assert!(!at(lo) && at(hi), "{bits} bits: bracket moved");
            }
            for delta in [1e-30, 1e-26] {
                let offset = u.map(|c| c * delta);
                let (d, k, esc) = estimate(&f, &base, offset);
                let what = format!("u={u:?} base={base:?} δ={delta:e}: {d:e} after {k}");
                assert!(esc && d > 0.0, "{what}");
                for bits in [192, 320] {
                    let other = estimate(&OracleFractal { bits, ..f.clone() }, &base, offset);
                    assert!(other.2 && other.1 == k, "{what}: {bits} bits {other:?}");
                    assert!(
                        (other.0 - d).abs() <= 1e-9 * d,
                        "{what}: {bits} bits {other:?}"
                    );
                }
                // The 40-iteration set's own boundary is no surface for the
                // estimate: ½·ln r·r/dr there is ~1e-12, not ~δ.
                let reel_point = [0, 1, 2].map(|i| base[i].parse::<f64>().unwrap() + offset[i]);
                let e = m.estimate(glam::DVec3::from_array(reel_point), 1e-30);
                eprintln!(
                    "{what}; mandelreel f64 at the rounded point {:e} after {}",
                    e.distance, e.iterations
                );
            }
            checked += 1;
        }
    }

    /// The Julia set of c = 0 is the unit ball, and there the estimate is
    /// ½·|p|·ln|p| exactly (rₖ = |p|^(nᵏ), drₖ = nᵏ·|p|^(nᵏ−1)), at any
    /// depth: at |p| = 1 + δ, δ down to 1e-30, in every convention, on and
    /// off the pole axes, the oracle gives it to 1e-9; points at 1 − δ are
    /// inside. 128 bits (38 digits) is too coarse at 1e-30, 192 is not.
    #[test]
    fn unit_ball_estimate_at_depth() {
        // Directions with |u| = 1 exactly in decimal.
        let directions = [
            [0.6, 0.8, 0.0],
            [0.36, 0.48, 0.8],
            [-0.48, 0.6, -0.64],
            [0.0, 0.0, 1.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
        ];
        for formula in FORMULAS {
            let f = OracleFractal {
                formula,
                power: 8,
                iterations: 60,
                bailout: 4.0,
                julia: Some(["0", "0", "0"].map(String::from)),
                bits: 192,
            };
            for u in directions {
                let base = u.map(|c| format!("{c}"));
                for delta in [1e-3f64, 1e-12, 1e-20, 1e-30] {
                    let want = 0.5 * (1.0 + delta) * delta.ln_1p();
                    let (d, k, esc) = estimate(&f, &base, u.map(|c| c * delta));
                    let what = format!("{formula:?} u={u:?} δ={delta:e}: {d:e} after {k}");
                    assert!(esc, "{what}");
                    assert!((d - want).abs() <= 1e-9 * want, "{what}, want {want:e}");
                    let (d, _, esc) = estimate(&f, &base, u.map(|c| -c * delta));
                    assert!(!esc && d == 0.0, "{what}: 1 − δ escaped");
                }
            }
        }
        // The precision matters: at 128 bits the 1e-30 offset is rounded
        // to a few digits of itself.
        let coarse = OracleFractal {
            formula: Formula::Quilez,
            power: 8,
            iterations: 60,
            bailout: 4.0,
            julia: Some(["0", "0", "0"].map(String::from)),
            bits: 128,
        };
        let base = ["0.36", "0.48", "0.8"].map(String::from);
        let (d, _, _) = estimate(&coarse, &base, [0.36e-30, 0.48e-30, 0.8e-30]);
        assert!((d - 0.5e-30).abs() > 1e-9 * 0.5e-30, "128 bits gave {d:e}");
    }
}
