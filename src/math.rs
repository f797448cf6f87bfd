//! Numeric foundations shared by every other module: the `Real` type used for
//! geometry (f64), the vector and colour types, and a few small guards that keep
//! NaN and infinity from leaking out of the hot path.

pub use glam::{DVec3, Vec3};
use std::ops::{Add, Div, Mul, Neg, Sub};

/// The floating-point type of all geometry and distance estimation.
pub type Real = f64;

/// The arithmetic of the whole-power step: the four operations and square
/// roots. Implemented for the kernel's number types and for `Vector`s of
/// them, so one formula serves one orbit and several side by side.
pub trait Arith:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    fn sqrt(self) -> Self;
}

/// The arithmetic the fractal kernel needs. Implemented for f64, for f32 (to
/// show what single precision costs) and for dual numbers (forward-mode
/// derivatives), so one iteration driver serves all three.
pub trait Number: Arith + Neg<Output = Self> {
    /// Machine epsilon of the underlying float.
    const EPSILON: Real;
    /// log₂ of the underlying float's largest value (its range).
    const MAX_LOG2: Real;
    fn from_real(v: Real) -> Self;
    /// The plain value (for comparisons, traps and results).
    fn value(self) -> Real;
    fn acos(self) -> Self;
    fn asin(self) -> Self;
    fn atan2(self, x: Self) -> Self;
    fn sin_cos(self) -> (Self, Self);
    fn powf(self, n: Real) -> Self;
    fn ln(self) -> Self;
    /// Clamps the value to [-1, 1], keeping derivatives where inside.
    fn clamp_unit(self) -> Self;
}

/// One SIMD register of f64 (as many lanes as the instruction set `S`
/// has: 8 with AVX-512, 4 with AVX2, 1 without), with the token that proves
/// the instructions exist. Each operation is one IEEE instruction per lane,
/// the same operation a lone f64 takes, so results are bit-identical.
#[derive(Clone, Copy, Debug)]
pub struct Vector<S: pulp::Simd>(pub S, pub S::f64s);

impl<S: pulp::Simd> Vector<S> {
    #[inline(always)]
    pub fn splat(simd: S, v: f64) -> Self {
        Vector(simd, simd.splat_f64s(v))
    }
}

macro_rules! vector_operator {
    ($trait:ident, $method:ident, $simd:ident) => {
        impl<S: pulp::Simd> $trait for Vector<S> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, o: Self) -> Self {
                Vector(self.0, self.0.$simd(self.1, o.1))
            }
        }
    };
}
vector_operator!(Add, add, add_f64s);
vector_operator!(Sub, sub, sub_f64s);
vector_operator!(Mul, mul, mul_f64s);
vector_operator!(Div, div, div_f64s);

impl<S: pulp::Simd> Arith for Vector<S> {
    #[inline(always)]
    fn sqrt(self) -> Self {
        Vector(self.0, self.0.sqrt_f64s(self.1))
    }
}

/// What `ln_in_range` needs beyond `Arith`: constants and a lane-by-lane choice.
/// Implemented for one f64 and for a `Vector` of them, so the scalar
/// estimate and the vector kernel take the same logarithm to the bit.
pub trait Lanes: Arith {
    /// `v` in every lane.
    fn constant(self, v: f64) -> Self;
    /// Lane by lane: `then` where `self ≥ bound`, else `otherwise` (also
    /// where `self` is NaN).
    fn if_at_least(self, bound: f64, then: Self, otherwise: Self) -> Self;
    /// For a normal x ≥ ½ (what `ln_in_range` takes), x = m·2ᵉ with m in
    /// [1, 2): (m, e), exactly (the sign is dropped). Below ½ the vector
    /// version's e is wrong.
    fn mantissa_and_exponent(self) -> (Self, Self);
}

/// The bits of an f64's exponent and of its mantissa, and 1.0's.
const EXPONENT_BITS: u64 = 0x7ff0_0000_0000_0000;
const MANTISSA_BITS: u64 = 0x000f_ffff_ffff_ffff;
const ONE_BITS: u64 = 0x3ff0_0000_0000_0000;

