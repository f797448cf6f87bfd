//! Unit tests of the fractal, by concern, and the helpers they share.

use super::estimate::*;
use super::kernel::*;
use super::orbit::*;
use super::power::*;
use super::*;
use crate::math::{shell_points as points, DVec3, Dual, Number, Real};

/// The triplex power as the orbit takes it: complex squaring for whole
/// exponents off the pole axis, the trigonometric form otherwise.
fn triplex_power<T: Number>(formula: Formula, z: Triplex<T>, r: T, n: Real) -> Triplex<T> {
    match whole_power(n) {
        Some(k) => whole_power_step(formula, z, r, k).0,
        None => triplex_power_trig(formula, z, r, n),
    }
}

/// The triplex power on glam vectors.
fn power(f: Formula, z: DVec3, n: Real) -> DVec3 {
    let w = triplex_power(f, [z.x, z.y, z.z], z.length(), n);
    DVec3::new(w[0], w[1], w[2])
}

fn bulb(formula: Formula) -> Fractal {
    Fractal {
        formula,
        ..Fractal::default()
    }
}

/// Every convention, in Mandelbrot and Julia mode, at whole powers (8, with
/// its own loop, and 3) and a fractional one.
fn variants() -> Vec<Fractal> {
    let mut fractals = vec![];
    for formula in Formula::ALL {
        for julia in [None, Some(DVec3::new(0.3, -0.5, 0.2))] {
            for power in [8.0, 3.0, 7.5] {
                fractals.push(Fractal {
                    formula,
                    julia,
                    power,
                    ..Fractal::default()
                });
            }
        }
    }
    fractals
}

mod estimate;
mod kernel;
mod power;
mod stability;
