//! Each formula's power, from its `Shape`: the trigonometric form, and
//! whole powers by complex squaring without trigonometry.

use super::{Formula, Triplex};
use crate::math::{Arith, Number, Real};

#[inline(always)]
pub(super) fn length_squared<T: Arith>(z: Triplex<T>) -> T {
    z[0] * z[0] + z[1] * z[1] + z[2] * z[2]
}

/// Where a formula's power puts its axes: the spherical power turns a
/// point's polar angle, from its pole coordinate, by n, and its azimuth,
/// the angle of its equatorial pair, by n too (the bulb) or not at all
/// (the quaternion). Every form of the power (scalar, vector, dual
/// numbers, high precision, perturbed) reads it, so a formula of this
/// family is one row of `Formula::shape`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Shape {
    /// The pole coordinate's index.
    pub(crate) pole: usize,
    /// The equatorial pair's indices, in the order whose angle is the azimuth.
    pub(crate) equator: [usize; 2],
    /// Whether the polar angle is measured from the equator (asin).
    pub(crate) from_equator: bool,
    /// Whether zⁿ multiplies the azimuth by n.
    pub(crate) turns_azimuth: bool,
}

impl Shape {
    /// The pole coordinate and the equatorial pair of `z`.
    #[inline(always)]
    pub(crate) fn split<T: Copy>(self, z: Triplex<T>) -> (T, [T; 2]) {
        (z[self.pole], self.equator.map(|k| z[k]))
    }

    /// How near the pole axis, as a share of r², the whole power hands
    /// over to the trigonometric form: the bulb's azimuth is undefined on
    /// the axis and loses bits beside it; the quaternion's, kept as the
    /// equatorial pair over ρ, stays exact until ρ² is 0.
    #[inline(always)]
    pub(crate) const fn axis_margin(self) -> Real {
        if self.turns_azimuth {
            1e-12
        } else {
            0.0
        }
    }

    /// The point whose pole coordinate and equatorial pair are given.
    #[inline(always)]
    pub(crate) fn join<T: Clone>(self, pole: T, [e1, e2]: [T; 2]) -> Triplex<T> {
        let mut out = [pole.clone(), pole.clone(), pole];
        (out[self.equator[0]], out[self.equator[1]]) = (e1, e2);
        out
    }
}

/// Raises `z` (with length `r`, already computed) to the power `n` in the given
/// convention with trigonometric functions. The origin maps to itself.
#[inline]
pub fn triplex_power_trig<T: Number>(formula: Formula, z: Triplex<T>, r: T, n: Real) -> Triplex<T> {
    triplex_power_trig_scaled(formula, z, r, n, r.powf(n))
}

/// `triplex_power_trig` with rⁿ = `rn` already known.
#[inline]
pub(super) fn triplex_power_trig_scaled<T: Number>(
    formula: Formula,
    z: Triplex<T>,
    r: T,
    n: Real,
    rn: T,
) -> Triplex<T> {
    let rv = r.value();
    if rv <= 0.0 || !rv.is_finite() {
        return [T::from_real(0.0); 3];
    }
    let shape = formula.shape();
    let nn = T::from_real(n);
    let (pole, [e1, e2]) = shape.split(z);
    let ratio = (pole / r).clamp_unit();
    // The quaternion's angle by atan2: acos loses it near the axis, where
    // its whole power stays exact (`Shape::axis_margin`).
    let angle = if shape.from_equator {
        ratio.asin()
    } else if shape.turns_azimuth {
        ratio.acos()
    } else {
        (e1 * e1 + e2 * e2).sqrt().atan2(pole)
    };
    let (st, ct) = (angle * nn).sin_cos();
    let (sp, cp) = if shape.turns_azimuth {
        (e2.atan2(e1) * nn).sin_cos()
    } else {
        // The azimuth's own cosine and sine; none on the pole axis.
        let rho = (e1 * e1 + e2 * e2).sqrt();
        match rho.value() > 0.0 {
            true => (e2 / rho, e1 / rho),
            false => (T::from_real(0.0), T::from_real(0.0)),
        }
    };
    let (along, across) = if shape.from_equator {
        (st, ct)
    } else {
        (ct, st)
    };
    shape.join(along * rn, [across * cp * rn, across * sp * rn])
}

/// `x` to the integer power `n` ≥ 1 by repeated squaring: about 2·log₂(n)
/// multiplications where `powf` calls `exp(n·ln x)`; with `n` a constant
/// the loops unroll into straight-line code.
#[inline(always)]
pub fn powi<T: Copy>(x: T, n: u32, mul: impl Fn(T, T) -> T) -> T {
    debug_assert!(n >= 1);
    let (mut base, mut k) = (x, n.max(1));
    while k & 1 == 0 {
        base = mul(base, base);
        k >>= 1;
    }
    let mut result = base;
    k >>= 1;
    while k > 0 {
        base = mul(base, base);
        if k & 1 == 1 {
            result = mul(result, base);
        }
        k >>= 1;
    }
    result
}

/// The complex number (re, im) to the integer power `n` ≥ 1.
#[inline(always)]
pub(super) fn complex_powi<T: Arith>(re: T, im: T, n: u32) -> (T, T) {
    powi((re, im), n, |(a, b), (c, d)| (a * c - b * d, a * d + b * c))
}

