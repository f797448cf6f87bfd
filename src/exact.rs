//! Coordinates with more digits than f64 keeps. A timeline may write any
//! component of a camera position or target as a string of decimal digits
//! ("0.50304436772512345678901234567890"): the scene keeps the nearest f64
//! for everything f64 does well, and the digits for deep frames, whose
//! reference orbit starts from them exactly (`fractal::deep`).

use crate::math::DVec3;
use dashu_float::round::mode::HalfEven;
use dashu_float::{DBig, FBig};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::str::FromStr;
use std::sync::{Arc, Mutex};

/// A binary float of any precision: what reference orbits are computed in.
pub type Big = FBig;

/// The decimal digits of a point's three components, as the timeline wrote
/// them (numbers written as numbers are kept as their f64's shortest form).
pub type Digits = Arc<[String; 3]>;

/// The most significant digits a coordinate may have: 1e-300 deep needs
/// about 320; more would only slow every reference orbit down.
pub const MAX_DIGITS: usize = 400;

/// The largest decimal exponent a coordinate may be written with.
const MAX_EXPONENT: i32 = 400;

/// A triple as a timeline writes it: numbers, or strings of digits.
#[derive(Clone, Debug, PartialEq)]
pub struct Coordinates {
    /// The nearest f64 of each component.
    pub value: DVec3,
    /// The digits, where any component was written as a string.
    pub digits: Option<Digits>,
}

impl From<DVec3> for Coordinates {
    fn from(value: DVec3) -> Self {
        Coordinates {
            value,
            digits: None,
        }
    }
}

/// Checks a string of digits ("-0.5", "1.25e-3"): what is wrong with it,
/// or its nearest f64. Only plain decimal notation, at most `MAX_DIGITS`
/// digits and an exponent within ±`MAX_EXPONENT`, so that no string makes
/// a reference orbit slow or huge.
pub fn parse_digits(text: &str) -> Result<f64, String> {
    let unsigned = text.strip_prefix(['-', '+']).unwrap_or(text);
    let (mantissa, exponent) = match unsigned.split_once(['e', 'E']) {
        Some((m, e)) => (m, Some(e)),
        None => (unsigned, None),
    };
    let (whole, fraction) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    let digits = whole.len() + fraction.len();
    let all_digits = |s: &str| s.bytes().all(|b| b.is_ascii_digit());
    let bad = || {
        format!(
            "{text:?} is not a decimal number (write digits such as \"0.503044367725123456789\")"
        )
    };
    if digits == 0 || !all_digits(whole) || !all_digits(fraction) {
        return Err(bad());
    }
    if let Some(e) = exponent {
        let e = e.strip_prefix(['-', '+']).unwrap_or(e);
        if e.is_empty() || !all_digits(e) {
            return Err(bad());
        }
        if e.len() > 3 || e.parse::<i32>().map_or(true, |e| e > MAX_EXPONENT) {
            return Err(format!("{text:?} has an exponent past ±{MAX_EXPONENT}"));
        }
    }
    if digits > MAX_DIGITS {
        return Err(format!(
            "a coordinate may have at most {MAX_DIGITS} digits, got {digits}"
        ));
    }
    text.parse::<f64>().map_err(|_| bad())
}

/// `digits` (already checked by `parse_digits`) as a binary float of `bits`:
/// converted once per string and precision (`CONVERTED`).
pub fn big_from_digits(digits: &str, bits: usize) -> Big {
    let kept = lock(&CONVERTED)
        .get(digits)
        .and_then(|by_bits| by_bits.get(&bits).cloned());
    if let Some(big) = kept {
        return big;
    }
    let big = convert(digits, bits);
    let mut converted = lock(&CONVERTED);
    if converted.values().map(BTreeMap::len).sum::<usize>() >= MOST_CONVERTED {
        converted.clear();
    }
    let by_bits = converted.entry(digits.to_string()).or_default();
    by_bits.insert(bits, big.clone());
    big
}

/// Digit strings already converted, by string and precision. Every scene
/// of a film holds its target's digits, and a decimal-to-binary conversion
/// (at up to `DIFFERENCE_BITS`) costs hundreds of times the arithmetic
/// done with its result: converted once, they cost nothing per frame.
static CONVERTED: Mutex<BTreeMap<String, BTreeMap<usize, Big>>> = Mutex::new(BTreeMap::new());

/// The most conversions kept (a few hundred bytes each): a film's digits
/// take one per precision its deep frames ask for, a few hundred at most;
/// past this (an explorer session trying many targets) they start over.
const MOST_CONVERTED: usize = 4096;