impl Lanes for f64 {
    #[inline(always)]
    fn constant(self, v: f64) -> Self {
        v
    }
    #[inline(always)]
    fn mantissa_and_exponent(self) -> (Self, Self) {
        let bits = self.to_bits();
        let biased = (bits & EXPONENT_BITS) >> 52;
        (
            f64::from_bits(bits & MANTISSA_BITS | ONE_BITS),
            biased as f64 - 1023.0,
        )
    }
    #[inline(always)]
    fn if_at_least(self, bound: f64, then: Self, otherwise: Self) -> Self {
        if self >= bound {
            then
        } else {
            otherwise
        }
    }
}

impl<S: pulp::Simd> Lanes for Vector<S> {
    #[inline(always)]
    fn constant(self, v: f64) -> Self {
        Vector::splat(self.0, v)
    }
    #[inline(always)]
    fn mantissa_and_exponent(self) -> (Self, Self) {
        /// 2ᵏ for k = 512, 256, …, 1: (k, 2ᵏ, 2⁻ᵏ), all exact.
        const LADDER: [(f64, f64, f64); 10] = {
            let mut ladder = [(0.0, 0.0, 0.0); 10];
            let mut i = 0;
            while i < 10 {
                let k = 512 >> i;
                ladder[i] = (
                    k as f64,
                    f64::from_bits((1023 + k as u64) << 52),
                    f64::from_bits((1023 - k as u64) << 52),
                );
                i += 1;
            }
            ladder
        };
        let simd = self.0;
        let bits = simd.transmute_u64s_f64s(self.1);
        let mantissa = simd.and_u64s(bits, simd.splat_u64s(MANTISSA_BITS));
        let mantissa = simd.or_u64s(mantissa, simd.splat_u64s(ONE_BITS));
        let power = simd.and_u64s(bits, simd.splat_u64s(EXPONENT_BITS));
        let mut power = Vector(simd, simd.transmute_f64s_u64s(power));
        // pulp has no shift of 64-bit lanes nor integer conversion for
        // every instruction set, so e comes from 2ᵉ by exact steps: the
        // same whole number the scalar version reads from the bits. For
        // 2ᵉ ≥ 2⁻¹ (x ≥ ½); below, e is meaningless, as x is out of range.
        let mut e = self.constant(0.0);
        for (k, at_least, inverse) in LADDER {
            let (scaled, raised) = (power * power.constant(inverse), e + e.constant(k));
            e = power.if_at_least(at_least, raised, e);
            power = power.if_at_least(at_least, scaled, power);
        }
        e = power.if_at_least(1.0, e, e - e.constant(1.0));
        (Vector(simd, simd.transmute_f64s_u64s(mantissa)), e)
    }
    #[inline(always)]
    fn if_at_least(self, bound: f64, then: Self, otherwise: Self) -> Self {
        let simd = self.0;
        let mask = simd.greater_than_or_equal_f64s(self.1, simd.splat_f64s(bound));
        Vector(simd, simd.select_f64s(mask, then.1, otherwise.1))
    }
}

