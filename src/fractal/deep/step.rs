//! The perturbed power step: (Z + δ)ⁿ − Zⁿ for a reference point Z and a
//! small δ, to δ's own relative precision, where subtracting the two
//! powers in f64 would keep nothing of δ once it is below 2⁻⁵²·|Z|.
//!
//! The whole power is a product of two complex powers (`power.rs`): qⁿ with
//! q = pole + iρ (or ρ + i·pole for the asin form) and uᵐ with u the unit
//! equatorial direction (m = n for the bulb, 1 for the quaternion). Each difference is taken exactly in δ: ρ′ − ρ as
//! (ρ′² − ρ²)/(ρ′ + ρ), u′ − u as (δw − u·δρ)/ρ′, a′ⁿ − aⁿ as
//! (a′ − a)·Σ a′ⁿ⁻¹⁻ʲ·aʲ, and a product's as δa·b′ + a·δb.

use super::super::{Formula, Triplex};
use crate::exact::Big;
use crate::math::{Arith, Number, Real, Vector};

/// What the perturbed step computes with: one number of the kernel's types
/// (f64, f32, dual numbers) or a `Vector` of f64 lanes, alike operation
/// for operation, so one lane of a vector gets one f64's bits.
pub(crate) trait Delta: Arith {
    /// `v` (in every lane).
    fn constant(self, v: Real) -> Self;
    /// Lane by lane: `then` where `self` > 0, else `otherwise`.
    fn positive_or(self, then: Self, otherwise: Self) -> Self;
    /// Whether `self` > 0 in every lane.
    fn all_positive(self) -> bool;
}

impl<T: Number> Delta for T {
    #[inline(always)]
    fn constant(self, v: Real) -> Self {
        T::from_real(v)
    }
    #[inline(always)]
    fn positive_or(self, then: Self, otherwise: Self) -> Self {
        if self.value() > 0.0 {
            then
        } else {
            otherwise
        }
    }
    #[inline(always)]
    fn all_positive(self) -> bool {
        self.value() > 0.0
    }
}

impl<S: pulp::Simd> Delta for Vector<S> {
    #[inline(always)]
    fn constant(self, v: Real) -> Self {
        Vector::splat(self.0, v)
    }
    #[inline(always)]
    fn positive_or(self, then: Self, otherwise: Self) -> Self {
        let simd = self.0;
        let mask = simd.greater_than_f64s(self.1, simd.splat_f64s(0.0));
        Vector(simd, simd.select_f64s(mask, then.1, otherwise.1))
    }
    #[inline(always)]
    fn all_positive(self) -> bool {
        let simd = self.0;
        let not = simd.not_m64s(simd.greater_than_f64s(self.1, simd.splat_f64s(0.0)));
        simd.first_true_m64s(not) >= S::F64_LANES
    }
}

/// A complex number of the kernel's type.
#[derive(Clone, Copy)]
pub(super) struct C<T>(pub T, pub T);

impl<T: Delta> C<T> {
    #[inline(always)]
    fn add(self, o: C<T>) -> C<T> {
        C(self.0 + o.0, self.1 + o.1)
    }
    #[inline(always)]
    fn mul(self, o: C<T>) -> C<T> {
        C(self.0 * o.0 - self.1 * o.1, self.0 * o.1 + self.1 * o.0)
    }
    #[inline(always)]
    fn constant(like: T, c: [Real; 2]) -> C<T> {
        C(like.constant(c[0]), like.constant(c[1]))
    }
}

/// What the step needs of one reference point, all from its f64 value.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Point {
    /// The pole coordinate and the equatorial pair (`Shape::split`).
    pub pole: Real,
    pub equator: [Real; 2],
    /// Distance from the pole axis.
    pub rho: Real,
    /// qʲ for j = 0..=n and uʲ for j = 0..=m (index j; `Shape`).
    pub q_powers: Vec<[Real; 2]>,
    pub u_powers: Vec<[Real; 2]>,
    /// The equatorial pair and ρ times 2ᵏ (`Far`), for offsets whose
    /// squares f64 cannot hold.
    pub far: Far,
}

/// A reference point's distance from the pole axis, and its equatorial
/// pair, scaled by 2ᵏ into f64's range: offsets below 2⁻⁵⁰⁰ (past 1e-150)
/// lose their squares, and a reference by the axis its equatorial pair
/// (`off_the_axis` puts it 2⁻⁽ᵇⁱᵗˢ⁻³²⁾ of its size away), so the step takes
/// ρ′ − ρ and u′ − u for them at that scale, where both are whole.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Far {
    pub scale: Real,
    pub equator: [Real; 2],
    pub rho: Real,
}

