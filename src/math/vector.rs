//! A SIMD register of f64 or f32 lanes as one number of the kernel's
//! arithmetic.

use super::Arith;
use std::ops::{Add, Div, Mul, Sub};

/// One SIMD register of `E` (f64 by default; as many lanes as the
/// instruction set `S` has), with the token that proves the instructions
/// exist. Each operation is one IEEE instruction per lane, the same
/// operation a lone `E` takes, so results are bit-identical.
#[derive(Clone, Copy, Debug)]
pub struct Vector<S: pulp::Simd, E: Lane = f64>(pub S, pub E::Reg<S>);

impl<S: pulp::Simd, E: Lane> Vector<S, E> {
    #[inline(always)]
    pub fn splat(simd: S, v: f64) -> Self {
        Vector(simd, E::splat(simd, E::from_f64(v)))
    }
}

/// A float a register holds lanes of: the register and mask types of each
/// instruction set, and the lane-wise operations the kernel takes on them.
pub trait Lane: Copy + PartialOrd + Default + 'static {
    type Reg<S: pulp::Simd>: Copy + std::fmt::Debug;
    type Mask<S: pulp::Simd>: Copy;
    /// A register's lanes in memory, cache-line aligned.
    type Stored: Copy + Default + AsRef<[Self]> + AsMut<[Self]>;
    fn lanes<S: pulp::Simd>() -> usize;
    fn from_f64(v: f64) -> Self;
    fn splat<S: pulp::Simd>(simd: S, v: Self) -> Self::Reg<S>;
    fn add<S: pulp::Simd>(simd: S, a: Self::Reg<S>, b: Self::Reg<S>) -> Self::Reg<S>;
    fn sub<S: pulp::Simd>(simd: S, a: Self::Reg<S>, b: Self::Reg<S>) -> Self::Reg<S>;
    fn mul<S: pulp::Simd>(simd: S, a: Self::Reg<S>, b: Self::Reg<S>) -> Self::Reg<S>;
    fn div<S: pulp::Simd>(simd: S, a: Self::Reg<S>, b: Self::Reg<S>) -> Self::Reg<S>;
    fn sqrt<S: pulp::Simd>(simd: S, a: Self::Reg<S>) -> Self::Reg<S>;
    fn abs<S: pulp::Simd>(simd: S, a: Self::Reg<S>) -> Self::Reg<S>;
    fn select<S: pulp::Simd>(
        simd: S,
        mask: Self::Mask<S>,
        a: Self::Reg<S>,
        b: Self::Reg<S>,
    ) -> Self::Reg<S>;
    fn less<S: pulp::Simd>(simd: S, a: Self::Reg<S>, b: Self::Reg<S>) -> Self::Mask<S>;
    fn greater<S: pulp::Simd>(simd: S, a: Self::Reg<S>, b: Self::Reg<S>) -> Self::Mask<S>;
    fn equal<S: pulp::Simd>(simd: S, a: Self::Reg<S>, b: Self::Reg<S>) -> Self::Mask<S>;
    fn and<S: pulp::Simd>(simd: S, a: Self::Mask<S>, b: Self::Mask<S>) -> Self::Mask<S>;
    fn not<S: pulp::Simd>(simd: S, a: Self::Mask<S>) -> Self::Mask<S>;
    fn first_true<S: pulp::Simd>(simd: S, a: Self::Mask<S>) -> usize;
    /// What `past` compares |z|² with for an orbit to be past the squared
    /// escape radius `e2`, which the scalar orbit tests in f64.
    fn escape_bound(e2: f64) -> Self;
    /// The lanes whose |z|² `r2`, as f64, is above the `e2` that gave
    /// `bound` (`escape_bound`): bit for bit the scalar test.
    fn past<S: pulp::Simd>(simd: S, r2: Self::Reg<S>, bound: Self::Reg<S>) -> Self::Mask<S>;
    /// The register of the first `lanes::<S>()` values of `a`.
    fn load<S: pulp::Simd>(a: &[Self]) -> Self::Reg<S>;
    /// `v` into the first `lanes::<S>()` values of `a`.
    fn store<S: pulp::Simd>(v: Self::Reg<S>, a: &mut [Self]);
}

