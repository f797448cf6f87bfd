//! The rows written out: CSV, and the Markdown tables of docs/performance.md.

use super::ceiling::{CEILING, CEILING_CHAINS};
use super::peak::{Peak, FLOPS_PER_POWER8_ITERATION};
use super::rows::{Row, KERNEL};
use crate::render::Film;
use std::fmt::Write as _;

/// The rows as CSV, one header line first.
pub(super) fn to_csv(rows: &[Row]) -> String {
    crate::output::csv::csv_text(rows)
}

/// The Markdown tables of docs/performance.md, made from the rows.
pub(super) fn to_markdown(rows: &[Row], peak: &Peak) -> String {
    let mut md = String::new();
    let machine = rows.first().map_or("", |r| r.machine.as_str());
    let _ = writeln!(
        md,
        "Machine `{machine}`: {}, {} cores at {:.2} GHz, {} f64 lanes per vector, \
nominal f64 FMA peak {:.1} GFLOP/s.\n",
        peak.cpu,
        peak.cores,
        peak.clock_ghz,
        peak.lanes,
        peak.gflops()
    );
    md.push_str("| scene | mandelreel | Mandelbulber2 | speed-up | Mpixel/s | DE evals/s | DE iterations/s | peak RSS |\n");
    md.push_str("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n");
    let is_scene = |r: &Row| {
        r.renderer == "mandelreel"
            && r.scene != KERNEL
            && r.scene != CEILING
            && !r.scene.contains('@')
            && !r.scene.ends_with("(scaling)")
            && !r.scene.ends_with("(render only)")
    };
    for r in rows.iter().filter(|r| is_scene(r)) {
        let theirs = rows
            .iter()
            .find(|o| o.renderer == "mandelbulber2" && o.scene == r.scene);
        let _ = writeln!(
            md,
            "| {} | {:.3} s | {} | {} | {:.2} | {:.3e} | {:.3e} | {:.0} MiB |",
            r.scene,
            r.median_s,
            theirs.map_or("–".into(), |t| format!("{:.3} s", t.median_s)),
            theirs.map_or("–".into(), |_| format!(
                "{:.1}×",
                r.speedup_vs_mandelbulber2
            )),
            r.mpixels_per_s,
            r.de_evaluations_per_s,
            r.de_iterations_per_s,
            r.peak_rss_mib,
        );
    }
    md.push_str(
        "\n| scene | threads | median | speed-up over 1 thread | render only (in-process) | DE iterations/s | share of FMA peak |\n",
    );
    md.push_str("| --- | ---: | ---: | ---: | ---: | ---: | ---: |\n");
    for r in rows.iter().filter(|r| r.scene.ends_with(" (scaling)")) {
        let scene = r.scene.trim_end_matches(" (scaling)");
        let render_only = rows
            .iter()
            .find(|o| o.scene == format!("{scene} (render only)") && o.threads == r.threads)
            .map_or("–".into(), |o| {
                format!("{:.3} s, {:.2}×", o.median_s, o.scaling_vs_one_thread)
            });
        let _ = writeln!(
            md,
            "| {} | {} | {:.3} s | {:.2}× | {} | {:.3e} | {:.1}% |",
            scene,
            r.threads,
            r.median_s,
            r.scaling_vs_one_thread,
            render_only,
            r.de_iterations_per_s,
            100.0 * r.fraction_of_peak
        );
    }
    let kernel: Vec<&Row> = rows.iter().filter(|r| r.scene == KERNEL).collect();
    if let Some(r) = kernel.iter().max_by_key(|r| r.threads) {
        let _ = write!(
            md,
            "\nKernel alone ({}, analytic estimate at points around the bulb): \
{:.3e} DE iterations/s × {} flops = {:.1} GFLOP/s, {:.1}% of the nominal peak.",
            counted(r.threads, "thread"),
            r.de_iterations_per_s,
            FLOPS_PER_POWER8_ITERATION,
            r.gflops,
            100.0 * r.fraction_of_peak
        );
        if kernel.len() > 1 && kernel.iter().any(|k| k.threads == 1) {
            let scaling: Vec<String> = kernel
                .iter()
                .map(|k| {
                    format!(
                        "{} {:.2}×",
                        counted(k.threads, "thread"),
                        k.scaling_vs_one_thread
                    )
                })
                .collect();
            let _ = write!(
                md,
                " Its speed-up over one thread, with no start-up, rows or files in it: {}.",
                scaling.join(", ")
            );
        }
        md.push('\n');
    }
    md.push_str(&ceiling_markdown(rows, peak));
    for r in rows
        .iter()
        .filter(|r| r.scene.contains('@') && r.depth_error_mean_px.is_none())
    {
        let _ = writeln!(
            md,
            "\nPeak memory, {}: {:.0} MiB against {:.0} MiB of output buffers \
(the film: colour, alpha, depth, estimates per pixel; {} B/px): {:.2}×, in {:.1} s.",
            r.scene,
            r.peak_rss_mib,
            r.output_buffers_mib,
            Film::BYTES_PER_PIXEL,
            r.peak_rss_mib / r.output_buffers_mib.max(1e-9),
            r.median_s
        );
    }
    md.push_str(&depth_markdown(rows));
    md
}

