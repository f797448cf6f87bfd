//! The Pareto front of median time against error, timing noise allowed for,
//! and the setting to recommend.

use super::Measurement;

/// Median times closer than this factor are within timing noise.
pub const TIMING_NOISE: f64 = 1.03;

/// One candidate for a Pareto front: its cost and one of its errors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrontPoint {
    /// Median wall time.
    pub seconds: f64,
    pub de_evaluations: u64,
    pub error: f64,
    /// The scene's own settings (wins ties).
    pub is_scene: bool,
}

impl FrontPoint {
    fn of(row: &Measurement, error: f64) -> FrontPoint {
        FrontPoint {
            seconds: row.seconds,
            de_evaluations: row.de_evaluations,
            error,
            is_scene: row.knob == "scene",
        }
    }
}

/// Which points are on the Pareto front of cost against error (`None` is
/// no candidate). Median times within `TIMING_NOISE` of each other are the
/// same cost, and errors equal to three significant digits the same error, so:
/// - a point is off the front when another has less error at no more than
///   `TIMING_NOISE` × its time;
/// - points with equal error are one point: of those within `TIMING_NOISE`
///   of the fastest of them, or with its DE evaluation count (the same work,
///   whose time differences are noise), the one with fewer evaluations
///   stays, then the scene's own settings, then the faster, then the first.
///
/// Deciding equal errors as a group, not pair by pair, keeps the rule free
/// of cycles (A ties B, B ties C, C beats A), so the front is never empty.
pub fn pareto_front(points: &[Option<FrontPoint>]) -> Vec<bool> {
    let candidates: Vec<(usize, FrontPoint)> = points
        .iter()
        .enumerate()
        .filter_map(|(i, p)| p.map(|p| (i, p)))
        .collect();
    let preferred = |a: &&(usize, FrontPoint), b: &&(usize, FrontPoint)| {
        (a.1.de_evaluations.cmp(&b.1.de_evaluations))
            .then(b.1.is_scene.cmp(&a.1.is_scene))
            .then(a.1.seconds.total_cmp(&b.1.seconds))
            .then(a.0.cmp(&b.0))
    };
    // Errors are compared to three significant digits: a variant whose image
    // differs from another's in the sixth digit is not better.
    let candidates: Vec<(usize, FrontPoint)> = candidates
        .into_iter()
        .map(|(i, p)| {
            let error = significant(p.error, 3);
            (i, FrontPoint { error, ..p })
        })
        .collect();
    let mut front = vec![false; points.len()];
    let undercut = |p: &FrontPoint| {
        candidates
            .iter()
            .any(|(_, q)| q.error < p.error && q.seconds <= p.seconds * TIMING_NOISE)
    };
    for &(i, p) in &candidates {
        // A NaN error is no error level to be on the front at.
        if p.error.is_nan() || undercut(&p) {
            continue;
        }
        // The level's members another variant beats cannot hold its star.
        let same_error = || {
            candidates
                .iter()
                .filter(|(_, q)| q.error == p.error && !undercut(q))
        };
        let fastest = same_error()
            .min_by(|a, b| a.1.seconds.total_cmp(&b.1.seconds))
            .expect("p itself qualifies")
            .1;
        let kept = same_error()
            .filter(|(_, q)| {
                q.seconds <= fastest.seconds * TIMING_NOISE
                    || q.de_evaluations == fastest.de_evaluations
            })
            .min_by(preferred)
            .expect("the fastest qualifies");
        front[i] = kept.0 == i;
    }
    front
}

/// `v` rounded to `digits` significant digits.
fn significant(v: f64, digits: i32) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    let scale = 10f64.powi(digits - 1 - v.abs().log10().floor() as i32);
    (v * scale).round() / scale
}

/// The front of median time against `error` over `rows`. The reference is
/// the yardstick, not a candidate, and is never on it.
pub fn front_of(rows: &[Measurement], error: impl Fn(&Measurement) -> f64) -> Vec<bool> {
    let points: Vec<Option<FrontPoint>> = rows
        .iter()
        .map(|r| (r.knob != "reference").then(|| FrontPoint::of(r, error(r))))
        .collect();
    pareto_front(&points)
}

/// Marks (★) the front of median time against image error.
pub fn mark_pareto(rows: &mut [Measurement]) {
    let front = front_of(rows, |r| r.image_rmse);
    for (row, on) in rows.iter_mut().zip(front) {
        row.pareto = on;
    }
}

