//! The fractals: the Mandelbulb's triplex power in each angle convention and
//! the quaternion's, both one row of `Formula::shape` (whole powers by
//! complex squaring, without trigonometry), one iteration driver
//! (bailout, running derivative, orbit traps, Julia mode) generic over f64, f32
//! and dual numbers, its vector twin that iterates 16 orbits in SIMD registers
//! bit-identically (`estimate_lanes`), and five distance
//! estimators built on them.
//!
//! Sources: the spherical power and the scalar running derivative
//! `dr ← n·r^(n−1)·dr (+1 in Mandelbrot mode)` with `DE = ½·ln(r)·r/dr`: the
//! university course notes "Mandelbulb" and Christensen's "Distance
//! Estimated 3D Fractals", parts V–VI, which also give the
//! potential-gradient, sinh and escape-length estimators and their costs;
//! the y-up convention, the power-8 polynomial (a benchmark comparison) and
//! the four orbit traps: Quilez, "Mandelbulb" ("The algorithm",
//! "Optimizing", "Coloring"). The quaternion Julia sets, and that the same
//! estimate and scalar derivative hold for them (Hart; Dang, Kauffman and
//! Sandin, "Hypercomplex Iterations"): Christensen, parts III and V.

use crate::math::{DVec3, Real};
use serde::{Deserialize, Serialize};

/// The formula iterated: the bulb's triplex power in one of its three
/// angle conventions, or the quaternion's power.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Formula {
    /// Quilez's y-up form: θ = acos(y/r), φ = atan2(x, z).
    Quilez,
    /// The White–Nylander z-up form: θ = acos(z/r), φ = atan2(y, x).
    WhiteNylander,
    /// The asin form Mandelbulber2's "Mandelbulb" formula uses: θ = asin(z/r), φ = atan2(y, x).
    Asin,
    /// Quaternions x + y·i + z·j + 0·k: zⁿ multiplies the angle
    /// from the real axis x by n and keeps the imaginary direction.
    Quaternion,
}

impl Formula {
    pub fn name(self) -> &'static str {
        match self {
            Formula::Quilez => "Quilez",
            Formula::WhiteNylander => "WhiteNylander",
            Formula::Asin => "Asin",
            Formula::Quaternion => "Quaternion",
        }
    }

    /// Every formula: what tests and sweeps run over.
    pub const ALL: [Formula; 4] = [
        Formula::Quilez,
        Formula::WhiteNylander,
        Formula::Asin,
        Formula::Quaternion,
    ];

    /// Where the formula's power puts its axes (`power::Shape`).
    #[inline(always)]
    pub(crate) const fn shape(self) -> power::Shape {
        let (pole, equator, from_equator, turns_azimuth) = match self {
            Formula::Quilez => (1, [2, 0], false, true),
            Formula::WhiteNylander => (2, [0, 1], false, true),
            Formula::Asin => (2, [0, 1], true, true),
            Formula::Quaternion => (0, [1, 2], false, false),
        };
        power::Shape {
            pole,
            equator,
            from_equator,
            turns_azimuth,
        }
    }
}

/// How the distance to the surface is estimated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum DeMethod {
    /// ½·ln r·r/dr with the running scalar derivative (one orbit).
    Analytic,
    /// Quilez's potential gradient ½·G/|∇G|, G = ln r/n^k, gradient by finite differences (five orbits).
    Potential,
    /// Christensen's sinh form ½·sinh G/(e^G·|∇G|) (five orbits).
    SinhPotential,
    /// Escape-length gradient ½·r·ln r/|∇r|, every sample at the centre's iteration count (five orbits).
    EscapeLength,
    /// Forward-mode derivatives: ½·r·ln r/‖J‖₂ with J the 3×3 Jacobian of z_k and ‖·‖₂ its
    /// spectral norm (largest stretch), carried through one orbit of dual numbers.
    Jacobian,
}

impl DeMethod {
    pub const ALL: [DeMethod; 5] = [
        DeMethod::Analytic,
        DeMethod::Potential,
        DeMethod::SinhPotential,
        DeMethod::EscapeLength,
        DeMethod::Jacobian,
    ];

    pub fn name(self) -> &'static str {
        match self {
            DeMethod::Analytic => "Analytic",
            DeMethod::Potential => "Potential",
            DeMethod::SinhPotential => "SinhPotential",
            DeMethod::EscapeLength => "EscapeLength",
            DeMethod::Jacobian => "Jacobian",
        }
    }
}

/// Floating-point precision of the distance-estimator kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Precision {
    F64,
    /// Single precision, as GPU renderers use; marching itself stays f64.
    F32,
}

impl Precision {
    pub fn name(self) -> &'static str {
        match self {
            Precision::F64 => "f64",
            Precision::F32 => "f32",
        }
    }
}

