//! Rows of results and their builders: alternating timings, the timing and
//! rate columns, thread scaling, and the in-process render-only and kernel rows.

use super::child::Measurement;
use super::options::Options;
use super::peak::Peak;
use super::scenes::{BenchScene, Work};
use crate::error::Error;
use crate::error::Result;
use crate::render::FrameStats;
use crate::timeline::Timeline;
use rayon::prelude::*;
use serde::Serialize;
use std::time::Instant;

/// One row of results.
#[derive(Clone, Debug, Default, Serialize)]
pub(super) struct Row {
    pub machine: String,
    /// Scene name, `KERNEL`, `CEILING`, or `<scene>@<W>x<H>` for the memory render.
    pub scene: String,
    pub renderer: String,
    pub threads: usize,
    pub runs: usize,
    pub median_s: f64,
    pub min_s: f64,
    pub max_s: f64,
    pub frames: u32,
    pub pixels: u64,
    pub mpixels_per_s: f64,
    pub de_evaluations: u64,
    pub de_evaluations_per_s: f64,
    pub de_iterations: u64,
    pub de_iterations_per_s: f64,
    pub gflops: f64,
    pub peak_gflops: f64,
    pub fraction_of_peak: f64,
    pub peak_rss_mib: f64,
    /// Size of the frame's output buffers (`Film::BYTES_PER_PIXEL` per pixel), MiB.
    pub output_buffers_mib: f64,
    /// Mandelbulber2's median over mandelreel's, on the mandelreel row.
    pub speedup_vs_mandelbulber2: f64,
    /// This row's median over the one-thread median, on scaling rows.
    pub scaling_vs_one_thread: f64,
    /// On depth rows: mean and 99th percentile of the depth error against
    /// the membership reference, in pixel footprints, and the share of
    /// pixels where hit and miss differ from it.
    pub depth_error_mean_px: Option<f64>,
    pub depth_error_p99_px: Option<f64>,
    pub hit_mismatch: Option<f64>,
}

/// Times `contenders` candidates `runs` times each, in alternating order
/// (forwards on even runs, backwards on odd ones) so a machine that drifts
/// favours none of them: `each_run(n)` before run n (from 1), `time(i)` for
/// candidate i. Each candidate's timings, in the order of the candidates.
pub(super) fn alternate<T>(
    runs: usize,
    contenders: usize,
    mut each_run: impl FnMut(usize),
    mut time: impl FnMut(usize) -> Result<T>,
) -> Result<Vec<Vec<T>>> {
    let mut timings: Vec<Vec<T>> = (0..contenders).map(|_| Vec::new()).collect();
    for run in 0..runs {
        each_run(run + 1);
        for k in 0..contenders {
            let i = if run % 2 == 0 { k } else { contenders - 1 - k };
            timings[i].push(time(i)?);
        }
    }
    Ok(timings)
}

/// `alternate` for work done in this process: `work(i)` for candidate i,
/// each candidate's wall times in seconds.
fn timed_in_process(runs: usize, contenders: usize, mut work: impl FnMut(usize)) -> Vec<Vec<f64>> {
    alternate(
        runs,
        contenders,
        |_| {},
        |i| -> Result<f64> {
            let start = Instant::now();
            work(i);
            Ok(start.elapsed().as_secs_f64())
        },
    )
    .expect("an in-process timing has no error to return")
}

pub(super) const MIB: f64 = 1024.0 * 1024.0;

/// Fills the timing columns of `row` from `runs`, and the rates from `work`.
pub(super) fn timing_row(
    mut row: Row,
    runs: &[Measurement],
    work: Option<&Work>,
    peak: &Peak,
) -> Row {
    let walls: Vec<f64> = runs.iter().map(|m| m.wall_s).collect();
    row.runs = runs.len();
    row.median_s = crate::math::median(&mut walls.clone());
    row.min_s = walls.iter().copied().fold(f64::INFINITY, f64::min);
    row.max_s = walls.iter().copied().fold(0.0, f64::max);
    row.peak_rss_mib = runs.iter().map(|m| m.peak_rss_kib).max().unwrap_or(0) as f64 / 1024.0;
    if let Some(w) = work {
        let t = row.median_s.max(1e-9);
        row.frames = w.frames;
        row.pixels = w.pixels;
        row.mpixels_per_s = mpixels_per_s(w.pixels, t);
        row.de_evaluations = w.stats.de_evaluations;
        row.de_evaluations_per_s = w.stats.de_evaluations as f64 / t;
        row.de_iterations = w.stats.de_iterations;
        row.de_iterations_per_s = w.stats.de_iterations as f64 / t;
        let gflops = w.flops() as f64 / t / 1e9;
        row.gflops = gflops;
        row.peak_gflops = peak.gflops_for(row.threads);
        row.fraction_of_peak = gflops / row.peak_gflops.max(1e-9);
    }
    row
}