/// The memo's contents, whole even where a thread panicked holding it
/// (each entry is inserted whole).
fn lock<T>(memo: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    memo.lock().unwrap_or_else(|e| e.into_inner())
}

/// `digits` as a binary float of `bits`, converted from decimal.
fn convert(digits: &str, bits: usize) -> Big {
    #[cfg(test)]
    tally::count(digits);
    let decimal = DBig::from_str(digits.strip_prefix('+').unwrap_or(digits))
        .unwrap_or_else(|_| unreachable!("checked by parse_digits"));
    decimal
        .with_base_and_precision::<2>(bits)
        .value()
        .with_rounding()
}

/// `v` exactly, as a binary float of `bits` (at least f64's 53).
pub fn big_from_f64(v: f64, bits: usize) -> Big {
    Big::try_from(v)
        .unwrap_or_else(|_| unreachable!("validation keeps coordinates finite"))
        .with_precision(bits)
        .value()
}

/// The point's components as binary floats of `bits`: from the digits where
/// the timeline gave them, else the f64 values exactly.
pub fn big_point(value: DVec3, digits: Option<&Digits>, bits: usize) -> [Big; 3] {
    match digits {
        Some(d) => [0, 1, 2].map(|i| big_from_digits(&d[i], bits)),
        None => value.to_array().map(|v| big_from_f64(v, bits)),
    }
}

/// The precision `difference` works in: enough for every digit a
/// coordinate may have, and f64's own.
const DIFFERENCE_BITS: usize = 64 + MAX_DIGITS * 4;

/// `a − b` for points held as f64 values with their digits where given,
/// computed in enough bits that a difference far below f64's resolution
/// of either point survives.
pub fn difference(a: (DVec3, Option<&Digits>), b: (DVec3, Option<&Digits>)) -> DVec3 {
    if a.1.is_none() && b.1.is_none() {
        return a.0 - b.0;
    }
    #[cfg(test)]
    [a.1, b.1].into_iter().flatten().for_each(tally::differ);
    let bits = DIFFERENCE_BITS;
    let (p, q) = (big_point(a.0, a.1, bits), big_point(b.0, b.1, bits));
    // To the nearest f64: `Big` rounds towards zero.
    let nearest = |d: Big| d.with_rounding::<HalfEven>().to_f64().value();
    DVec3::from_array([0, 1, 2].map(|i| nearest(&p[i] - &q[i])))
}

/// `b` as decimal digits: `significant` of them, in plain or scientific
/// notation as dashu writes it.
pub fn decimal(b: &Big, significant: usize) -> String {
    let d: DBig = b
        .clone()
        .with_base_and_precision::<10>(significant)
        .value()
        .with_rounding();
    d.to_string()
}

/// `v` exactly, in decimal digits `parse_digits` accepts: below about
/// 1e-148, where an f64's expansion is longer, to `MAX_DIGITS` of them.
pub fn f64_digits(v: f64) -> String {
    // 770 significant digits hold any f64's binary expansion exactly.
    let exact: DBig = big_from_f64(v, 64)
        .with_base_and_precision::<10>(770)
        .value()
        .with_rounding();
    fitted(exact)
}

/// `anchor` (digits `parse_digits` accepts) moved by `delta`, exactly, as
/// digits `parse_digits` accepts: what a track keyed with digits gives
/// between its keys (`timeline::deep_keys`). Rounded to `MAX_DIGITS`
/// significant digits where the exact sum has more.
pub fn moved(anchor: &str, delta: f64) -> String {
    let start = DBig::from_str(anchor.strip_prefix('+').unwrap_or(anchor))
        .unwrap_or_else(|_| unreachable!("checked by parse_digits"));
    // Shortest decimal that reads back as `delta`: the step as f64 means it.
    let step = DBig::from_str(&format!("{delta:e}"))
        .unwrap_or_else(|_| unreachable!("a finite f64 prints as digits"));
    fitted(start.with_precision(MAX_DIGITS).value() + step)
}