/// One register's f64 lanes in memory (AVX-512's eight at most), aligned
/// to a whole cache line so that moving a 512-bit register to or from it
/// never splits across two lines, wherever the stack happens to be.
#[derive(Clone, Copy, Default)]
#[repr(C, align(64))]
pub struct Stored(pub [f64; 8]);

impl Stored {
    pub const ZERO: Stored = Stored([0.0; 8]);
}

impl std::ops::Deref for Stored {
    type Target = [f64; 8];
    fn deref(&self) -> &[f64; 8] {
        &self.0
    }
}

impl std::ops::DerefMut for Stored {
    fn deref_mut(&mut self) -> &mut [f64; 8] {
        &mut self.0
    }
}

impl AsRef<[f64]> for Stored {
    fn as_ref(&self) -> &[f64] {
        &self.0
    }
}

impl AsMut<[f64]> for Stored {
    fn as_mut(&mut self) -> &mut [f64] {
        &mut self.0
    }
}

/// One register's f32 lanes in memory (AVX-512's sixteen at most).
#[derive(Clone, Copy, Default)]
#[repr(C, align(64))]
pub struct Stored32(pub [f32; 16]);

impl AsRef<[f32]> for Stored32 {
    fn as_ref(&self) -> &[f32] {
        &self.0
    }
}

impl AsMut<[f32]> for Stored32 {
    fn as_mut(&mut self) -> &mut [f32] {
        &mut self.0
    }
}

macro_rules! lane {
    ($t:ty, $stored:ty, $lanes:ident, $splat:ident, $add:ident, $sub:ident,
     $mul:ident, $div:ident, $sqrt:ident, $abs:ident, $select:ident, $lt:ident, $gt:ident,
     $eq:ident, $and:ident, $not:ident, $first:ident, $as:ident, $as_mut:ident,
     $reg:ident, $mask:ident, $past:ident, $bound:path) => {
        impl Lane for $t {
            type Reg<S: pulp::Simd> = S::$reg;
            type Mask<S: pulp::Simd> = S::$mask;
            type Stored = $stored;
            #[inline(always)]
            fn lanes<S: pulp::Simd>() -> usize {
                S::$lanes
            }
            #[inline(always)]
            fn from_f64(v: f64) -> Self {
                v as $t
            }
            #[inline(always)]
            fn splat<S: pulp::Simd>(simd: S, v: Self) -> S::$reg {
                simd.$splat(v)
            }
            #[inline(always)]
            fn add<S: pulp::Simd>(simd: S, a: S::$reg, b: S::$reg) -> S::$reg {
                simd.$add(a, b)
            }
            #[inline(always)]
            fn sub<S: pulp::Simd>(simd: S, a: S::$reg, b: S::$reg) -> S::$reg {
                simd.$sub(a, b)
            }
            #[inline(always)]
            fn mul<S: pulp::Simd>(simd: S, a: S::$reg, b: S::$reg) -> S::$reg {
                simd.$mul(a, b)
            }
            #[inline(always)]
            fn div<S: pulp::Simd>(simd: S, a: S::$reg, b: S::$reg) -> S::$reg {
                simd.$div(a, b)
            }
            #[inline(always)]
            fn sqrt<S: pulp::Simd>(simd: S, a: S::$reg) -> S::$reg {
                simd.$sqrt(a)
            }
            #[inline(always)]
            fn abs<S: pulp::Simd>(simd: S, a: S::$reg) -> S::$reg {
                simd.$abs(a)
            }
            #[inline(always)]
            fn select<S: pulp::Simd>(simd: S, m: S::$mask, a: S::$reg, b: S::$reg) -> S::$reg {
                simd.$select(m, a, b)
            }
            #[inline(always)]
            fn less<S: pulp::Simd>(simd: S, a: S::$reg, b: S::$reg) -> S::$mask {
                simd.$lt(a, b)
            }
            #[inline(always)]
            fn greater<S: pulp::Simd>(simd: S, a: S::$reg, b: S::$reg) -> S::$mask {
                simd.$gt(a, b)
            }
            #[inline(always)]
            fn equal<S: pulp::Simd>(simd: S, a: S::$reg, b: S::$reg) -> S::$mask {
                simd.$eq(a, b)
            }
            #[inline(always)]
            fn and<S: pulp::Simd>(simd: S, a: S::$mask, b: S::$mask) -> S::$mask {
                simd.$and(a, b)
            }
            #[inline(always)]
            fn not<S: pulp::Simd>(simd: S, a: S::$mask) -> S::$mask {
                simd.$not(a)
            }
            #[inline(always)]
            fn first_true<S: pulp::Simd>(simd: S, a: S::$mask) -> usize {
                simd.$first(a)
            }
            #[inline(always)]
            fn escape_bound(e2: f64) -> Self {
                $bound(e2)
            }
            #[inline(always)]
            fn past<S: pulp::Simd>(simd: S, r2: S::$reg, bound: S::$reg) -> S::$mask {
                simd.$past(r2, bound)
            }
            #[inline(always)]
            fn load<S: pulp::Simd>(a: &[Self]) -> S::$reg {
                S::$as(&a[..S::$lanes]).0[0]
            }
            #[inline(always)]
            fn store<S: pulp::Simd>(v: S::$reg, a: &mut [Self]) {
                S::$as_mut(&mut a[..S::$lanes]).0[0] = v;
            }
        }
    };
}