/// The ceiling rows as a paragraph, with the kernel's share of the
/// ceiling on as many threads; nothing without them.
fn ceiling_markdown(rows: &[Row], peak: &Peak) -> String {
    let ceiling: Vec<&Row> = rows.iter().filter(|r| r.scene == CEILING).collect();
    if ceiling.is_empty() {
        return String::new();
    }
    let each: Vec<String> = ceiling
        .iter()
        .map(|c| {
            let mut text = format!(
                "{} {:.1} GFLOP/s ({:.2}× the nominal peak of {}",
                counted(c.threads, "thread"),
                c.gflops,
                c.fraction_of_peak,
                counted(c.threads.min(peak.cores), "core")
            );
            if c.scaling_vs_one_thread > 0.0 && c.threads != 1 {
                let _ = write!(text, ", {:.2}× one thread", c.scaling_vs_one_thread);
            }
            text + ")"
        })
        .collect();
    let mut md = format!(
        "\nMachine ceiling, measured (the same pools; {CEILING_CHAINS} independent chains of fused \
multiply-adds on f64 vectors, in registers, nothing shared): {}.",
        each.join(", ")
    );
    let widest = ceiling.iter().max_by_key(|c| c.threads);
    let kernel = widest.and_then(|c| {
        rows.iter()
            .find(|k| k.scene == KERNEL && k.threads == c.threads)
            .map(|k| (k, c))
    });
    if let Some((k, c)) = kernel {
        let _ = write!(
            md,
            " The kernel alone on {} does {:.1}% of the ceiling's flops per second.",
            counted(k.threads, "thread"),
            100.0 * k.gflops / c.gflops.max(1e-9)
        );
    }
    md.push('\n');
    md
}

/// "1 thread", "2 threads": `n` and `noun`, plural unless `n` is 1.
fn counted(n: usize, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

/// The depth rows as a Markdown table, or nothing without them.
fn depth_markdown(rows: &[Row]) -> String {
    let depth: Vec<&Row> = rows
        .iter()
        .filter(|r| r.depth_error_mean_px.is_some())
        .collect();
    let Some(first) = depth.first() else {
        return String::new();
    };
    let mut md = format!(
        "\nDepth against the membership reference of `mandelreel accuracy`, {}: error in pixel \
footprints where both hit. Mandelbulber2 saves its z-buffer log-scaled between a minimum and \
maximum it does not record; its depths here are the least-squares best fit of that scale to the \
reference, so its figures are lower bounds. The fit also takes out any constant bias, so \
mandelreel's depths are shown through the same fit as well: compare the fitted rows.\n\n",
        first.scene
    );
    md.push_str("| renderer | depth error mean | depth error p99 | hit/miss differ |\n");
    md.push_str("| --- | ---: | ---: | ---: |\n");
    for r in depth {
        let _ = writeln!(
            md,
            "| {} | {:.2} px | {:.2} px | {:.2}% |",
            r.renderer,
            r.depth_error_mean_px.unwrap_or_default(),
            r.depth_error_p99_px.unwrap_or_default(),
            100.0 * r.hit_mismatch.unwrap_or_default(),
        );
    }
    md
}
