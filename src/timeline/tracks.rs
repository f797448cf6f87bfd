//! A track: one parameter's keys, validated and laid out as one spline per
//! component on the `splines` crate, sampled at any time. In a looping film
//! the keys repeat every period.

use super::deep_keys::DeepKeys;
use super::messages::Shown;
use super::parameters::{Exact, Parameter, ZOOM_TRACK};
use super::schema::{Interpolation, KeySpec, KeyValue, TrackSpec};
use super::spline::build_spline;
use crate::exact::Coordinates;
use crate::math::DVec3;
use crate::math::Real;
use crate::scene::Scene;
use splines::Spline;

/// One validated, ready-to-sample track.
#[derive(Clone, Debug)]
pub struct Track {
    pub name: String,
    pub interpolation: Interpolation,
    pub key_times: Vec<Real>,
    /// One spline per component, over padded keys (see `build_spline`).
    splines: Vec<Spline<Real, Real>>,
    /// First and last key values per component, for sampling outside the keys.
    ends: (Vec<Real>, Vec<Real>),
    /// Values are stored as logarithms and exponentiated when sampled.
    log_space: bool,
    /// In a looping film, its period: the track repeats with it, and its
    /// splines hold the keys of three periods (`build_spline`).
    period: Option<Real>,
    /// Writes a sampled value into a scene (`Parameter::set`).
    set: fn(&mut Scene, &[Real]),
    /// Where a key is written as digits: the keys as digits, sampled in
    /// high precision, and what writes such a value (`Parameter::digits`).
    deep: Option<(DeepKeys, Exact)>,
}

impl Track {
    /// The parameter's value at `time_seconds`; held constant outside the
    /// keys, or in a looping film the same every period.
    pub fn sample(&self, time_seconds: Real) -> Vec<Real> {
        self.sample_components(time_seconds)[..self.splines.len()].to_vec()
    }

    /// `sample` without allocating (every scene of every frame is checked):
    /// the value's components first, at most three.
    pub(super) fn sample_components(&self, time_seconds: Real) -> [Real; 3] {
        if let Some((deep, _)) = &self.deep {
            return deep.sample(time_seconds).value.to_array();
        }
        let first = self.key_times[0];
        let last = self.key_times[self.key_times.len() - 1];
        let mut raw = [0.0; 3];
        let values = raw.iter_mut().zip(&self.splines).zip(&self.ends.0);
        if let Some(period) = self.period {
            // Into [0, period): a tiny negative time's remainder can round
            // up to the period itself.
            let t = time_seconds.rem_euclid(period);
            let t = if t < period { t } else { 0.0 };
            for ((v, s), &fallback) in values {
                *v = s.sample(t).unwrap_or(fallback);
            }
        } else if time_seconds <= first {
            raw[..self.ends.0.len()].copy_from_slice(&self.ends.0);
        } else if time_seconds >= last {
            raw[..self.ends.1.len()].copy_from_slice(&self.ends.1);
        } else {
            for ((v, s), &fallback) in values {
                *v = s.sample(time_seconds).unwrap_or(fallback);
            }
        }
        if self.log_space {
            raw = raw.map(Real::exp);
        }
        raw
    }
}

/// A key's or track's problem: where below the track (`.keys[3].time`, or
/// nothing for the track itself) and the message.
pub(super) type TrackError = (String, String);

impl Track {
    /// The track of `parameter` from its `spec`, with at least one key; in
    /// a looping film of `period` seconds at `fps`, over one period.
    pub(super) fn build(
        parameter: &Parameter,
        spec: &TrackSpec,
        period: Option<Real>,
        fps: Real,
    ) -> std::result::Result<Track, TrackError> {
        let log_space = parameter.name == ZOOM_TRACK;
        let (times, mut columns) = key_columns(parameter, &spec.keys, log_space)?;
        let digits = spec
            .keys
            .iter()
            .any(|k| matches!(k.value, KeyValue::Digits(_)));
        let interpolation = spec.interpolation.unwrap_or(Interpolation::CatmullRom);
        let ends = (
            columns.iter().map(|c| c[0]).collect(),
            columns.iter().map(|c| c[c.len() - 1]).collect(),
        );
        // Which key each laid-out key is: a loop moves and drops keys.
        columns.push((0..times.len()).map(|k| k as Real).collect());
        // The keys the splines go through: in a looping film, those of
        // one period, in [0, period).
        let (loop_times, loop_columns) = match period {
            Some(period) => one_period(&times, columns, &spec.keys, period, fps)
                .map_err(|(k, what, message)| (format!(".keys[{k}].{what}"), message))?,
            None => (times.clone(), columns),
        };
        let mut loop_columns = loop_columns;
        let laid_out = loop_columns.pop().unwrap_or_default();
        let deep = match parameter.digits {
            Some(exact) if digits => {
                let points = laid_out
                    .iter()
                    .map(|&k| key_point(&spec.keys[k as usize].value))
                    .collect();
                Some((
                    DeepKeys::new(loop_times.clone(), points, interpolation, period),
                    exact,
                ))
            }
            _ => None,
        };
        let splines = loop_columns
            .iter()
            .map(|c| build_spline(&loop_times, c, interpolation, period))
            .collect();
        Ok(Track {
            name: parameter.name.to_string(),
            interpolation,
            splines,
            key_times: times,
            ends,
            log_space,
            period,
            set: parameter.set,
            deep,
        })
    }

    /// How many numbers a value holds.
    pub(super) fn components(&self) -> usize {
        self.splines.len()
    }