/// Below this distance from the pole axis f64's pair loses bits (it
/// nears the subnormals): u is taken from the exact pair.
const NEAR_AXIS: Real = 1e-290;

/// Offsets from the pole axis below this (their squares below 2⁻¹⁰⁰⁰)
/// take the step's scaled form (`Far`).
const TINY_SQUARED: Real = 9.332636185032189e-302; // 2⁻¹⁰⁰⁰

/// The most a `Far` scales by: 2ᵏ for k ≤ this keeps offsets up to 2⁻⁵⁰⁰
/// (`TINY_SQUARED`'s root) and their squares within f64's range.
const MOST_FAR: i32 = 1000;

/// q from the pole coordinate and ρ: the complex number whose argument is
/// the polar angle in the formula's convention.
#[inline(always)]
fn q_of<T: Copy>(formula: Formula, pole: T, rho: T) -> C<T> {
    match formula.shape().from_equator {
        true => C(rho, pole),
        false => C(pole, rho),
    }
}

impl Point {
    /// The step's data for reference point `z` (in high precision) and
    /// power `n`; `None` on the pole axis (and at the origin), where u is
    /// undefined.
    pub fn new(formula: Formula, z: &[Big; 3], n: u32) -> Option<Point> {
        let rounded = z.each_ref().map(|v| v.to_f64().value());
        let (pole, equator) = formula.shape().split(rounded);
        let (_, [e1, e2]) = formula.shape().split(z.each_ref());
        let exact_rho = (e1 * e1 + e2 * e2).sqrt();
        if exact_rho == Big::ZERO {
            return None;
        }
        let far = Far::new(e1, e2, &exact_rho);
        let rho = equator[0].hypot(equator[1]);
        if !rho.is_finite() {
            return None;
        }
        // Where f64 holds ρ to its last bit u comes from the rounded pair
        // (as it always has); nearer the axis, from the exact one.
        let u = if rho >= NEAR_AXIS {
            [equator[0] / rho, equator[1] / rho]
        } else {
            [e1, e2].map(|e| (e / &exact_rho).to_f64().value())
        };
        let powers = |a: [Real; 2], n: u32| {
            let mut out = vec![[1.0, 0.0]];
            for _ in 0..n {
                let p = out[out.len() - 1];
                out.push([p[0] * a[0] - p[1] * a[1], p[0] * a[1] + p[1] * a[0]]);
            }
            out
        };
        let q = q_of(formula, pole, rho);
        Some(Point {
            pole,
            equator,
            rho,
            q_powers: powers([q.0, q.1], n),
            // The azimuth turns n times, or not at all (`Shape`).
            u_powers: powers(u, if formula.shape().turns_azimuth { n } else { 1 }),
            far,
        })
    }

    /// (Z + δ)ⁿ − Zⁿ for this reference point Z.
    #[inline(always)]
    pub fn power_difference<T: Delta>(&self, formula: Formula, delta: Triplex<T>) -> Triplex<T> {
        let (n, m) = (self.q_powers.len() - 1, self.u_powers.len() - 1);
        let like = delta[0];
        let k = |v: Real| like.constant(v);
        let (d_pole, [d1, d2]) = formula.shape().split(delta);
        let [e1, e2] = self.equator.map(k);
        let rho = k(self.rho);
        // uᵐ's difference; on the axis uᵐ's factor below is 0, so any u does.
        let u = C::constant(like, self.u_powers[1]);
        let (mut d_rho, mut d_u) = equatorial_differences([e1, e2], rho, [d1, d2], u);
        let usual = d1 * d1 + d2 * d2 - k(TINY_SQUARED);
        if !usual.all_positive() {
            let (far_rho, far_u) = self.far.differences([d1, d2], u);
            d_rho = usual.positive_or(d_rho, far_rho);
            d_u = C(
                usual.positive_or(d_u.0, far_u.0),
                usual.positive_or(d_u.1, far_u.1),
            );
        }
        // qⁿ's difference.
        let d_q = q_of(formula, d_pole, d_rho);
        let q_pixel = C::constant(like, self.q_powers[1]).add(d_q);
        let d_qn = d_q.mul(geometric_sum(q_pixel, &self.q_powers[..n]));
        let d_un = d_u.mul(geometric_sum(u.add(d_u), &self.u_powers[..m]));
        let [qc, qs] = self.q_powers[n].map(k);
        let un = C::constant(like, self.u_powers[m]);
        let un_pixel = un.add(d_un);
        // (radial part) × (azimuthal part), differenced as δa·b′ + a·δb.
        let times_u = |a: T, d_a: T| [d_a * un_pixel.0 + a * d_un.0, d_a * un_pixel.1 + a * d_un.1];
        // Along the pole rc and across it rs·uᵐ, or the other way round
        // from the equator (asin).
        match formula.shape().from_equator {
            false => formula.shape().join(d_qn.0, times_u(qs, d_qn.1)),
            true => formula.shape().join(d_qn.1, times_u(qc, d_qn.0)),
        }
    }
}

