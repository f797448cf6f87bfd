//! The triplex power in each angle convention: the trigonometric form, and
//! whole powers by complex squaring without trigonometry.

use super::{Formula, Triplex};
use crate::math::{Arith, Number, Real};

#[inline(always)]
pub(super) fn length_squared<T: Arith>(z: Triplex<T>) -> T {
    z[0] * z[0] + z[1] * z[1] + z[2] * z[2]
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
    let nn = T::from_real(n);
    let [x, y, zz] = z;
    match formula {
        Formula::Quilez => {
            let (st, ct) = ((y / r).clamp_unit().acos() * nn).sin_cos();
            let (sp, cp) = (x.atan2(zz) * nn).sin_cos();
            [st * sp * rn, ct * rn, st * cp * rn]
        }
        Formula::WhiteNylander => {
            let (st, ct) = ((zz / r).clamp_unit().acos() * nn).sin_cos();
            let (sp, cp) = (y.atan2(x) * nn).sin_cos();
            [st * cp * rn, st * sp * rn, ct * rn]
        }
        Formula::Asin => {
            let (st, ct) = ((zz / r).clamp_unit().asin() * nn).sin_cos();
            let (sp, cp) = (y.atan2(x) * nn).sin_cos();
            [ct * cp * rn, ct * sp * rn, st * rn]
        }
    }
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
/// trigonometry: the spherical power multiplies both angles by n, and an angle
/// times n is the argument of a complex number to the n-th power (de Moivre).
/// The polar angle comes from (pole, ρ) as one complex number, the azimuth
/// from the unit vector of the equatorial pair as another, where ρ is the
/// distance from the pole axis; multiplying them out gives the three
/// conventions of Quilez's "Mandelbulb" with the trigonometric form's exact result. For
/// n = 8 that is three complex squarings each, cheaper than Quilez's
/// expanded polynomial, which this replaces. Returns `None` within a relative
/// 1e-6 of the pole axis, where the azimuth is undefined; the caller then
/// uses the trigonometric form, which is exact there.
#[inline(always)]
pub fn triplex_power_int<T: Number>(formula: Formula, z: Triplex<T>, n: u32) -> Option<Triplex<T>> {
    let (out, rho2, r2) = triplex_power_int_unchecked(formula, z, n, T::from_real(1.0));
    // ρ² > 1e-12·r² also fails for an infinite or NaN r².
    let usable = rho2.value() > 1e-12 * r2.value() && out.iter().all(|v| v.value().is_finite());
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
    let [x, y, zz] = z;
    // The pole coordinate and the equatorial pair whose angle is the azimuth.
    let (pole, (e1, e2)) = match formula {
        Formula::Quilez => (y, (zz, x)),
        Formula::WhiteNylander | Formula::Asin => (zz, (x, y)),
    };
    let rho2 = e1 * e1 + e2 * e2;
    let r2 = rho2 + pole * pole;
    let rho = rho2.sqrt();
    // cos nφ + i sin nφ: (e1 + i·e2)ⁿ = ρⁿ(cos nφ + i sin nφ), divided by ρⁿ.
    // For even n, ρⁿ comes from ρ² directly, so the division runs beside
    // the square root instead of after it.
    let mul = |a: T, b: T| a * b;
    let rho_n = if n.is_multiple_of(2) {
        powi(rho2, n / 2, mul)
    } else {
        powi(rho, n, mul)
    };
    let inv_rho_n = one / rho_n;
    let (a, b) = complex_powi(e1, e2, n);
    let (cp, sp) = (a * inv_rho_n, b * inv_rho_n);
    // rⁿ(cos nθ + i sin nθ): θ from the pole, (pole + iρ)ⁿ; from the
    // equator (asin), (ρ + i·pole)ⁿ.
    let (rc, rs) = match formula {
        Formula::Asin => complex_powi(rho, pole, n),
        Formula::Quilez | Formula::WhiteNylander => complex_powi(pole, rho, n),
    };
    let out = match formula {
        Formula::Quilez => [rs * sp, rc, rs * cp],
        Formula::WhiteNylander => [rs * cp, rs * sp, rc],
        Formula::Asin => [rc * cp, rc * sp, rs],
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
    (n.fract() == 0.0 && (2.0..=64.0).contains(&n)).then_some(n as u32)
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