pub(super) fn mpixels_per_s(pixels: u64, seconds: f64) -> f64 {
    pixels as f64 / seconds.max(1e-9) / 1e6
}

/// Frame 0 of `timeline` rendered in this process on each of `pools`
/// (`thread_pools` of `options.threads`), alternating, medians over
/// `options.runs`.
pub(super) fn render_only_rows(
    scene: &BenchScene,
    timeline: &Timeline,
    pools: &[(usize, rayon::ThreadPool)],
    options: &Options,
    base: Row,
) -> Vec<Row> {
    let frame = timeline.scene_at(0);
    let (w, h) = (timeline.width, timeline.height);
    // Each pool's own counts, so the rows can show they do not depend on it.
    let mut counts = vec![FrameStats::default(); pools.len()];
    let walls = timed_in_process(options.runs, pools.len(), |i| {
        let film = pools[i]
            .1
            .install(|| crate::render::render_frame(&frame, 0, w, h, &|| {}));
        counts[i] = film.stats;
    });
    let works: Vec<Work> = counts
        .into_iter()
        .map(|stats| Work {
            frames: 1,
            pixels: w as u64 * h as u64,
            stats,
            counted_flops: None,
        })
        .collect();
    pool_rows(
        &format!("{} (render only)", scene.name),
        pools,
        walls,
        &works,
        &options.peak,
        base,
    )
}

/// A rayon pool of each size in `threads`, in that order; an error names
/// the size the system would not start.
pub(super) fn thread_pools(threads: &[usize]) -> Result<Vec<(usize, rayon::ThreadPool)>> {
    threads
        .iter()
        .map(|&t| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .map_err(|e| {
                    Error::usage(
                        "--threads",
                        format!("could not start a pool of {t} threads: {e}"),
                    )
                })?;
            Ok((t, pool))
        })
        .collect()
}

/// The rows of work timed in this process on each pool (`walls[i]` and
/// `works[i]` on `pools[i]`), with their speed-ups over the one-thread pool.
pub(super) fn pool_rows(
    scene: &str,
    pools: &[(usize, rayon::ThreadPool)],
    walls: Vec<Vec<f64>>,
    works: &[Work],
    peak: &Peak,
    base: Row,
) -> Vec<Row> {
    let runs = pools
        .iter()
        .zip(walls)
        .zip(works)
        .map(|(((threads, _), walls), work)| {
            let runs = walls
                .iter()
                .map(|&wall_s| Measurement {
                    wall_s,
                    peak_rss_kib: 0,
                    exit_code: 0,
                })
                .collect();
            (*threads, runs, work)
        });
    thread_rows(scene, runs, peak, &base)
}

/// A row of mandelreel's timings per thread count (`runs`: the count, its
/// runs and the work they did), with their speed-ups over one thread.
pub(super) fn thread_rows<'w>(
    scene: &str,
    runs: impl IntoIterator<Item = (usize, Vec<Measurement>, &'w Work)>,
    peak: &Peak,
    base: &Row,
) -> Vec<Row> {
    let mut rows: Vec<Row> = runs
        .into_iter()
        .map(|(threads, runs, work)| {
            let row = Row {
                scene: scene.into(),
                renderer: "mandelreel".into(),
                threads,
                ..base.clone()
            };
            timing_row(row, &runs, Some(work), peak)
        })
        .collect();
    scale_to_one_thread(&mut rows);
    rows
}

/// Sets each row's speed-up over the one-thread row among them, if any.
fn scale_to_one_thread(rows: &mut [Row]) {
    if let Some(one) = rows.iter().find(|r| r.threads == 1).map(|r| r.median_s) {
        for row in rows {
            row.scaling_vs_one_thread = one / row.median_s.max(1e-9);
        }
    }
}

