//! The chart's log axes: their ranges, which ticks are labelled and how a
//! tick value is written, and the step line a Pareto front is drawn as.

/// The range of a log axis holding every value with a margin, at least
/// half a decade wide.
pub(super) fn log_range(values: &[f64]) -> (f64, f64) {
    let positive = values.iter().copied().filter(|v| v.is_finite() && *v > 0.0);
    let lo = positive.clone().fold(f64::INFINITY, f64::min);
    let hi = positive.fold(0.0, f64::max);
    if !lo.is_finite() || hi <= 0.0 {
        return (1e-3, 1.0);
    }
    let (lo, hi) = (lo / 1.6, hi * 1.6);
    let mid = (lo * hi).sqrt();
    let half = 3f64.sqrt();
    (lo.min(mid / half), hi.max(mid * half))
}

/// Mantissas of log-axis ticks, from coarse to fine.
pub(super) const MANTISSAS: [&[f64]; 5] = [
    &[1.0],
    &[1.0, 3.0],
    &[1.0, 2.0, 5.0],
    &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0],
    &[
        1.0, 1.2, 1.4, 1.6, 1.8, 2.0, 2.5, 3.0, 3.5, 4.0, 4.5, 5.0, 6.0, 7.0, 8.0, 9.0,
    ],
];

/// Values m × 10^k in `[lo, hi]` for the mantissas `m`, ascending.
pub(super) fn decade_values(lo: f64, hi: f64, mantissas: &[f64]) -> Vec<f64> {
    let (k0, k1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    (k0..=k1)
        .flat_map(|k| mantissas.iter().map(move |m| m * 10f64.powi(k)))
        .filter(|&v| v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9))
        .collect()
}

/// Labelled ticks of a log axis over `[lo, hi]`: the coarsest of 1, 1-3,
/// 1-2-5, 1…9 per decade that gives at least five, thinned to `most`.
pub(super) fn log_ticks(lo: f64, hi: f64, most: usize) -> Vec<f64> {
    let mut ticks = Vec::new();
    for mantissas in MANTISSAS {
        ticks = decade_values(lo, hi, mantissas);
        if ticks.len() >= 5 {
            break;
        }
    }
    let step = ticks.len().div_ceil(most.max(1)).max(1);
    ticks.into_iter().step_by(step).collect()
}

/// A tick value in few characters: `0.002`, `1.5`, `20`, `1e-4`.
pub(super) fn tick_label(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        return "0".into();
    }
    let trim = |s: String| {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    };
    if (1e-3..1e5).contains(&a) {
        let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
        trim(format!("{v:.decimals$}"))
    } else {
        let s = format!("{v:.2e}");
        let (mantissa, exponent) = s.split_once('e').expect("{:e} writes an exponent");
        format!("{}e{exponent}", trim(mantissa.to_string()))
    }
}

/// The staircase through a front's points: from each point along to the
/// next one's cost, then down to its error.
pub(super) fn step_path(front: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut points = front.to_vec();
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut path = Vec::with_capacity(2 * points.len());
    for (i, &(x, y)) in points.iter().enumerate() {
        if i > 0 {
            path.push((x, path.last().map_or(y, |p: &(f64, f64)| p.1)));
        }
        path.push((x, y));
    }
    path
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(ticks: &[f64]) -> Vec<String> {
        ticks.iter().map(|&v| tick_label(v)).collect()
    }

    #[test]
    fn log_ticks_give_several_labels_per_axis() {
        // Two decades: 1-2-5 is the coarsest set with at least five.
        assert_eq!(
            labels(&log_ticks(0.002, 0.09, 9)),
            ["0.002", "0.005", "0.01", "0.02", "0.05"]
        );
        // Under a decade: every integer mantissa.
        assert_eq!(
            labels(&log_ticks(0.0031, 0.0095, 9)),
            ["0.004", "0.005", "0.006", "0.007", "0.008", "0.009"]
        );
        // Sixteen decades: one per decade, thinned to the limit, still spanning.
        let wide = log_ticks(1e-8, 1e8, 6);
        assert!((4..=6).contains(&wide.len()), "{wide:?}");
        assert_eq!(tick_label(wide[0]), "1e-8");
        assert!(wide.last().is_some_and(|&v| v >= 1e6));
        for ticks in [log_ticks(0.002, 0.09, 9), wide] {
            assert!(ticks.windows(2).all(|w| w[0] < w[1]));
        }
    }

    #[test]
    fn log_range_holds_every_value_and_half_a_decade() {
        let (lo, hi) = log_range(&[0.004, 0.0041]);
        assert!(lo < 0.004 && hi > 0.0041 && hi / lo >= 3.0 - 1e-9);
        let (lo, hi) = log_range(&[1e-4, 0.3, 0.0]);
        assert!(lo < 1e-4 && hi > 0.3);
    }

    #[test]
    fn tick_labels_are_short() {
        let cases = [
            (0.002, "0.002"),
            (0.0015, "0.0015"),
            (1.5, "1.5"),
            (20.0, "20"),
            (0.1 + 0.2, "0.3"),
            (1e-4, "1e-4"),
            (2.5e-5, "2.5e-5"),
            (1e5, "1e5"),
        ];
        for (v, label) in cases {
            assert_eq!(tick_label(v), label, "{v}");
        }
    }

    #[test]
    fn step_path_goes_along_then_down() {
        assert_eq!(
            step_path(&[(2.0, 0.5), (1.0, 1.0), (4.0, 0.1)]),
            [(1.0, 1.0), (2.0, 1.0), (2.0, 0.5), (4.0, 0.5), (4.0, 0.1)]
        );
    }
}