/// `sum` as digits `parse_digits` accepts, to `MAX_DIGITS` significant
/// digits or fewer.
fn fitted(sum: DBig) -> String {
    // Fewer digits only where neither notation holds the sum within the
    // limits (digits far below anything f64 offsets reach).
    let mut precision = MAX_DIGITS;
    loop {
        let rounded = sum.clone().with_precision(precision).value();
        let plain = rounded.to_string();
        if parse_digits(&plain).is_ok() {
            return plain;
        }
        // One digit before the point keeps the exponent small.
        let (significand, exponent) = rounded.repr().clone().into_parts();
        let written = significand.to_string();
        let (sign, digits) = match written.strip_prefix('-') {
            Some(digits) => ("-", digits),
            None => ("", &*written),
        };
        let (first, rest) = digits.split_at(1);
        let exponent = exponent as i64 + rest.len() as i64;
        let scientific = format!("{sign}{first}.{rest}e{exponent}");
        if parse_digits(&scientific).is_ok() {
            return scientific;
        }
        if precision <= 17 {
            // Below 1e-380, past anything f64 or a coordinate's exponent
            // holds: the anchor and the step cancel.
            return "0".into();
        }
        precision /= 2;
    }
}

/// One component as written: a number or a string of digits.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Component {
    Number(f64),
    Digits(String, f64),
}

impl Component {
    /// Its value in f64 (a string of digits' nearest).
    pub(crate) fn value(&self) -> f64 {
        match self {
            Component::Number(v) | Component::Digits(_, v) => *v,
        }
    }
}

impl<'de> Deserialize<'de> for Component {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visit;
        impl serde::de::Visitor<'_> for Visit {
            type Value = Component;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number, or a string of decimal digits")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Component, E> {
                Ok(Component::Number(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Component, E> {
                Ok(Component::Number(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Component, E> {
                Ok(Component::Number(v as f64))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Component, E> {
                let value = parse_digits(v).map_err(E::custom)?;
                Ok(Component::Digits(v.to_string(), value))
            }
        }
        d.deserialize_any(Visit)
    }
}

impl<'de> Deserialize<'de> for Coordinates {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visit;
        impl<'de> serde::de::Visitor<'de> for Visit {
            type Value = Coordinates;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a triple (x, y, z) of numbers or strings of digits")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<Coordinates, A::Error> {
                let mut parts = Vec::with_capacity(3);
                while let Some(c) = seq.next_element::<Component>()? {
                    if parts.len() == 3 {
                        return Err(serde::de::Error::invalid_length(4, &self));
                    }
                    parts.push(c);
                }
                let [x, y, z]: [Component; 3] = parts
                    .try_into()
                    .map_err(|p: Vec<_>| serde::de::Error::invalid_length(p.len(), &self))?;
                Ok(Coordinates::from_components([x, y, z]))
            }
        }
        d.deserialize_tuple(3, Visit)
    }
}

impl Coordinates {
    /// These coordinates with digits: their own, else each number's
    /// shortest decimal form (as `from_components` writes a number).
    pub fn with_digits(self) -> Coordinates {
        let digits = self
            .digits
            .unwrap_or_else(|| Arc::new(self.value.to_array().map(|v| format!("{v:?}"))));
        Coordinates {
            value: self.value,
            digits: Some(digits),
        }
    }

    /// The components as written: the digits kept where any is a string.
    pub(crate) fn from_components(parts: [Component; 3]) -> Coordinates {
        let value = |c: &Component| match c {
            Component::Number(v) | Component::Digits(_, v) => *v,
        };
        let any_digits = parts.iter().any(|c| matches!(c, Component::Digits(..)));
        let digits = any_digits.then(|| {
            Arc::new(parts.each_ref().map(|c| match c {
                Component::Digits(d, _) => d.clone(),
                // A number as written (its shortest decimal form): 0.1
                // means a tenth, as the strings beside it mean what they say.
                Component::Number(v) => format!("{v:?}"),
            }))
        });
        Coordinates {
            value: DVec3::new(value(&parts[0]), value(&parts[1]), value(&parts[2])),
            digits,
        }
    }
}

impl Serialize for Coordinates {
    /// As numbers where no digits were given (the form every scene's hash
    /// has always been taken over), else as the strings.
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match &self.digits {
            Some(d) => d.serialize(s),
            None => self.value.serialize(s),
        }
    }
}

/// How often tests' digit strings were converted and subtracted: each
/// test's strings are its own, so tests running at once do not mix.
#[cfg(test)]
pub(crate) mod tally {
    use super::{lock, BTreeMap, Digits, Mutex};

    static CONVERSIONS: Mutex<BTreeMap<String, usize>> = Mutex::new(BTreeMap::new());
    static DIFFERENCES: Mutex<BTreeMap<String, usize>> = Mutex::new(BTreeMap::new());

    pub(super) fn count(digits: &str) {
        *lock(&CONVERSIONS).entry(digits.to_string()).or_default() += 1;
    }

