//! The bench run as a whole: its options, the order of its parts, the
//! renders timed against Mandelbulber2, and the files it writes.

use super::ceiling::ceiling_rows;
use super::child::{mandelbulber_args, render_args, timed};
use super::mandelbulber2::depth_rows;
use super::options::{log, Options};
use super::report::{to_csv, to_markdown};
use super::rows::{
    alternate, kernel_rows, mpixels_per_s, render_only_rows, thread_pools, thread_rows, timing_row,
    Row, MIB,
};
use super::scenes::{load_counted, scenes, BenchScene, Work};
use crate::error::Error;
use crate::error::Result;
use crate::render::Film;
use std::path::{Path, PathBuf};

/// What every render a bench run times shares: the options, this program,
/// the scratch folder its renders go to, and the machine's thread count.
struct Runner<'a> {
    options: &'a Options,
    exe: PathBuf,
    scratch: &'a Path,
    all_threads: usize,
}

impl Runner<'_> {
    /// A row of this machine, its other columns empty.
    fn base(&self) -> Row {
        Row {
            machine: self.options.machine.clone(),
            ..Row::default()
        }
    }

    fn log(&self, message: &str) {
        log(self.options.quiet, message)
    }
}

/// Runs the whole benchmark and returns its rows.
fn run(options: &Options) -> Result<Vec<Row>> {
    let exe = std::env::current_exe().map_err(|e| Error::io(Path::new("mandelreel"), e))?;
    let peak = &options.peak;
    let all_threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let scenes = scenes(&options.scenes, &options.fract_dir)?;
    let scratch = tempfile::tempdir().map_err(|e| Error::io(Path::new("temp"), e))?;
    // The in-process pools, started before any timing so that a size the
    // system will not start stops the bench at once.
    let pools = thread_pools(&options.threads)?;
    let runner = Runner {
        options,
        exe,
        scratch: scratch.path(),
        all_threads,
    };
    let mut rows = Vec::new();
    runner.log(&format!(
        "machine: {} ({}, {} cores, {:.2} GHz, {} f64 lanes: peak {:.1} GFLOP/s)",
        options.machine,
        peak.cpu,
        peak.cores,
        peak.clock_ghz,
        peak.lanes,
        peak.gflops()
    ));

    // Each timeline is loaded and its work counted once.
    let mut loaded = Vec::new();
    for scene in &scenes {
        let (timeline, work) = load_counted(scene)?;
        rows.extend(comparison_rows(&runner, scene, &work)?);
        loaded.push((timeline, work));
    }

    // Thread scaling on every scene (the zoom is a whole sequence, where
    // start-up is shared by its frames), counts alternating low/high.
    for (scene, (_, work)) in scenes.iter().zip(&loaded) {
        rows.extend(scaling_rows(&runner, scene, work)?);
    }
    let first = &scenes[0];
    let (timeline, _) = loaded.swap_remove(0);

    // The same frame rendered in this process on pools of each size: the
    // renderer's own scaling, without start-up and file writing.
    rows.extend(render_only_rows(
        first,
        &timeline,
        &pools,
        options,
        runner.base(),
    ));

    // The kernel alone, on pools of each size: analytic estimates at points
    // where marching spends its time.
    rows.extend(kernel_rows(&timeline, &pools, options, runner.base()));

    // The machine's own ceiling on the same pools: fused multiply-adds in
    // registers, nothing shared.
    runner.log("ceiling: FMA loop");
    rows.extend(ceiling_rows(&pools, options, runner.base()));

    // Peak memory of a big EXR frame against its output buffers.
    if let Some(size) = options.memory_size {
        rows.push(memory_row(&runner, first, size)?);
    }

    // Depth error of both renderers against the accuracy reference.
    if let Some((w, h)) = options.depth_size {
        runner.log(&format!("depth: {w}x{h} against the reference"));
        let out = runner.scratch.join("depth");
        std::fs::create_dir_all(&out).map_err(|e| Error::io(&out, e))?;
        rows.extend(depth_rows(
            first,
            &timeline,
            options,
            (w, h),
            &out,
            runner.base(),
        )?);
    }
    Ok(rows)
}