/// Measures DE iterations per second of the analytic estimator at points on
/// a shell just outside the bulb of `timeline`'s first frame (where the
/// marcher spends most of its estimates), on a pool of each size in
/// `options.threads`, alternating: the kernel's own thread scaling, with no
/// start-up, scheduling of rows or file writing in it.
pub(super) fn kernel_rows(
    timeline: &Timeline,
    pools: &[(usize, rayon::ThreadPool)],
    options: &Options,
    base: Row,
) -> Vec<Row> {
    let fractal = timeline.scene_at(0).fractal;
    let points = crate::math::shell_points(1 << 16, 0.9..1.3, 7);
    const CHUNK: usize = 1024;
    let chunks = points.len() / CHUNK;
    // `passes` passes over the points on a pool, as one parallel loop over
    // their chunks (one fork and join, not one per pass of a millisecond or
    // two, whose wake-ups and ragged ends the kernel's scaling would carry):
    // their orbit iterations.
    let pass = |pool: &rayon::ThreadPool, passes: u64| {
        pool.install(|| {
            (0..passes as usize * chunks)
                .into_par_iter()
                .map(|k| {
                    let chunk = &points[(k % chunks) * CHUNK..][..CHUNK];
                    let before = crate::fractal::iterations_on_this_thread();
                    // A vector of points at a time, into one array of estimates
                    // kept from call to call, as marching asks.
                    let mut estimates = [crate::fractal::Estimate::IDLE; crate::fractal::VECTOR];
                    let sum: f64 = chunk
                        .chunks_exact(crate::fractal::VECTOR)
                        .map(|v| {
                            let v: &[crate::math::DVec3; crate::fractal::VECTOR] =
                                v.try_into().expect("whole vectors");
                            fractal.estimate_lanes_into(
                                v,
                                &[1e-4; crate::fractal::VECTOR],
                                &mut estimates,
                            );
                            estimates.iter().map(|e| e.distance).sum::<f64>()
                        })
                        .sum();
                    std::hint::black_box(sum);
                    crate::fractal::iterations_on_this_thread() - before
                })
                .sum::<u64>()
        })
    };
    let (passes, walls, iterations) = sampled_passes(pools, options, (1, 1), pass);
    let works: Vec<Work> = iterations
        .into_iter()
        .map(|iterations| Work {
            stats: FrameStats {
                de_evaluations: (chunks * CHUNK) as u64 * passes,
                de_iterations: iterations,
                ..FrameStats::default()
            },
            ..Work::default()
        })
        .collect();
    pool_rows(KERNEL, pools, walls, &works, &options.peak, base)
}

/// The scene name of the kernel's rows (`kernel_rows`).
pub(super) const KERNEL: &str = "kernel";

/// `pass(pool, amount)` timed on each of `pools`, as the kernel's and the
/// ceiling's rows time it: `warm` on every pool first (its threads started,
/// its data in cache); then `trial` on the widest pool, scaled to the
/// amount that lasts about 0.2 s there (longer on fewer threads); then
/// `options.runs` samples of that amount on each pool, alternating, each
/// sample one call of `pass`. The amount, each pool's wall times, and what
/// its last sample returned.
pub(super) fn sampled_passes<R: Default + Clone>(
    pools: &[(usize, rayon::ThreadPool)],
    options: &Options,
    (warm, trial): (u64, u64),
    pass: impl Fn(&rayon::ThreadPool, u64) -> R,
) -> (u64, Vec<Vec<f64>>, Vec<R>) {
    let Some((_, widest)) = pools.iter().max_by_key(|(t, _)| *t) else {
        return (0, Vec::new(), Vec::new());
    };
    for (_, pool) in pools {
        pass(pool, warm);
    }
    let start = Instant::now();
    pass(widest, trial);
    let amount = (trial as f64 * 0.2 / start.elapsed().as_secs_f64().max(1e-6))
        .ceil()
        .max(1.0) as u64;
    let mut done = vec![R::default(); pools.len()];
    let walls = timed_in_process(options.runs, pools.len(), |i| {
        done[i] = pass(&pools[i].1, amount);
    });
    (amount, walls, done)
}
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn alternate_reverses_the_order_every_other_run() {
        let (mut calls, mut runs) = (Vec::new(), Vec::new());
        let timings = alternate(
            3,
            3,
            |run| runs.push(run),
            |i| {
                calls.push(i);
                Ok(calls.len())
            },
        )
        .unwrap();
        assert_eq!(runs, [1, 2, 3]);
        assert_eq!(calls, [0, 1, 2, 2, 1, 0, 0, 1, 2]);
        // Each candidate's timings, in call order: 0 was called 1st, 6th, 7th.
        assert_eq!(timings, [vec![1, 6, 7], vec![2, 5, 8], vec![3, 4, 9]]);
        // An error stops the timing.
        assert!(alternate(
            2,
            2,
            |_| {},
            |i| if i == 1 {
                Err(Error::usage("x", "y"))
            } else {
                Ok(i)
            }
        )
        .is_err());
    }

    #[test]
    fn the_iteration_counter_counts_each_power_step() {
        // The flop rate is iterations × flops per iteration: check a power-8
        // orbit counts one iteration per power step through the thread counter.
        let f = crate::fractal::Fractal {
            iterations: 5,
            ..crate::fractal::Fractal::default()
        };
        let before = crate::fractal::iterations_on_this_thread();
        let orbit = f.orbit([0.1, 0.2, 0.3], 5, true);
        assert_eq!(
            crate::fractal::iterations_on_this_thread() - before,
            orbit.iterations as u64
        );
        assert_eq!(
            orbit.iterations, 5,
            "the point is inside, so every iteration runs"
        );
    }
}
