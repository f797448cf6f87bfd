//! The checks a field's value passes or fails, each with one wording:
//! what `parameters` gives each animatable field and `validate` applies.

use super::limits::count_outside;
use super::messages::Shown;
use crate::math::Vec3;

/// A value within its range, or what is wrong with it.
pub type Checked = std::result::Result<(), String>;

/// `ok`, else `message`'s problem. The message is built only when the
/// check fails: every rendered scene is checked, thousands per frame under
/// motion blur.
pub(super) fn rule(ok: bool, message: impl FnOnce() -> String) -> Checked {
    if ok {
        Ok(())
    } else {
        Err(message())
    }
}

// The three checks most fields need, each with one wording.

pub(super) fn positive<T: Into<f64> + Copy + Shown>(v: T) -> Checked {
    let x: f64 = v.into();
    rule(x.is_finite() && x > 0.0, || {
        format!("must be positive, got {}", v.shown())
    })
}

pub(super) fn non_negative<T: Into<f64> + Copy + Shown>(v: T) -> Checked {
    let x: f64 = v.into();
    rule(x.is_finite() && x >= 0.0, || {
        format!("must be non-negative, got {}", v.shown())
    })
}

pub(super) fn colour(c: Vec3) -> Checked {
    rule(c.is_finite() && c.min_element() >= 0.0, || {
        format!("colours must be finite and non-negative, got {}", c.shown())
    })
}

/// A count from 1 to `most`.
pub(super) fn counted(n: u32, most: u32) -> Checked {
    rule((1..=most).contains(&n), || count_outside(most, n))
}
