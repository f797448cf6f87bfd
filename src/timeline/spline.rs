//! One component's keys as a spline on the `splines` crate, padded so
//! every segment between the keys has its neighbours.

use super::schema::Interpolation;
use crate::math::Real;
use splines::{Key, Spline};

/// Builds the spline of one component. Phantom keys are mirrored beyond both
/// ends so Catmull–Rom, which needs a neighbour on each side, covers the first
/// and last segments too. With a `period` (a looping film; `times` in
/// [0, period)), the keys are laid out over the period before, this one and
/// the next instead, so every segment in [0, period) has its true
/// neighbours: the last key leads into the first as any key into the next.
pub(super) fn build_spline(
    times: &[Real],
    values: &[Real],
    mode: Interpolation,
    period: Option<Real>,
) -> Spline<Real, Real> {
    let m = mode.spline_mode();
    if let Some(period) = period {
        let keys = [-period, 0.0, period].into_iter().flat_map(|shift| {
            let key = move |(&t, &v): (&Real, &Real)| Key::new(t + shift, v, m);
            times.iter().zip(values).map(key)
        });
        return Spline::from_vec(keys.collect());
    }
    let mut keys: Vec<Key<Real, Real>> = times
        .iter()
        .zip(values)
        .map(|(&t, &v)| Key::new(t, v, m))
        .collect();
    let n = times.len();
    if n >= 2 {
        let before = Key::new(2.0 * times[0] - times[1], 2.0 * values[0] - values[1], m);
        let after = Key::new(
            2.0 * times[n - 1] - times[n - 2],
            2.0 * values[n - 1] - values[n - 2],
            m,
        );
        keys.insert(0, before);
        keys.push(after);
    }
    Spline::from_vec(keys)
}

impl Interpolation {
    fn spline_mode(self) -> splines::Interpolation<Real, Real> {
        match self {
            Interpolation::Step => splines::Interpolation::Step(1.0),
            Interpolation::Linear => splines::Interpolation::Linear,
            Interpolation::CatmullRom => splines::Interpolation::CatmullRom,
            Interpolation::Smooth => splines::Interpolation::Cosine,
        }
    }
}