lane!(
    f64,
    Stored,
    F64_LANES,
    splat_f64s,
    add_f64s,
    sub_f64s,
    mul_f64s,
    div_f64s,
    sqrt_f64s,
    abs_f64s,
    select_f64s,
    less_than_f64s,
    greater_than_f64s,
    equal_f64s,
    and_m64s,
    not_m64s,
    first_true_m64s,
    as_simd_f64s,
    as_mut_simd_f64s,
    f64s,
    m64s,
    greater_than_f64s,
    std::convert::identity
);
lane!(
    f32,
    Stored32,
    F32_LANES,
    splat_f32s,
    add_f32s,
    sub_f32s,
    mul_f32s,
    div_f32s,
    sqrt_f32s,
    abs_f32s,
    select_f32s,
    less_than_f32s,
    greater_than_f32s,
    equal_f32s,
    and_m32s,
    not_m32s,
    first_true_m32s,
    as_simd_f32s,
    as_mut_simd_f32s,
    f32s,
    m32s,
    greater_than_or_equal_f32s,
    least_f32_above
);

/// The least f32 whose value is above `e2`: for an f32 |z|², being at
/// least it is being above `e2` in f64. Where no f32 is above `e2` (it is
/// +∞ or NaN), NaN, which nothing is at least.
fn least_f32_above(e2: f64) -> f32 {
    if e2.is_nan() || e2 == f64::INFINITY {
        return f32::NAN;
    }
    let mut x = e2 as f32;
    while (x as f64) <= e2 && x < f32::INFINITY {
        x = x.next_up();
    }
    while ((x.next_down()) as f64) > e2 {
        x = x.next_down();
    }
    x
}

macro_rules! vector_operator {
    ($trait:ident, $method:ident) => {
        impl<S: pulp::Simd, E: Lane> $trait for Vector<S, E> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, o: Self) -> Self {
                Vector(self.0, E::$method(self.0, self.1, o.1))
            }
        }
    };
}
vector_operator!(Add, add);
vector_operator!(Sub, sub);
vector_operator!(Mul, mul);
vector_operator!(Div, div);

impl<S: pulp::Simd, E: Lane> Arith for Vector<S, E> {
    #[inline(always)]
    fn sqrt(self) -> Self {
        Vector(self.0, E::sqrt(self.0, self.1))
    }
}

#[cfg(test)]
mod tests {
    use super::least_f32_above;

    #[test]
    fn an_f32_at_least_the_escape_bound_is_exactly_one_above_it_in_f64() {
        let finite = [16.0, 10.89, 1e300, f32::MAX as f64, 0.0, -1.0, 1e-310];
        let edges = [f64::INFINITY, f64::NEG_INFINITY, f64::NAN];
        for e2 in finite.into_iter().chain(edges) {
            let bound = least_f32_above(e2);
            let near = e2 as f32;
            let mut xs = vec![f32::INFINITY, f32::NEG_INFINITY, f32::NAN, 0.0, f32::MAX];
            for k in 0..4 {
                xs.push(f32::from_bits(near.to_bits().wrapping_add(k)));
                xs.push(f32::from_bits(near.to_bits().wrapping_sub(k)));
            }
            for x in xs {
                assert_eq!(x >= bound, (x as f64) > e2, "{x} against {e2}");
            }
        }
    }
}
