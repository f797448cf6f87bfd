//! The report: the table as Markdown and CSV, and the words on how the times
//! were taken and the front drawn.

use super::chart;
use super::front::{recommended, TIMING_NOISE};
use super::reference::REFERENCE_STEP;
use super::timing::{MAX_TIMED_RUNS, MIN_TIMED_RUNS, SLOW_BUDGET_SECONDS, TIMING_BUDGET_SECONDS};
use super::{Measurement, Report};

/// How the times were taken and the front drawn, for the Markdown.
pub fn front_rule_text() -> String {
    format!(
        "Times are the median of {MIN_TIMED_RUNS} to {MAX_TIMED_RUNS} runs of the frame (more for quick frames, within {TIMING_BUDGET_SECONDS} s a variant; fewer, down to one, for frames too slow for {MIN_TIMED_RUNS} runs in {SLOW_BUDGET_SECONDS} s). \
★ marks the Pareto front of median time against image RMSE (the chart draws the same front for mean depth error too), \
with times within {:.0}% of each other counted as the same cost and errors equal to three significant digits as the same error: a variant is off the front when another has less error \
at no more than {TIMING_NOISE}× its median time. Variants with equal error are one point: of those within {:.0}% of the fastest of them, \
or with its DE evaluation count (the same work), the star goes to the one with fewer DE evaluations, \
then to the scene's own settings, then to the faster. The reference is the yardstick, not a candidate.",
        100.0 * (TIMING_NOISE - 1.0),
        100.0 * (TIMING_NOISE - 1.0)
    )
}

/// The table as CSV, one row per variant, a column per field.
pub fn to_csv(rows: &[Measurement]) -> String {
    crate::output::csv::csv_text(rows)
}

/// The table as Markdown, with times relative to the scene's own settings.
pub fn to_markdown(report: &Report, title: &str) -> String {
    let rows = &report.rows;
    let r = &report.reference;
    let base = rows
        .iter()
        .find(|r| r.knob == "scene")
        .map(|r| r.seconds)
        .unwrap_or(1.0)
        .max(1e-9);
    let mut out = format!(
        "{title}\n\nReference: the scene's set ({} iterations, bailout {}), Analytic f64, hit threshold {}, fudge {}, {} steps, normal step {}, {} samples per pixel; depths by membership steps of 1/{} footprint. Against steps twice as long, its depths move by {:.2} px on average and {:.2}% of pixels change hit/miss: differences below that are within the reference's own uncertainty.\n\n| knob | setting | time (s) | × scene | DE evals | depth err mean (px) | depth err p99 (px) | hit/miss differ | overshoot | 3D distance to the set (median, px) | PSNR (dB) | Pareto |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|:-:|\n",
        r.fractal.iterations,
        r.fractal.bailout,
        r.quality.hit_threshold,
        r.quality.fudge,
        r.quality.max_steps,
        r.quality.normal_step,
        r.samples_per_pixel,
        (1.0 / REFERENCE_STEP).round(),
        report.convergence.depth_change_mean_px,
        100.0 * report.convergence.hit_change,
    );
    for r in rows {
        out += &format!(
            "| {} | {} | {:.3} | {:.2} | {} | {:.2} | {:.2} | {:.2}% | {:.2}% | {} | {} | {} |\n",
            r.knob,
            r.setting,
            r.seconds,
            r.seconds / base,
            r.de_evaluations,
            r.depth_error_mean_px,
            r.depth_error_p99_px,
            100.0 * r.hit_mismatch,
            100.0 * r.overshoot,
            r.surface_distance_px
                .map_or("–".into(), |d| format!("{d:.2}")),
            if r.psnr_db.is_finite() {
                format!("{:.1}", r.psnr_db)
            } else {
                "∞".into()
            },
            if r.pareto { "★" } else { "" }
        );
    }
    // After the table, so the reference paragraph above stays as it is.
    out += &format!("\n{}\n", front_rule_text());
    out += &format!(
        "\n{} ({}; a red ring marks {}).\n",
        chart::advice(rows, recommended(rows)),
        chart::star_rule(),
        chart::flag_rule()
    );
    out
}

#[cfg(test)]
mod tests {
    use super::super::reference::{reference_scene, Convergence};
    use super::super::row;
    use super::*;
    use crate::scene::Scene;

    #[test]
    fn markdown_says_how_the_front_was_computed() {
        let report = Report {
            rows: vec![row("reference", 5.0, 0.0), row("scene", 1.0, 0.1)],
            reference: reference_scene(&Scene::default()),
            convergence: Convergence {
                depth_change_mean_px: 0.0,
                hit_change: 0.0,
            },
        };
        let md = to_markdown(&report, "# t");
        assert!(md.contains(&format!(
            "median of {MIN_TIMED_RUNS} to {MAX_TIMED_RUNS} runs"
        )));
        assert!(
            md.contains("less error at no more than 1.03× its median time"),
            "{md}"
        );
        assert!(md.contains("within 3% of the fastest of them"));
        // Which setting to use, in words, as the chart's star says.
        assert!(md.contains("recommended: "), "{md}");
    }
}