    /// Writes the value at `time_seconds` into `scene`.
    pub(super) fn apply(&self, scene: &mut Scene, time_seconds: Real) {
        if let Some((deep, exact)) = &self.deep {
            return (exact.set)(scene, deep.sample(time_seconds));
        }
        let values = self.sample_components(time_seconds);
        (self.set)(scene, &values[..self.components()]);
    }
}

/// The keys' times, and their values a column per component (logarithms
/// in `log_space`): finite, increasing times and finite values of the
/// parameter's shape.
fn key_columns(
    parameter: &Parameter,
    keys: &[KeySpec],
    log_space: bool,
) -> std::result::Result<(Vec<Real>, Vec<Vec<Real>>), TrackError> {
    let arity = parameter.shape.components();
    let mut times = Vec::with_capacity(keys.len());
    let mut columns = vec![Vec::with_capacity(keys.len()); arity];
    for (k, key) in keys.iter().enumerate() {
        let time = || format!(".keys[{k}].time");
        let value = || format!(".keys[{k}].value");
        if !key.time.is_finite() {
            let shown = key.time.shown();
            let message = format!("must be a finite number of seconds, got {shown}");
            return Err((time(), message));
        }
        if let Some(&prev) = times.last() {
            if key.time <= prev {
                let message = format!("key times must increase: {} follows {prev}", key.time);
                return Err((time(), message));
            }
        }
        times.push(key.time);
        let values = key.value.components();
        let shape = |n: usize| {
            if n == 1 {
                "a number"
            } else {
                "a triple (x, y, z)"
            }
        };
        if values.len() != arity {
            let (name, shape, given) = (parameter.name, shape(arity), shape(values.len()));
            return Err((value(), format!("{name} takes {shape}, got {given}")));
        }
        if let (KeyValue::Digits(_), None) = (&key.value, parameter.digits) {
            let takes: Vec<&str> = super::parameters::all()
                .filter(|p| p.digits.is_some())
                .map(|p| p.name)
                .collect();
            let message = format!(
                "{} takes numbers: strings of digits are for {}",
                parameter.name,
                takes.join(", ")
            );
            return Err((value(), message));
        }
        if let Some(bad) = values.iter().find(|v| !v.is_finite()) {
            let message = format!("values must be finite, got {}", bad.shown());
            return Err((value(), message));
        }
        if log_space && values[0] <= 0.0 {
            let shown = values[0].shown();
            let message = format!("a camera distance must be positive, got {shown}");
            return Err((value(), message));
        }
        for (column, v) in columns.iter_mut().zip(values) {
            column.push(if log_space { v.ln() } else { v });
        }
    }
    Ok((times, columns))
}

/// A key's value as a point with digits (`DeepKeys`).
fn key_point(value: &KeyValue) -> Coordinates {
    let point = match value {
        KeyValue::Digits(c) => c.clone(),
        other => {
            let v = other.components();
            Coordinates::from(DVec3::new(v[0], v[1], v[2]))
        }
    };
    point.with_digits()
}

/// A key's problem: its index, the field (`time` or `value`), the message.
type KeyError = (usize, &'static str, String);

/// The keys of a looping film's track (`times`, one column of values per
/// component, written as `keys`) laid out over one period, [0, `period`).
/// A key at the period's end is the start's again: within half a frame of
/// it, since `duration_seconds` is rounded to whole frames (4 s at 29.97 fps
/// is 120 frames, a period of 4.004 s), and no frame lies between. It must
/// equal a key at the start (within half a frame of 0), which then stands
/// for both; without one it moves to 0 s. A key outside the period is an
/// error.
fn one_period(
    times: &[Real],
    mut columns: Vec<Vec<Real>>,
    keys: &[KeySpec],
    period: Real,
    fps: Real,
) -> std::result::Result<(Vec<Real>, Vec<Vec<Real>>), KeyError> {
    let half_frame = 0.5 / fps;
    let at_end = |t: Real| (t - period).abs() < half_frame;
    if let Some(k) = times
        .iter()
        .position(|&t| t < 0.0 || (t > period && !at_end(t)))
    {
        let period = (period * 1e6).round() / 1e6;
        let message = format!(
            "a looping film's keys lie within its one period, 0 s to {period} s (frames / fps), \
             got {}; the loop repeats them every {period} s",
            times[k]
        );
        return Err((k, "time", message));
    }
    let mut times = times.to_vec();
    let last = times.len() - 1;
    if !at_end(times[last]) {
        return Ok((times, columns));
    }
    times.pop();
    let end_values: Vec<Real> = columns.iter_mut().filter_map(|c| c.pop()).collect();
    if last > 0 && times[0] < half_frame {
        let (end, start) = (&keys[last].value, &keys[0].value);
        let digits = [start, end]
            .iter()
            .any(|v| matches!(v, KeyValue::Digits(_)));
        let same = if digits {
            // Keys in digits may differ far below f64's tolerance.
            let (a, b) = (key_point(start), key_point(end));
            let apart = crate::exact::difference(
                (a.value, a.digits.as_ref()),
                (b.value, b.digits.as_ref()),
            );
            apart == DVec3::ZERO
        } else {
            start
                .components()
                .iter()
                .zip(end.components())
                .all(|(a, b)| (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0))
        };
        if !same {
            let message = format!(
                "in a looping film the key at its end ({} s) is the key at 0 s again, so it \
                 must have the same value: {} here, {} at 0 s (or leave one of them out)",
                keys[last].time,
                end.shown(),
                start.shown()
            );
            return Err((last, "value", message));
        }
    } else {
        times.insert(0, 0.0);
        for (c, v) in columns.iter_mut().zip(end_values) {
            c.insert(0, v);
        }
    }
    Ok((times, columns))
}