impl Far {
    /// The scale that brings `rho` (> 0) near 1, up to 2^`MOST_FAR`, and
    /// the pair and ρ at that scale.
    fn new(e1: &Big, e2: &Big, rho: &Big) -> Far {
        // Where f64 holds ρ, its own log; below, ρ is at least 2⁻¹²⁰⁰ of the
        // reference's size (`crate::deep::bits`).
        let plain = rho.to_f64().value();
        let log2 = if plain >= NEAR_AXIS {
            plain.log2()
        } else {
            (rho.clone() << 1200).to_f64().value().log2() - 1200.0
        };
        let k = ((-log2).floor() as i32).clamp(0, MOST_FAR);
        let at = |v: &Big| (v.clone() << k as isize).to_f64().value();
        Far {
            scale: (2.0 as Real).powi(k),
            equator: [at(e1), at(e2)],
            rho: at(rho),
        }
    }

    /// ρ′ − ρ and u′ − u for the equatorial offset `[d1, d2]` (each lane
    /// under 2⁻⁵⁰⁰), taken at the scale where they are whole.
    #[inline(always)]
    fn differences<T: Delta>(&self, [d1, d2]: [T; 2], u: C<T>) -> (T, C<T>) {
        let k = |v: Real| d1.constant(v);
        let scaled = [d1 * k(self.scale), d2 * k(self.scale)];
        let (d_rho, d_u) = equatorial_differences(self.equator.map(k), k(self.rho), scaled, u);
        (d_rho * k(1.0 / self.scale), d_u)
    }
}

/// ρ′ − ρ and u′ − u for a reference point's equatorial pair `e` (ρ from
/// the pole axis, unit direction `u`) moved by `d`: (2e·d + d·d)/(ρ′ + ρ)
/// and (d − u·δρ)/ρ′, each exact in d. u′ − u is 0 where ρ′ is.
#[inline(always)]
fn equatorial_differences<T: Delta>(
    [e1, e2]: [T; 2],
    rho: T,
    [d1, d2]: [T; 2],
    u: C<T>,
) -> (T, C<T>) {
    let k = |v: Real| d1.constant(v);
    // The pixel's distance from the pole axis, and its difference.
    let (w1, w2) = (e1 + d1, e2 + d2);
    let rho_pixel = (w1 * w1 + w2 * w2).sqrt();
    let d_rho = (k(2.0) * (e1 * d1 + e2 * d2) + d1 * d1 + d2 * d2) / (rho_pixel + rho);
    let (inverse, zero) = (k(1.0) / rho_pixel, k(0.0));
    let d_u = C(
        rho_pixel.positive_or((d1 - u.0 * d_rho) * inverse, zero),
        rho_pixel.positive_or((d2 - u.1 * d_rho) * inverse, zero),
    );
    (d_rho, d_u)
}

/// Σ a′ⁿ⁻¹⁻ʲ·aʲ over j = 0..n given aʲ (`powers`, n of them):
/// (a′ⁿ − aⁿ)/(a′ − a) without the division. For n a power of two it is
/// Π (a′^(2ⁱ) + a^(2ⁱ)) over 2ⁱ < n (a′⁸ − a⁸ = (a′ − a)(a′ + a)(a′² + a²)
/// (a′⁴ + a⁴)): 4 products for the classic 8 where Horner's rule takes 7.
#[inline(always)]
fn geometric_sum<T: Delta>(a_pixel: C<T>, powers: &[[Real; 2]]) -> C<T> {
    let like = a_pixel.0;
    let n = powers.len();
    if n.is_power_of_two() && n > 1 {
        let (mut power, mut k) = (a_pixel, 1);
        let mut product = power.add(C::constant(like, powers[1]));
        while 2 * k < n {
            (power, k) = (power.mul(power), 2 * k);
            product = product.mul(power.add(C::constant(like, powers[k])));
        }
        return product;
    }
    let mut sum = C::constant(like, powers[0]);
    for &p in &powers[1..] {
        sum = sum.mul(a_pixel).add(C::constant(like, p));
    }
    sum
}
