//! The arithmetic the fractal's formulas are written in: the four
//! operations and square roots, and the functions the kernel needs.

use super::Real;
use std::ops::{Add, Div, Mul, Neg, Sub};

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
