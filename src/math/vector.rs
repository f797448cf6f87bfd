//! A SIMD register of f64 lanes as one number of the kernel's arithmetic.

use super::Arith;
use std::ops::{Add, Div, Mul, Sub};

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
