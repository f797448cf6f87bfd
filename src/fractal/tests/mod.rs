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

mod estimate;
mod kernel;
mod power;
mod stability;
