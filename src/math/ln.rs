//! A natural logarithm built from the four operations and bit masks, so
//! that one f64 and a vector lane get the same bits.

use super::{Arith, Vector};

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

#[cfg(test)]
mod tests {
    use super::*;

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
}