/// The share of pixels whose overshoot earns a variant a warning: one in
/// a thousand (15 pixels of a 160×90 frame). The scene's own settings
/// overshoot on 2 pixels at zoom frame 60, the analytic estimator at finer
/// hit thresholds on 6, the membership walk on 3% and more.
pub const OVERSHOOT_FLAG: f64 = 0.001;
/// PSNR differences under this many dB are taken as not worth paying for
/// (a convention, not a measurement of what shows).
pub const VISIBLE_PSNR_DB: f64 = 0.5;

/// Marched through the surface on at least `OVERSHOOT_FLAG` of the pixels.
/// Hit/miss differences do not count: they grow with samples per pixel
/// (a pixel hits where any sample does) and with the reference's finer
/// threshold, on every setting of a scene alike (2.6–3.9% on S1).
pub fn flagged(r: &Measurement) -> bool {
    r.overshoot >= OVERSHOOT_FLAG
}

/// The setting to use: of the variants not `flagged`, the cheapest whose
/// image is within `VISIBLE_PSNR_DB` of the best of them. Of those within
/// `TIMING_NOISE` of the cheapest, the scene's own settings win, then
/// fewer DE evaluations. `None` when every variant is flagged.
pub fn recommended(rows: &[Measurement]) -> Option<usize> {
    let candidates = || {
        rows.iter()
            .enumerate()
            .filter(|(_, r)| r.knob != "reference" && !flagged(r) && !r.psnr_db.is_nan())
    };
    let best = candidates().map(|(_, r)| r.psnr_db).reduce(f64::max)?;
    let good = || candidates().filter(|(_, r)| r.psnr_db >= best - VISIBLE_PSNR_DB);
    let cheapest = good().map(|(_, r)| r.seconds).reduce(f64::min)?;
    good()
        .filter(|(_, r)| r.seconds <= cheapest * TIMING_NOISE)
        .min_by(|(_, a), (_, b)| {
            (b.knob == "scene")
                .cmp(&(a.knob == "scene"))
                .then(a.de_evaluations.cmp(&b.de_evaluations))
                .then(a.seconds.total_cmp(&b.seconds))
        })
        .map(|(i, _)| i)
}

#[cfg(test)]
mod tests {
    use super::super::row;
    use super::*;

    #[test]
    fn a_flag_needs_overshoot_on_one_pixel_in_a_thousand() {
        let mut r = row("fudge", 1.0, 0.1);
        // Two pixels of a 160×90 frame: the scene's own settings at zoom frame 60.
        r.overshoot = 2.0 / 14400.0;
        assert!(!flagged(&r));
        r.overshoot = 0.0011;
        assert!(flagged(&r));
        // Hit/miss differences alone, as on every variant of S1: no flag.
        r.overshoot = 0.0;
        r.hit_mismatch = 0.03;
        assert!(!flagged(&r));
    }

    #[test]
    fn recommended_is_the_cheapest_within_sight_of_the_best_image() {
        let mut rows = vec![
            row("reference", 50.0, 0.0),
            row("scene", 1.0, 0.12),
            row("fast", 0.5, 0.2),
            row("best", 3.0, 0.09),
            // 0.4 dB worse than the best, cheaper: recommended.
            row("close", 2.0, 0.09 * 10f64.powf(0.4 / 20.0)),
            // 0.6 dB worse: too far.
            row("near", 1.5, 0.09 * 10f64.powf(0.6 / 20.0)),
            // Better and cheaper than all, but marches through the surface.
            row("broken", 0.8, 0.01),
        ];
        rows[6].overshoot = 0.05;
        assert_eq!(recommended(&rows), Some(4));
        // Within timing noise of the cheapest, the scene's own settings win.
        rows[1] = row("scene", 2.05, 0.09);
        assert_eq!(recommended(&rows), Some(1));
        for r in &mut rows {
            r.overshoot = 0.5;
        }
        assert_eq!(recommended(&rows), None);
    }

    #[test]
    fn pareto_front_keeps_only_undominated_points() {
        let mut rows = vec![
            row("a", 1.0, 0.1),
            row("b", 2.0, 0.05),
            row("c", 2.0, 0.2), // slower and worse than a
            row("d", 0.5, 0.3),
            row("e", 3.0, 0.05), // as good as b but slower
        ];
        // The reference (zero error) is the yardstick: never on the front, and
        // it does not push others off it.
        rows.push(row("reference", 50.0, 0.0));
        mark_pareto(&mut rows);
        let front: Vec<_> = rows.iter().filter(|r| r.pareto).map(|r| r.knob).collect();
        assert_eq!(front, ["a", "b", "d"]);
    }

