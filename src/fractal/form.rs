//! The fractal as a timeline writes it: the Julia constant may be numbers
//! or strings of digits (`crate::exact`), and the iterations a count or
//! `Auto` (`Auto(margin: 3)`).

use super::{AutoIterations, DeMethod, Formula, Fractal, Precision};
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
    iterations: Iterations,
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
            iterations: match form.iterations {
                Iterations::Count(n) => n,
                // Until a frame resolves it (`crate::timeline`).
                Iterations::Auto(_) => Fractal::default().iterations,
            },
            auto: match form.iterations {
                Iterations::Count(_) => None,
                Iterations::Auto(auto) => Some(auto),
            },
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
            // The count a frame renders with: its hash is the same whether
            // the timeline wrote the number or `Auto` chose it.
            iterations: Iterations::Count(f.iterations),
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

/// `iterations` as written. RON hands a bare word to `deserialize_any` as
/// a unit and `Word(…)` as a map, without the word: the timeline's parser
/// checks that the word is `Auto` (`crate::timeline`).
enum Iterations {
    Count(u32),
    Auto(AutoIterations),
}

impl Serialize for Iterations {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Iterations::Count(n) => s.serialize_u32(*n),
            Iterations::Auto(a) => s.serialize_newtype_variant("Iterations", 1, "Auto", &a.margin),
        }
    }
}

impl<'de> Deserialize<'de> for Iterations {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(IterationsVisitor)
    }
}

struct IterationsVisitor;

/// What a count outside a u32 is told (the limits' own words).
fn not_a_count<E: serde::de::Error>(written: impl std::fmt::Display) -> E {
    E::custom(format!(
        "must be 1..={}, got {written}",
        crate::fractal::MAX_ITERATIONS
    ))
}

impl<'de> serde::de::Visitor<'de> for IterationsVisitor {
    type Value = Iterations;
    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a whole number of iterations, `Auto` or `Auto(margin: 2)`")
    }
    fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Iterations, E> {
        u32::try_from(v)
            .map(Iterations::Count)
            .map_err(|_| not_a_count(v))
    }
    fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Iterations, E> {
        u64::try_from(v).map_or_else(|_| Err(not_a_count(v)), |v| self.visit_u64(v))
    }
    fn visit_u128<E: serde::de::Error>(self, v: u128) -> Result<Iterations, E> {
        Err(not_a_count(v))
    }
    fn visit_i128<E: serde::de::Error>(self, v: i128) -> Result<Iterations, E> {
        Err(not_a_count(v))
    }
    fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Iterations, E> {
        // RON reads an integer too large for any integer type as a float.
        if v.fract() == 0.0 && v.abs() > u32::MAX as f64 {
            return Err(not_a_count(v));
        }
        Err(E::custom(format!(
            "expected a whole number of iterations or `Auto`, got {v}"
        )))
    }
    fn visit_unit<E: serde::de::Error>(self) -> Result<Iterations, E> {
        Ok(Iterations::Auto(AutoIterations {
            margin: AutoIterations::DEFAULT_MARGIN,
        }))
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Iterations, A::Error> {
        use serde::de::Error;
        let mut margin = None;
        while let Some(name) = map.next_key::<String>()? {
            if name != "margin" || margin.is_some() {
                return Err(A::Error::custom(format!(
                    "`Auto` takes one field, `margin`, got `{name}`"
                )));
            }
            let m: i64 = map.next_value()?;
            let most = AutoIterations::MAX_MARGIN;
            let ok = u32::try_from(m).ok().filter(|&m| m <= most);
            margin =
                Some(ok.ok_or_else(|| {
                    A::Error::custom(format!("margin must be 0..={most}, got {m}"))
                })?);
        }
        Ok(Iterations::Auto(AutoIterations {
            margin: margin.unwrap_or(AutoIterations::DEFAULT_MARGIN),
        }))
    }
}