/// The natural logarithm for x in [½, 2¹⁰²⁴) (what the distance estimate
/// needs: an escaped radius is above the bailout, which is above 1), built
/// from the four operations and bit masks so that one f64 and a vector lane
/// get the same bits; within 2 ulp of `f64::ln` there (tested, densely where
/// the reduction rounds worst). Outside that range the result is meaningless: `ln` checks it.
///
/// x = m·2ᵉ: m in [1, 2) and e come from x's bits (`mantissa_and_exponent`;
/// in vectors e takes a few steps beside the rest, which does not wait on
/// it). With m moved into [√½, √2), ln m = 2·atanh(s)
/// with s = (m−1)/(m+1), |s| ≤ 0.172, whose odd series s·Σ s²ᵏ/(2k+1) is
/// below f64's resolution after 12 terms, summed by Estrin's scheme (a tree
/// of depth 4 rather than Horner's chain of 12).
#[inline(always)]
pub fn ln_in_range<T: Lanes>(x: T) -> T {
    /// 1/(2k+3) for k = 0..12: the series after its leading 1.
    const C: [f64; 12] = {
        let mut c = [0.0; 12];
        let mut k = 0;
        while k < 12 {
            c[k] = 1.0 / (2 * k + 3) as f64;
            k += 1;
        }
        c
    };
    let (mut m, mut e) = x.mantissa_and_exponent();
    // Centre m on 1.
    let (halved, raised) = (m * m.constant(0.5), e + e.constant(1.0));
    e = m.if_at_least(std::f64::consts::SQRT_2, raised, e);
    m = m.if_at_least(std::f64::consts::SQRT_2, halved, m);
    let one = m.constant(1.0);
    let s = (m - one) / (m + one);
    let t = s * s;
    // Σ C[k]·tᵏ by Estrin: pairs, then pairs of pairs, then the three quads.
    let p0 = t.constant(C[0]) + t.constant(C[1]) * t;
    let p1 = t.constant(C[2]) + t.constant(C[3]) * t;
    let p2 = t.constant(C[4]) + t.constant(C[5]) * t;
    let p3 = t.constant(C[6]) + t.constant(C[7]) * t;
    let p4 = t.constant(C[8]) + t.constant(C[9]) * t;
    let p5 = t.constant(C[10]) + t.constant(C[11]) * t;
    let t2 = t * t;
    let (q0, q1, q2) = (p0 + p1 * t2, p2 + p3 * t2, p4 + p5 * t2);
    let t4 = t2 * t2;
    let tail = (q0 + q1 * t4) + q2 * (t4 * t4);
    // ln m = 2s + 2s·t·tail: the leading term apart, so the series' rounding
    // touches only its last per cent.
    let two_s = m.constant(2.0) * s;
    e * e.constant(std::f64::consts::LN_2) + (two_s + two_s * t * tail)
}

/// `ln_in_range` where x is in its range, `f64::ln` elsewhere: the
/// logarithm of the distance estimate, for one value.
#[inline]
pub fn ln(x: f64) -> f64 {
    if in_ln_range(x) {
        ln_in_range(x)
    } else {
        x.ln()
    }
}

/// Whether `ln_in_range` is valid at `x`: x ≥ ½ and finite.
#[inline(always)]
pub fn in_ln_range(x: f64) -> bool {
    x >= 0.5 && x.is_finite()
}

macro_rules! impl_number_for_float {
    ($t:ty) => {
        impl Arith for $t {
            #[inline(always)]
            fn sqrt(self) -> Self {
                <$t>::sqrt(self)
            }
        }

        impl Number for $t {
            const EPSILON: Real = <$t>::EPSILON as Real;
            const MAX_LOG2: Real = <$t>::MAX_EXP as Real;
            #[inline(always)]
            fn from_real(v: Real) -> Self {
                v as $t
            }
            #[inline]
            fn value(self) -> Real {
                self as Real
            }
            #[inline]
            fn acos(self) -> Self {
                <$t>::acos(self)
            }
            #[inline]
            fn asin(self) -> Self {
                <$t>::asin(self)
            }
            #[inline]
            fn atan2(self, x: Self) -> Self {
                <$t>::atan2(self, x)
            }
            #[inline]
            fn sin_cos(self) -> (Self, Self) {
                <$t>::sin_cos(self)
            }
            #[inline]
            fn powf(self, n: Real) -> Self {
                <$t>::powf(self, n as $t)
            }
            #[inline]
            fn ln(self) -> Self {
                <$t>::ln(self)
            }
            #[inline]
            fn clamp_unit(self) -> Self {
                self.clamp(-1.0, 1.0)
            }
        }
    };
}
impl_number_for_float!(f64);
impl_number_for_float!(f32);

/// A value with its gradient with respect to the three coordinates of the
/// starting point: forward-mode automatic differentiation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dual<T> {
    pub v: T,
    pub d: [T; 3],
}