    #[test]
    fn a_level_keeps_its_star_when_only_its_slower_member_is_beaten() {
        // A and B share an error; C, a little better, is within noise of
        // B's time but not of A's: A holds the level's star (picking B,
        // which has fewer evaluations, and then finding it beaten left the
        // level without one). A NaN error is on no front, and panics nothing.
        let point = |seconds, de_evaluations, error| {
            Some(FrontPoint {
                seconds,
                de_evaluations,
                error,
                is_scene: false,
            })
        };
        let front = pareto_front(&[
            point(1.00, 300, 0.1),
            point(1.02, 200, 0.1),
            point(1.04, 300, 0.09),
            point(0.5, 100, f64::NAN),
        ]);
        assert_eq!(front, [true, false, true, false]);
    }

    /// The front of the scene (1 s, 1000 evaluations, error 0.1) and one
    /// variant: which of the two are on it.
    fn front_with_scene(seconds: f64, de_evaluations: u64, error: f64) -> Vec<bool> {
        let point = |seconds, de_evaluations, error, is_scene| {
            Some(FrontPoint {
                seconds,
                de_evaluations,
                error,
                is_scene,
            })
        };
        pareto_front(&[
            None, // the reference
            point(1.0, 1000, 0.1, true),
            point(seconds, de_evaluations, error, false),
        ])
    }

    #[test]
    fn pareto_front_allows_for_timing_noise() {
        // The same work (same error, same evaluation count) at 0.97× or 0.85×
        // the time: the difference is noise, one star, the scene's.
        assert_eq!(front_with_scene(0.97, 1000, 0.1), [false, true, false]);
        assert_eq!(front_with_scene(0.85, 1000, 0.1), [false, true, false]);
        assert_eq!(front_with_scene(1.15, 1000, 0.1), [false, true, false]);
        // Same error within the 3% noise: the evaluation count decides.
        assert_eq!(front_with_scene(0.98, 990, 0.1), [false, false, true]);
        assert_eq!(front_with_scene(0.98, 1010, 0.1), [false, true, false]);
        assert_eq!(front_with_scene(1.02, 990, 0.1), [false, false, true]);
        // Faster beyond noise, with fewer evaluations to show for it: a real speed-up.
        assert_eq!(front_with_scene(0.85, 850, 0.1), [false, false, true]);
        // Less error at a cost within noise pushes the scene off...
        assert_eq!(front_with_scene(1.02, 1020, 0.099), [false, false, true]);
        // ...beyond noise, both stay: a trade.
        assert_eq!(front_with_scene(1.10, 1100, 0.099), [false, true, true]);
        // Worse and no cheaper: only the scene.
        assert_eq!(front_with_scene(1.0, 900, 0.2), [false, true, false]);
    }

    #[test]
    fn pareto_front_of_equal_errors_is_one_point_without_cycles() {
        // A ties B (2.5% apart, B fewer evaluations), B ties C (2.4%, C fewer),
        // but A is faster than C beyond noise: pair by pair each would push
        // another off. As a group, B stays: within 3% of the fastest (A), with
        // fewer evaluations than A; C is beyond noise of A.
        let point = |seconds, de_evaluations| {
            Some(FrontPoint {
                seconds,
                de_evaluations,
                error: 0.1,
                is_scene: false,
            })
        };
        let front = pareto_front(&[point(1.0, 300), point(1.025, 200), point(1.05, 100)]);
        assert_eq!(front, [false, true, false]);
    }

    #[test]
    fn pareto_front_compares_errors_to_three_digits() {
        // An image differing in the sixth digit, the same work, 0.8× the time
        // (noise): the scene keeps the star.
        assert_eq!(front_with_scene(0.8, 1000, 0.1000001), [false, true, false]);
        assert_eq!(front_with_scene(0.8, 1000, 0.0999999), [false, true, false]);
        // In the third digit it is less error.
        assert_eq!(front_with_scene(1.0, 1000, 0.0995), [false, false, true]);
        assert_eq!(significant(0.012345, 3), 0.0123);
        assert_eq!(significant(33.094, 3), 33.1);
        assert_eq!(significant(0.0, 3), 0.0);
    }
}