    pub(super) fn differ(digits: &Digits) {
        let mut differences = lock(&DIFFERENCES);
        for d in digits.iter() {
            *differences.entry(d.clone()).or_default() += 1;
        }
    }

    /// Conversions of `digits` from decimal so far.
    pub fn conversions(digits: &str) -> usize {
        lock(&CONVERSIONS).get(digits).copied().unwrap_or(0)
    }

    /// High-precision differences of points written with `digits`.
    pub fn differences(digits: &str) -> usize {
        lock(&DIFFERENCES).get(digits).copied().unwrap_or(0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn digits_are_checked_and_rounded_to_the_nearest_f64() {
        assert_eq!(parse_digits("0.1"), Ok(0.1));
        assert_eq!(parse_digits("-2.5e-3"), Ok(-2.5e-3));
        assert_eq!(parse_digits("+1."), Ok(1.0));
        for bad in [
            "", "-", ".", "1e", "0x10", "1.2.3", "nan", "inf", " 1", "1e+",
        ] {
            assert!(parse_digits(bad).is_err(), "{bad:?} accepted");
        }
        assert!(parse_digits("1e999").unwrap_err().contains("exponent"));
        let long = format!("0.{}", "1".repeat(MAX_DIGITS));
        assert!(parse_digits(&long).unwrap_err().contains("at most"));
    }

    #[test]
    fn a_moved_point_keeps_every_digit_of_the_anchor_and_the_step() {
        assert_eq!(
            moved("0.5", 1.2345e-31),
            "0.50000000000000000000000000000012345"
        );
        let anchor = "0.50304436772512345678901234567891";
        let back = moved(&moved(anchor, -3.25e-40), 3.25e-40);
        assert_eq!(back, anchor);
        assert_eq!(moved("-1.25e-3", 0.0), "-0.00125");
        for (anchor, step) in [("0", 1e-300), (&*format!("0.{}", "7".repeat(399)), 1e-290)] {
            let text = moved(anchor, step);
            let value = parse_digits(&text).unwrap();
            let exact = big_from_digits(&text, 2000) - big_from_digits(anchor, 2000);
            let error = (exact.to_f64().value() - step).abs();
            assert!(
                error <= 4e-16 * step,
                "{anchor} + {step:e} = {text} ({value})"
            );
        }
    }

    #[test]
    fn an_f64_is_written_out_exactly() {
        let tenth = "0.1000000000000000055511151231257827021181583404541015625";
        assert_eq!(f64_digits(0.1), tenth);
        assert_eq!(f64_digits(-2.0), "-2");
        assert_eq!(f64_digits(0.0), "0");
        for v in [1.1040895136738123, -3.7e-7, 1e-130, 1e-150, 1e-300, 5e-324] {
            let text = f64_digits(v);
            assert_eq!(parse_digits(&text), Ok(v), "{text}");
            let error = big_from_digits(&text, 4000) - big_from_f64(v, 4000);
            let exact = error == big_from_f64(0.0, 4000);
            assert!(exact || v.abs() < 1e-148, "{v:e}: {text}");
        }
    }

    #[test]
    fn digits_keep_what_f64_rounds_away() {
        let a = big_from_digits("0.50000000000000000000000000000001", 256);
        let b = big_from_f64(0.5, 256);
        let difference = (&a - &b).to_f64().value();
        assert!((difference - 1e-32).abs() < 1e-45, "{difference}");
        assert_eq!(decimal(&a, 33), "0.50000000000000000000000000000001");
    }

    #[test]
    fn coordinates_read_numbers_and_strings() {
        let c: Coordinates = ron::from_str("(0.5, \"0.25000000000000000000001\", 3)").unwrap();
        assert_eq!(c.value, DVec3::new(0.5, 0.25, 3.0));
        let d = c.digits.expect("a string was given");
        assert_eq!(d[1], "0.25000000000000000000001");
        assert_eq!(big_from_digits(&d[0], 64).to_f64().value(), 0.5);
        let plain: Coordinates = ron::from_str("(1, 2, 3)").unwrap();
        assert!(plain.digits.is_none());
        assert_eq!(
            serde_json::to_string(&plain).unwrap(),
            serde_json::to_string(&DVec3::new(1.0, 2.0, 3.0)).unwrap()
        );
        assert!(ron::from_str::<Coordinates>("(1, 2)").is_err());
        assert!(ron::from_str::<Coordinates>("(1, 2, 3, 4)").is_err());
        assert!(ron::from_str::<Coordinates>("(1, \"x\", 3)").is_err());
    }
}
