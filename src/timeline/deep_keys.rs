//! A track keyed with digits (a deep camera's path, a Julia constant moved
//! below f64's resolution). Between its keys a value is the nearest key's
//! digits moved by the spline through the neighbouring keys' offsets from
//! it: the offsets are small where the keys are close, so f64 holds them,
//! and a pan a few footprints wide at 1e-30 keeps every digit.

use super::schema::Interpolation;
use super::spline::build_spline;
use crate::exact::{self, Coordinates, Digits};
use crate::math::{DVec3, Real};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// A track's keys as digits, laid out as its splines are (over one period
/// in a looping film).
#[derive(Clone, Debug)]
pub(super) struct DeepKeys {
    times: Vec<Real>,
    points: Vec<Coordinates>,
    /// For each key, the offsets of the keys from two before it to two
    /// after it (wrapping in a loop; zero past the ends): every key a
    /// segment's spline reads, from either end of the segment.
    near: Vec<[DVec3; 5]>,
    interpolation: Interpolation,
    period: Option<Real>,
    /// Values already sampled, by instant: a frame's scene is built several
    /// times (validation, planning, hashing), its digits worked out once.
    sampled: Arc<Mutex<HashMap<u64, Coordinates>>>,
}

/// The most sampled values kept (three strings of up to `MAX_DIGITS`
/// digits each, 1.3 kB at most: 20 MB a track); past it they start over,
/// costing a recomputation, never memory.
const MOST_SAMPLED: usize = 1 << 14;

impl DeepKeys {
    /// The keys at `times` (increasing), each with its digits.
    pub(super) fn new(
        times: Vec<Real>,
        points: Vec<Coordinates>,
        interpolation: Interpolation,
        period: Option<Real>,
    ) -> DeepKeys {
        let n = points.len() as isize;
        let index = |m: isize| match period {
            Some(_) => Some(m.rem_euclid(n) as usize),
            None => (0..n).contains(&m).then_some(m as usize),
        };
        let offset = |from: &Coordinates, to: &Coordinates| {
            exact::difference(
                (to.value, to.digits.as_ref()),
                (from.value, from.digits.as_ref()),
            )
        };
        let near = (0..n)
            .map(|a| {
                let from = &points[a as usize];
                [-2, -1, 0, 1, 2].map(|i| match index(a + i) {
                    Some(j) if i != 0 => offset(from, &points[j]),
                    _ => DVec3::ZERO,
                })
            })
            .collect();
        DeepKeys {
            times,
            points,
            near,
            interpolation,
            period,
            sampled: Arc::default(),
        }
    }

    /// The value at `time_seconds`, digits and nearest f64.
    pub(super) fn sample(&self, time_seconds: Real) -> Coordinates {
        // A panic elsewhere while holding the lock leaves whole entries.
        let lock = || self.sampled.lock().unwrap_or_else(|e| e.into_inner());
        let key = time_seconds.to_bits();
        if let Some(kept) = lock().get(&key) {
            return kept.clone();
        }
        let value = self.interpolated(time_seconds);
        let mut sampled = lock();
        if sampled.len() >= MOST_SAMPLED {
            sampled.clear();
        }
        sampled.insert(key, value.clone());
        value
    }

    /// Key `m` of the keys laid out without end (a loop's repeating every
    /// period): its time and its index in `points`.
    fn key(&self, m: isize) -> (Real, usize) {
        let n = self.points.len() as isize;
        let (turns, j) = (m.div_euclid(n), m.rem_euclid(n) as usize);
        let shift = self.period.map_or(0.0, |p| p * turns as Real);
        (self.times[j] + shift, j)
    }

    fn interpolated(&self, time_seconds: Real) -> Coordinates {
        let n = self.points.len();
        let (t, k) = match self.period {
            _ if n == 1 => return self.points[0].clone(),
            Some(period) => {
                let t = time_seconds.rem_euclid(period);
                let t = if t < period { t } else { 0.0 };
                // Key -1 is the last one a period back.
                (t, self.times.partition_point(|&x| x <= t) as isize - 1)
            }
            None if time_seconds <= self.times[0] => return self.points[0].clone(),
            None if time_seconds >= self.times[n - 1] => return self.points[n - 1].clone(),
            None => (
                time_seconds,
                self.times.partition_point(|&x| x <= time_seconds) as isize - 1,
            ),
        };
        let ((start, from), (end, _)) = (self.key(k), self.key(k + 1));
        if self.interpolation == Interpolation::Step {
            return self.points[from].clone();
        }
        let a = if t - start <= end - t { k } else { k + 1 };
        let anchor = self.key(a).1;
        let window: Vec<(Real, DVec3)> = (k - 1..=k + 2)
            .filter(|&m| self.period.is_some() || (0..n as isize).contains(&m))
            .map(|m| (self.key(m).0, self.near[anchor][(m - a + 2) as usize]))
            .collect();
        let times: Vec<Real> = window.iter().map(|w| w.0).collect();
        let step = DVec3::from_array([0, 1, 2].map(|i| {
            let values: Vec<Real> = window.iter().map(|w| w.1[i]).collect();
            build_spline(&times, &values, self.interpolation, None)
                .sample(t)
                .unwrap_or(0.0)
        }));
        moved(&self.points[anchor], step)
    }
}

/// `point` moved by `step`, its digits exactly.
fn moved(point: &Coordinates, step: DVec3) -> Coordinates {
    let Some(digits) = &point.digits else {
        return Coordinates::from(point.value + step);
    };
    let moved: [String; 3] = [0, 1, 2].map(|i| match step[i] {
        0.0 => digits[i].clone(),
        s => exact::moved(&digits[i], s),
    });
    let value = moved.each_ref().map(|d| {
        exact::parse_digits(d)
            .unwrap_or_else(|_| unreachable!("`exact::moved` keeps to the limits"))
    });
    Coordinates {
        value: DVec3::from_array(value),
        digits: Some(Digits::new(moved)),
    }
}

#[cfg(test)]
#[path = "deep_keys_tests.rs"]
mod tests;
