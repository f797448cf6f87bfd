//! The fractal as a timeline writes it: the Julia constant may be numbers
//! or strings of digits (`crate::exact`).

use super::{DeMethod, Formula, Fractal, Precision};
use crate::exact::Coordinates;
use crate::math::Real;
use serde::{Deserialize, Serialize};

/// `Fractal`'s serde form, field for field in the same order, so a scene's
/// JSON (and its hash) is what it was where no digits are written.
#[derive(Serialize, Deserialize)]
#[serde(rename = "Fractal", deny_unknown_fields, default)]
pub(super) struct FractalForm {
    formula: Formula,
    power: Real,
    iterations: u32,
    bailout: Real,
    julia: Option<Coordinates>,
    de: DeMethod,
    precision: Precision,
}

impl Default for FractalForm {
    fn default() -> Self {
        Fractal::default().into()
    }
}

impl From<FractalForm> for Fractal {
    fn from(form: FractalForm) -> Fractal {
        let (julia, julia_digits) = match form.julia {
            Some(k) => (Some(k.value), k.digits),
            None => (None, None),
        };
        Fractal {
            formula: form.formula,
            power: form.power,
            iterations: form.iterations,
            bailout: form.bailout,
            julia,
            julia_digits,
            de: form.de,
            precision: form.precision,
            deep: None,
            perturbation: true,
        }
    }
}

impl From<Fractal> for FractalForm {
    fn from(f: Fractal) -> FractalForm {
        FractalForm {
            formula: f.formula,
            power: f.power,
            iterations: f.iterations,
            bailout: f.bailout,
            julia: f.julia.map(|value| Coordinates {
                value,
                digits: f.julia_digits.clone(),
            }),
            de: f.de,
            precision: f.precision,
        }
    }
}