/// Parameters of the fractal for one frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(from = "form::FractalForm", into = "form::FractalForm")]
pub struct Fractal {
    pub formula: Formula,
    /// The exponent n of the triplex power (any real; 8 is the classic bulb).
    pub power: Real,
    /// Maximum orbit length: the timeline's count, or the one `auto`
    /// resolved for this frame.
    pub iterations: u32,
    /// `iterations: Auto`: the count is chosen per frame where the scene is
    /// made (`crate::timeline`), and `iterations` holds it after.
    pub auto: Option<AutoIterations>,
    /// Escape radius; must exceed 1 so ln(r) is positive at escape.
    pub bailout: Real,
    /// `None` for the Mandelbrot mode (z₀ = c = p), `Some(k)` for the Julia set of constant k.
    pub julia: Option<DVec3>,
    /// The Julia constant's digits where the timeline wrote them as strings:
    /// a deep frame's reference orbits take the constant from them.
    pub julia_digits: Option<crate::exact::Digits>,
    /// Distance estimator.
    pub de: DeMethod,
    /// Precision of the estimator's arithmetic.
    pub precision: Precision,
    /// A deep frame's reference (`deep`): points are then offsets from its
    /// anchor. Set for rendering a deep frame (`crate::deep`), never read
    /// from a timeline.
    pub deep: Option<std::sync::Arc<deep::Reference>>,
    /// Whether a deep frame is rendered by perturbation: false only for the
    /// accuracy report's row that shows what f64 alone gets there.
    pub perturbation: bool,
}

impl Default for Fractal {
    fn default() -> Self {
        Fractal {
            formula: Formula::Quilez,
            power: 8.0,
            iterations: 12,
            auto: None,
            bailout: 4.0,
            julia: None,
            de: DeMethod::Analytic,
            precision: Precision::F64,
            julia_digits: None,
            deep: None,
            perturbation: true,
        }
    }
}

/// The most orbit iterations a timeline may ask for, or `Auto` choose:
/// past this a frame takes days.
pub const MAX_ITERATIONS: u32 = 10_000;

/// Bumped whenever a change alters the estimates f32 gives, so resume
/// re-renders the frames that render in f32 and no others.
pub const F32_REVISION: u32 = 1;

/// `iterations: Auto(margin: m)`: per frame, the iterations after which
/// the running derivative at the frame's surface passes one over a pixel's
/// width (finer detail would alias), and `margin` more.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AutoIterations {
    pub margin: u32,
}

impl AutoIterations {
    /// The margin `Auto` alone takes: the target's derivative grows
    /// fastest, and the surface elsewhere in the frame needs a few more
    /// (docs/iterations.md measures it).
    pub const DEFAULT_MARGIN: u32 = 6;
    /// The largest margin: each iteration multiplies the derivative about
    /// eightfold at power 8, so past this the margin alone is 1e90 pixels.
    pub const MAX_MARGIN: u32 = 100;
}

/// Minimum distances of the orbit to the four traps of Quilez's colouring.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitTraps {
    /// Smallest |z|² over the orbit (the point trap at the origin).
    pub origin: Real,
    /// Smallest |z.x|, |z.y|, |z.z| (the planes x=0, y=0, z=0).
    pub planes: DVec3,
}

impl OrbitTraps {
    /// The traps of an orbit that ended at `z` (|z|² = `r2`, as its own
    /// arithmetic rounds it): those it met, or `z`'s own for a point
    /// outside the bailout from the start, which met none.
    #[inline(always)]
    fn ended(self, z: [Real; 3], r2: Real) -> OrbitTraps {
        if self.origin == Real::INFINITY {
            OrbitTraps {
                origin: r2,
                planes: DVec3::from_array(z).abs(),
            }
        } else {
            self
        }
    }
}

/// What one evaluation of the distance estimator returns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// Lower bound on the distance to the surface; 0 for points that never escape.
    pub distance: Real,
    pub traps: OrbitTraps,
    /// Iterations done before escape (equal to the limit when the orbit stayed bounded).
    pub iterations: u32,
    pub escaped: bool,
    /// Orbits computed for this estimate (the cost: 1 for analytic, 5 for gradient methods).
    pub orbits: u32,
    /// Where the estimate's orbit (of its point, stopping at the bailout)
    /// ended, in the estimator's precision: shading reads a hit's escape
    /// radius and final angle here instead of iterating the orbit again
    /// (`Fractal::ends_f64_orbits` says when it is the f64 orbit's).
    pub end: Triplex<Real>,
}

impl Estimate {
    /// A placeholder: where the kernel skips a register of padding, its
    /// lanes keep this (zero iterations, zero orbits).
    pub const IDLE: Estimate = Estimate {
        distance: 0.0,
        traps: OrbitTraps {
            origin: 0.0,
            planes: DVec3::ZERO,
        },
        iterations: 0,
        escaped: false,
        orbits: 0,
        end: [0.0; 3],
    };

    /// |z| where the orbit ended, as every orbit loop takes it (the root
    /// of `length_squared`), so it is their `Orbit::r` to the bit.
    pub fn end_radius(&self) -> Real {
        power::length_squared(self.end).sqrt()
    }
}

/// A point of the kernel's number type.
pub type Triplex<T> = [T; 3];

pub(crate) mod deep;
mod estimate;
mod form;
mod kernel;
mod orbit;
mod power;

pub use estimate::{spectral_norm, TETRAHEDRON};
pub use kernel::{IDLE_POINT, VECTOR};
pub use orbit::{iterations_on_this_thread, Orbit};
pub use power::{power8_polynomial, powi, triplex_power_int, triplex_power_trig, whole_power};

#[cfg(test)]
mod tests;
