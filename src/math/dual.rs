//! Dual numbers: values with their gradient, for the Jacobian estimator.

use super::{Arith, Number, Real};
use std::ops::{Add, Div, Mul, Neg, Sub};

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

#[cfg(test)]
mod tests {
    use super::*;

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
}