/// mandelreel's row for `scene` on every thread, and Mandelbulber2's beside
/// it where the options name it and the scene has a `.fract`, their runs
/// alternating.
fn comparison_rows(runner: &Runner, scene: &BenchScene, work: &Work) -> Result<Vec<Row>> {
    let (options, peak) = (runner.options, &runner.options.peak);
    let out_a = runner.scratch.join(format!("{}-mandelreel", scene.name));
    let out_b = runner.scratch.join(format!("{}-mandelbulber2", scene.name));
    std::fs::create_dir_all(&out_b).map_err(|e| Error::io(&out_b, e))?;
    let ours = render_args(&scene.timeline, &out_a, runner.all_threads, &[]);
    let theirs = match (&options.mandelbulber, &scene.fract) {
        (Some(program), Some(fract)) => {
            let text = std::fs::read_to_string(fract).map_err(|e| Error::io(fract, e))?;
            Some((
                program,
                mandelbulber_args(fract, &out_b, text.contains("[keyframes]")),
            ))
        }
        _ => None,
    };
    let contenders = 1 + theirs.is_some() as usize;
    let mut timings = alternate(
        options.runs,
        contenders,
        |run| runner.log(&format!("{}: run {run}/{}", scene.name, options.runs)),
        |i| match (i, &theirs) {
            (1, Some((program, args))) => {
                // Mandelbulber2 skips animation frames that already exist: start empty.
                let _ = std::fs::remove_dir_all(&out_b);
                std::fs::create_dir_all(&out_b).map_err(|e| Error::io(&out_b, e))?;
                timed(program, args)
            }
            _ => timed(&runner.exe, &ours),
        },
    )?;
    let b = if contenders > 1 {
        timings.pop().unwrap_or_default()
    } else {
        Vec::new()
    };
    let a = timings.pop().unwrap_or_default();
    let mut ours_row = timing_row(
        Row {
            scene: scene.name.clone(),
            renderer: "mandelreel".into(),
            threads: runner.all_threads,
            ..runner.base()
        },
        &a,
        Some(work),
        peak,
    );
    if b.is_empty() {
        return Ok(vec![ours_row]);
    }
    let mut theirs_row = timing_row(
        Row {
            scene: scene.name.clone(),
            renderer: "mandelbulber2".into(),
            threads: runner.all_threads,
            frames: work.frames,
            pixels: work.pixels,
            ..runner.base()
        },
        &b,
        None,
        peak,
    );
    ours_row.speedup_vs_mandelbulber2 = theirs_row.median_s / ours_row.median_s.max(1e-9);
    theirs_row.mpixels_per_s = mpixels_per_s(work.pixels, theirs_row.median_s);
    Ok(vec![ours_row, theirs_row])
}

/// mandelreel's rows for `scene` at each of `options.threads`, their runs
/// alternating.
fn scaling_rows(runner: &Runner, scene: &BenchScene, work: &Work) -> Result<Vec<Row>> {
    let options = runner.options;
    let timings = alternate(
        options.runs,
        options.threads.len(),
        |run| {
            let line = format!("scaling {}: run {run}/{}", scene.name, options.runs);
            runner.log(&line)
        },
        |i| {
            let threads = options.threads[i];
            let out = runner
                .scratch
                .join(format!("scaling-{}-{threads}", scene.name));
            timed(
                &runner.exe,
                &render_args(&scene.timeline, &out, threads, &[]),
            )
        },
    )?;
    let runs = options.threads.iter().zip(timings);
    Ok(thread_rows(
        &format!("{} (scaling)", scene.name),
        runs.map(|(&threads, runs)| (threads, runs, work)),
        &options.peak,
        &runner.base(),
    ))
}

/// The peak memory of one EXR frame of `scene` at `(w, h)`, against the
/// film's output buffers.
fn memory_row(runner: &Runner, scene: &BenchScene, (w, h): (u32, u32)) -> Result<Row> {
    runner.log(&format!("memory: {w}x{h} EXR"));
    let out = runner.scratch.join("memory");
    let size = format!("{w}x{h}");
    let args = render_args(
        &scene.timeline,
        &out,
        runner.all_threads,
        &["--size", &size, "--format", "exr", "--frames", "0..1"],
    );
    let m = timed(&runner.exe, &args)?;
    let mut row = timing_row(
        Row {
            scene: format!("{}@{w}x{h} exr", scene.name),
            renderer: "mandelreel".into(),
            threads: runner.all_threads,
            ..runner.base()
        },
        &[m],
        None,
        &runner.options.peak,
    );
    row.frames = 1;
    row.pixels = w as u64 * h as u64;
    row.mpixels_per_s = mpixels_per_s(row.pixels, row.median_s);
    row.output_buffers_mib = row.pixels as f64 * Film::BYTES_PER_PIXEL as f64 / MIB;
    Ok(row)
}

/// Runs the benchmark and writes `<results>/<machine>.csv` and `.md`;
/// returns the Markdown.
pub fn run_and_write(options: &Options) -> Result<String> {
    let rows = run(options)?;
    let peak = &options.peak;
    std::fs::create_dir_all(&options.results).map_err(|e| Error::io(&options.results, e))?;
    let csv = options.results.join(format!("{}.csv", options.machine));
    std::fs::write(&csv, to_csv(&rows)).map_err(|e| Error::io(&csv, e))?;
    let md_text = to_markdown(&rows, peak);
    let md = options.results.join(format!("{}.md", options.machine));
    std::fs::write(&md, &md_text).map_err(|e| Error::io(&md, e))?;
    Ok(md_text)
}