impl<T: Number> Dual<T> {
    pub fn constant(v: T) -> Self {
        let zero = T::from_real(0.0);
        Dual { v, d: [zero; 3] }
    }

    /// The `axis`-th coordinate as an independent variable.
    pub fn variable(v: T, axis: usize) -> Self {
        let mut x = Dual::constant(v);
        x.d[axis] = T::from_real(1.0);
        x
    }

    /// Applies the chain rule: f(v) with derivative f'(v) = `slope`.
    #[inline]
    fn chain(self, v: T, slope: T) -> Self {
        Dual {
            v,
            d: [self.d[0] * slope, self.d[1] * slope, self.d[2] * slope],
        }
    }
}

impl<T: Number> Add for Dual<T> {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Dual {
            v: self.v + o.v,
            d: [self.d[0] + o.d[0], self.d[1] + o.d[1], self.d[2] + o.d[2]],
        }
    }
}

impl<T: Number> Sub for Dual<T> {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        self + -o
    }
}

impl<T: Number> Neg for Dual<T> {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Dual {
            v: -self.v,
            d: [-self.d[0], -self.d[1], -self.d[2]],
        }
    }
}

impl<T: Number> Mul for Dual<T> {
    type Output = Self;
    #[inline]
    #[allow(clippy::suspicious_arithmetic_impl)] // the product rule adds
    fn mul(self, o: Self) -> Self {
        let d = |i: usize| self.d[i] * o.v + o.d[i] * self.v;
        Dual {
            v: self.v * o.v,
            d: [d(0), d(1), d(2)],
        }
    }
}

impl<T: Number> Div for Dual<T> {
    type Output = Self;
    #[inline]
    #[allow(clippy::suspicious_arithmetic_impl)] // the quotient rule subtracts
    fn div(self, o: Self) -> Self {
        let inv = T::from_real(1.0) / o.v;
        let v = self.v * inv;
        let d = |i: usize| (self.d[i] - v * o.d[i]) * inv;
        Dual {
            v,
            d: [d(0), d(1), d(2)],
        }
    }
}

impl<T: Number> Arith for Dual<T> {
    fn sqrt(self) -> Self {
        let s = self.v.sqrt();
        self.chain(s, T::from_real(0.5) / s)
    }
}

impl<T: Number> Number for Dual<T> {
    const EPSILON: Real = T::EPSILON;
    const MAX_LOG2: Real = T::MAX_LOG2;
    fn from_real(v: Real) -> Self {
        Dual::constant(T::from_real(v))
    }
    fn value(self) -> Real {
        self.v.value()
    }
    fn acos(self) -> Self {
        let one = T::from_real(1.0);
        self.chain(self.v.acos(), -(one / (one - self.v * self.v).sqrt()))
    }
    fn asin(self) -> Self {
        let one = T::from_real(1.0);
        self.chain(self.v.asin(), one / (one - self.v * self.v).sqrt())
    }
    fn atan2(self, x: Self) -> Self {
        // d atan2(y, x) = (x dy − y dx) / (x² + y²)
        let inv = T::from_real(1.0) / (x.v * x.v + self.v * self.v);
        let d = |i: usize| (x.v * self.d[i] - self.v * x.d[i]) * inv;
        Dual {
            v: self.v.atan2(x.v),
            d: [d(0), d(1), d(2)],
        }
    }
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.v.sin_cos();
        (self.chain(s, c), self.chain(c, -s))
    }
    fn powf(self, n: Real) -> Self {
        let p = self.v.powf(n - 1.0);
        self.chain(p * self.v, T::from_real(n) * p)
    }
    fn ln(self) -> Self {
        self.chain(self.v.ln(), T::from_real(1.0) / self.v)
    }
    fn clamp_unit(self) -> Self {
        let c = self.v.clamp_unit();
        if c.value() == self.v.value() {
            self
        } else {
            self.chain(c, T::from_real(0.0))
        }
    }
}

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

