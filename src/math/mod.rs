//! Numeric foundations shared by every other module: the `Real` type used for
//! geometry (f64), the vector and colour types, the kernel's arithmetic, and
//! a few small guards that keep NaN and infinity from leaking out of the hot
//! path.

pub use glam::{DVec3, Vec3};

mod colour;
mod dual;
mod geometry;
mod ln;
mod number;
mod sample;
mod stats;
mod vector;

pub use colour::{finite_or_zero, mix};
pub use dual::Dual;
pub use geometry::{direction, length, normalize_or, sphere_interval};
pub use ln::{in_ln_range, ln, ln_in_range, Lanes};
pub use number::{Arith, Number};
pub use sample::{sample_1d, shell_points};
pub use stats::{median, psnr_db, psnr_db_of_rmse};
pub use vector::{Lane, Stored, Stored32, Vector};

/// The floating-point type of all geometry and distance estimation.
pub type Real = f64;