/// The integer power `n` of a point whose exponent is a whole number, with no
/// trigonometry: the spherical power multiplies the polar angle by n (and
/// the bulb's azimuth too), and an angle times n is the argument of a
/// complex number to the n-th power (de Moivre). The polar angle comes from
/// (pole, ρ) as one complex number, the azimuth from the unit vector of the
/// equatorial pair as another, where ρ is the distance from the pole axis;
/// multiplying them out gives each formula's result (`Shape`). For the
/// bulb's n = 8 that is three complex squarings each, cheaper than Quilez's
/// expanded polynomial, which this replaces. Returns `None` within
/// `Shape::axis_margin` of the pole axis; the caller then uses the
/// trigonometric form, which is exact there.
#[inline(always)]
pub fn triplex_power_int<T: Number>(formula: Formula, z: Triplex<T>, n: u32) -> Option<Triplex<T>> {
    let (out, rho2, r2) = triplex_power_int_unchecked(formula, z, n, T::from_real(1.0));
    // ρ² > margin·r² also fails for an infinite or NaN r².
    let margin = formula.shape().axis_margin();
    // The product in T's own rounding, as the vector kernels take it.
    let usable = rho2.value() > (T::from_real(margin) * r2).value()
        && out.iter().all(|v| v.value().is_finite());
    usable.then_some(out)
}

/// `triplex_power_int` without its checks, for any `Arith` (one point or a
/// `Vector` of them; `one` is its 1): the power, ρ² and r², which the
/// callers test. Branch-free, so lanes near the axis compute values the
/// caller replaces.
#[inline(always)]
pub(super) fn triplex_power_int_unchecked<T: Arith>(
    formula: Formula,
    z: Triplex<T>,
    n: u32,
    one: T,
) -> (Triplex<T>, T, T) {
    let shape = formula.shape();
    let (pole, [e1, e2]) = shape.split(z);
    let rho2 = e1 * e1 + e2 * e2;
    let r2 = rho2 + pole * pole;
    let rho = rho2.sqrt();
    // cos mφ + i sin mφ: (e1 + i·e2)ᵐ = ρᵐ(cos mφ + i sin mφ), divided by ρᵐ,
    // for the azimuth's power m (n, or 1 where it is kept). For even m, ρᵐ
    // comes from ρ² directly, so the division runs beside the square root
    // instead of after it.
    let m = if shape.turns_azimuth { n } else { 1 };
    let mul = |a: T, b: T| a * b;
    let rho_m = if m.is_multiple_of(2) {
        powi(rho2, m / 2, mul)
    } else {
        powi(rho, m, mul)
    };
    let inv_rho_m = one / rho_m;
    let (a, b) = complex_powi(e1, e2, m);
    let (cp, sp) = (a * inv_rho_m, b * inv_rho_m);
    // rⁿ(cos nθ + i sin nθ): θ from the pole, (pole + iρ)ⁿ; from the
    // equator (asin), (ρ + i·pole)ⁿ. The pole takes the part along it.
    let out = if shape.from_equator {
        let (rc, rs) = complex_powi(rho, pole, n);
        shape.join(rs, [rc * cp, rc * sp])
    } else {
        let (rc, rs) = complex_powi(pole, rho, n);
        shape.join(rc, [rs * cp, rs * sp])
    };
    (out, rho2, r2)
}

/// Quilez's expanded power-8 polynomial ("Mandelbulb", "Optimizing"), kept only
/// so the kernel benchmark can compare it with `triplex_power_int`.
#[inline]
pub fn power8_polynomial<T: Number>(w: Triplex<T>) -> Option<Triplex<T>> {
    let [x, y, z] = w;
    let (x2, y2, z2) = (x * x, y * y, z * z);
    let k3 = x2 + z2;
    let r2 = k3 + y2;
    let off_axis = k3.value() > 1e-12 * r2.value();
    if !off_axis || !r2.value().is_finite() {
        return None;
    }
    let c = T::from_real;
    let (x4, y4, z4) = (x2 * x2, y2 * y2, z2 * z2);
    let k3_2 = k3 * k3;
    let k2 = c(1.0) / (k3_2 * k3_2 * k3_2 * k3).sqrt();
    let k1 = x4 + y4 + z4 - c(6.0) * y2 * z2 - c(6.0) * x2 * y2 + c(2.0) * z2 * x2;
    let k4 = x2 - y2 + z2;
    let out = [
        c(64.0) * x * y * z * (x2 - z2) * k4 * (x4 - c(6.0) * x2 * z2 + z4) * k1 * k2,
        c(-16.0) * y2 * k3 * k4 * k4 + k1 * k1,
        c(-8.0)
            * y
            * k4
            * (x4 * x4 - c(28.0) * x4 * x2 * z2 + c(70.0) * x4 * z4 - c(28.0) * x2 * z2 * z4
                + z4 * z4)
            * k1
            * k2,
    ];
    out.iter().all(|v| v.value().is_finite()).then_some(out)
}

/// `n` as a whole number in 2..=64, if it is one.
#[inline]
pub fn whole_power(n: Real) -> Option<u32> {
    // Compared through the integer, not `fract`, which is a call into libm
    // on x86-64's baseline, once per call of the lane kernel.
    ((2.0..=64.0).contains(&n) && (n as u32) as Real == n).then_some(n as u32)
}

/// One power step for a whole exponent `n`: (zⁿ, rⁿ⁻¹), the second for the
/// running derivative, both without `powf` or trigonometry off the pole axis.
#[inline(always)]
pub(super) fn whole_power_step<T: Number>(
    formula: Formula,
    z: Triplex<T>,
    r: T,
    n: u32,
) -> (Triplex<T>, T) {
    let w = triplex_power_int(formula, z, n)
        .unwrap_or_else(|| triplex_power_trig(formula, z, r, n as Real));
    // `whole_power` guarantees n ≥ 2.
    (w, powi(r, n - 1, |a, b| a * b))
}