/// `count` points spread over the shell of radii `radius` around the origin,
/// from the sampler with `seed`: the same points every run.
pub fn shell_points(count: usize, radius: std::ops::Range<Real>, seed: u64) -> Vec<DVec3> {
    (0..count as u64)
        .map(|i| {
            let u = |d: u32| sample_1d(seed, 0, i, 0, d);
            let z = 2.0 * u(0) - 1.0;
            let phi = std::f64::consts::TAU * u(1);
            let s = (1.0 - z * z).sqrt();
            let r = radius.start + (radius.end - radius.start) * u(2);
            DVec3::new(s * phi.cos(), z, s * phi.sin()) * r
        })
        .collect()
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

/// A uniform number in [0, 1) from (seed, frame, pixel, sample, dimension):
/// a stateless hash, so samples never depend on evaluation order.
pub fn sample_1d(seed: u64, frame: u32, pixel: u64, sample: u32, dim: u32) -> Real {
    // SplitMix64 finaliser over a combined key.
    let mut x = seed
        ^ (frame as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ pixel.wrapping_mul(0xBF58_476D_1CE4_E5B9)
        ^ ((sample as u64) << 32 | dim as u64).wrapping_mul(0x94D0_49BB_1331_11EB);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^= x >> 31;
    (x >> 11) as Real / (1u64 << 53) as Real
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sampler_is_uniform_and_deterministic() {
        let mut sum = 0.0;
        for i in 0..10_000u64 {
            let u = sample_1d(7, 3, i, 0, 0);
            assert!((0.0..1.0).contains(&u));
            sum += u;
        }
        assert!((sum / 10_000.0 - 0.5).abs() < 0.01);
        assert_eq!(sample_1d(1, 2, 3, 4, 5), sample_1d(1, 2, 3, 4, 5));
        assert_ne!(sample_1d(1, 2, 3, 4, 5), sample_1d(1, 2, 3, 4, 6));
    }

    #[test]
    fn dual_numbers_match_finite_differences() {
        // f(x, y, z) = atan2(y, x) · sqrt(x² + z²) + ln(z) · acos(y / 2) + x^3.5
        fn f<T: Number>(x: T, y: T, z: T) -> T {
            y.atan2(x) * (x * x + z * z).sqrt()
                + z.ln() * (y / T::from_real(2.0)).acos()
                + x.powf(3.5)
        }
        let p: [f64; 3] = [0.7, -0.4, 1.3];
        let d = f(
            Dual::variable(p[0], 0),
            Dual::variable(p[1], 1),
            Dual::variable(p[2], 2),
        );
        assert!((d.v - f(p[0], p[1], p[2])).abs() < 1e-15);
        let h = 1e-6;
        for axis in 0..3 {
            let (mut a, mut b) = (p, p);
            a[axis] += h;
            b[axis] -= h;
            let fd = (f(a[0], a[1], a[2]) - f(b[0], b[1], b[2])) / (2.0 * h);
            assert!(
                (d.d[axis] - fd).abs() < 1e-7,
                "axis {axis}: {} vs {fd}",
                d.d[axis]
            );
        }
        let (s, c) = Dual::variable(0.3f64, 0).sin_cos();
        assert!((s.d[0] - 0.3f64.cos()).abs() < 1e-15 && (c.d[0] + 0.3f64.sin()).abs() < 1e-15);
        let q = Dual::variable(3.0f64, 1) / Dual::variable(2.0, 0);
        assert_eq!(q.d, [-0.75, 0.5, 0.0]);
    }

    /// Values across `ln_in_range`'s whole range: near its ends, around 1
    /// and √2 (where the reduction switches), powers of two and their
    /// neighbours, and a spread of ordinary values.
    fn ln_samples() -> Vec<f64> {
        let mut xs = vec![
            0.5,
            1.0,
            2.0,
            f64::MAX,
            f64::from_bits(0.5f64.to_bits() + 1),
        ];
        // Just below 1, a few ulp at a time.
        xs.extend((1..2_000).map(|k| 1.0 - k as f64 * f64::EPSILON / 2.0));
        // Where the result is largest for its reduction (|ln m| near ln √2),
        // which is where rounding the quotient costs the most.
        xs.extend((0..50_000).map(|i| 0.61 + i as f64 * (0.0971 / 50_000.0)));
        xs.extend((0..50_000).map(|i| std::f64::consts::SQRT_2 + i as f64 * (0.236 / 50_000.0)));
        for k in -1..1024 {
            let p = 2f64.powi(k);
            xs.extend([
                p,
                p * 1.000_000_1,
                p * 0.999_999_9,
                p * std::f64::consts::SQRT_2,
            ]);
        }
        for x in [std::f64::consts::SQRT_2, std::f64::consts::FRAC_1_SQRT_2] {
            xs.extend([
                x,
                f64::from_bits(x.to_bits() + 1),
                f64::from_bits(x.to_bits() - 1),
            ]);
        }
        xs.extend((0..20_000).map(|i| 0.5 + i as f64 * 0.0137));
        xs.extend((0..2_000).map(|i| 1.0 + (i as f64 * 1e-9)));
        xs.extend((0..5_000).map(|i| (i as f64 * 0.14).exp()));
        xs.retain(|&x| in_ln_range(x));
        xs
    }

    #[test]
    fn logarithm_is_within_two_ulp_of_the_library_one() {
        let mut worst = 0.0f64;
        for x in ln_samples() {
            let (ours, exact) = (ln(x), x.ln());
            // Error in units of the last place of the true value.
            let ulp = if exact == 0.0 {
                f64::MIN_POSITIVE
            } else {
                (f64::from_bits(exact.abs().to_bits() + 1) - exact.abs()).max(f64::MIN_POSITIVE)
            };
            let err = (ours - exact).abs() / ulp;
            assert!(
                err <= 2.0,
                "ln({x:e}) = {ours:e}, library {exact:e}: {err} ulp"
            );
            worst = worst.max(err);
        }
        assert!(worst > 0.0, "a different rounding somewhere is expected");
        // Outside the range it is the library's.
        for x in [0.25, 1e-300, 0.0, f64::INFINITY] {
            assert_eq!(ln(x).to_bits(), x.ln().to_bits());
        }
        assert!(ln(f64::NAN).is_nan() && ln(-1.0).is_nan());
    }

    #[test]
    fn vector_logarithm_matches_one_lane_at_a_time() {
        struct Logs<'a>(&'a [f64]);
        impl pulp::WithSimd for Logs<'_> {
            type Output = Vec<f64>;
            fn with_simd<S: pulp::Simd>(self, simd: S) -> Vec<f64> {
                let mut out = vec![0.0; self.0.len()];
                let lanes = S::F64_LANES;
                for (x, o) in self.0.chunks_exact(lanes).zip(out.chunks_exact_mut(lanes)) {
                    let v = Vector(simd, S::as_simd_f64s(x).0[0]);
                    S::as_mut_simd_f64s(o).0[0] = ln_in_range(v).1;
                }
                out
            }
        }
        let mut xs = ln_samples();
        xs.truncate(xs.len() / 8 * 8);
        let expected: Vec<u64> = xs.iter().map(|&x| ln(x).to_bits()).collect();
        let check = |got: Vec<f64>, arch: &str| {
            for (k, g) in got.iter().enumerate() {
                assert_eq!(g.to_bits(), expected[k], "{arch} at {:e}", xs[k]);
            }
        };
        use pulp::WithSimd;
        check(pulp::Arch::new().dispatch(Logs(&xs)), "dispatched");
        check(Logs(&xs).with_simd(pulp::Scalar::new()), "scalar");
        #[cfg(target_arch = "x86_64")]
        {
            if let Some(v3) = pulp::x86::V3::try_new() {
                check(Logs(&xs).with_simd(v3), "AVX2");
            }
            if let Some(v4) = pulp::x86::V4::try_new() {
                check(Logs(&xs).with_simd(v4), "AVX-512");
            }
        }
    }

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
}
