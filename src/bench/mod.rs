//! `mandelreel bench`: whole renders timed against Mandelbulber2 on the same
//! frames, the distance-estimator kernel measured against the machine's
//! floating-point peak, thread scaling, peak memory and depth error against
//! the accuracy reference (Mandelbulber2's too, from its z-buffer); written
//! to `bench/results/<machine>.csv` and the Markdown tables of docs/performance.md.
//!
//! Every render runs in its own process, timed from spawn to exit (start-up,
//! parsing and PNG encoding included: what a user waits for), under a small
//! `mandelreel measure` wrapper whose only child it is, so the wrapper's
//! `getrusage(RUSAGE_CHILDREN)` is that render's peak resident memory.
//! mandelreel and Mandelbulber2 runs alternate (A B, B A, …) so drift in the
//! machine's speed falls on both alike; medians are reported.

use crate::error::{Error, Result};
use crate::math::Real;
use crate::render::{render_frame_into, Film, FrameStats, Layers};
use crate::timeline::Timeline;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// Floating-point operations in one power-8 orbit iteration of the vector
/// kernel (`Fractal::estimate_lanes`, what rendering runs), counted from the
/// code, with a multiply, add, subtract, divide or square root each one
/// operation (comparisons, min and abs not counted): triplex power 50 (ρ²
/// and r² 5, ρ 1, the axis test 1, ρ⁸ from ρ² 2, its reciprocal 1, the
/// azimuth's cosine and sine scaled by it 2, two complex eighth powers by
/// three squarings of 6 each 36, the output 2); r⁷ 4; running derivative 3;
/// adding c 3; |z|² and |z| 6. The traps reuse |z|² and cost none.
pub const FLOPS_PER_POWER8_ITERATION: u64 = 66;

/// What the bench is asked to do.
#[derive(Clone, Debug)]
pub struct Options {
    /// Folder of benchmark timelines (`timelines/bench`).
    pub scenes: PathBuf,
    /// Folder of the matching Mandelbulber2 settings (`bench/mandelbulber2`).
    pub fract_dir: PathBuf,
    /// The Mandelbulber2 program, when it is to be compared.
    pub mandelbulber: Option<PathBuf>,
    /// A/B pairs per scene, and samples per pool of the in-process
    /// (render only), kernel and ceiling rows.
    pub runs: usize,
    /// Thread counts for the scaling rows (every scene; in-process on the
    /// first; the kernel alone).
    pub threads: Vec<usize>,
    /// Size of the peak-memory render; `None` skips it.
    pub memory_size: Option<(u32, u32)>,
    /// Size of the depth comparison against the accuracy reference; `None` skips it.
    pub depth_size: Option<(u32, u32)>,
    /// Where `<machine>.csv` and `<machine>.md` go.
    pub results: PathBuf,
    pub machine: String,
    /// The machine's peak, detected once for every row.
    pub peak: Peak,
    pub quiet: bool,
}

/// FMA units per core: 2 on current x86 server cores (an assumption; the
/// CPU does not report it).
pub const FMA_UNITS: u32 = 2;

/// The machine's floating-point peak, from what the CPU reports.
#[derive(Clone, Debug)]
pub struct Peak {
    pub cpu: String,
    /// Physical cores: hyper-threads share their core's FMA units.
    pub cores: usize,
    pub clock_ghz: f64,
    /// f64 lanes of the widest vector unit (8 with AVX-512, 4 with AVX2, 2 with SSE2).
    pub lanes: u32,
}

impl Peak {
    /// cores × FMA units × lanes × 2 flops × clock, in GFLOP/s.
    pub fn gflops(&self) -> f64 {
        self.cores as f64 * FMA_UNITS as f64 * self.lanes as f64 * 2.0 * self.clock_ghz
    }

    /// The peak of `threads` threads: one core each, at most every core.
    pub fn gflops_for(&self, threads: usize) -> f64 {
        self.gflops() * threads.min(self.cores) as f64 / self.cores as f64
    }

    /// Reads the CPU model, clock and vector width of this machine.
    pub fn detect() -> Peak {
        let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
        let field = |name: &str| {
            cpuinfo
                .lines()
                .find(|l| l.starts_with(name))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        };
        let clock_ghz = field("cpu MHz")
            .and_then(|v| v.parse::<f64>().ok())
            .map_or(0.0, |mhz| mhz / 1000.0);
        // Distinct (physical id, core id) pairs; logical CPUs where absent.
        let mut core_ids = std::collections::BTreeSet::new();
        let mut physical = "";
        for line in cpuinfo.lines() {
            if let Some((key, value)) = line.split_once(':') {
                match key.trim() {
                    "physical id" => physical = value.trim(),
                    "core id" => {
                        core_ids.insert((physical, value.trim()));
                    }
                    _ => {}
                }
            }
        }
        let logical = std::thread::available_parallelism().map_or(1, |n| n.get());
        let cores = if core_ids.is_empty() {
            logical
        } else {
            core_ids.len().min(logical)
        };
        Peak {
            cpu: field("model name").unwrap_or_else(|| std::env::consts::ARCH.to_string()),
            cores,
            clock_ghz,
            lanes: vector_lanes(),
        }
    }
}

#[cfg(target_arch = "x86_64")]
fn vector_lanes() -> u32 {
    if std::arch::is_x86_feature_detected!("avx512f") {
        8
    } else if std::arch::is_x86_feature_detected!("avx2") {
        4
    } else {
        2
    }
}

#[cfg(not(target_arch = "x86_64"))]
fn vector_lanes() -> u32 {
    2 // 128-bit vectors (NEON and the like)
}

/// One timed process: wall seconds and peak resident memory.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct Measurement {
    pub wall_s: f64,
    pub peak_rss_kib: u64,
    pub exit_code: i32,
}

/// Runs `program args…` as the only child of this process and measures it:
/// the body of the hidden `measure` subcommand.
pub fn measure_child(program: &Path, args: &[String]) -> Result<Measurement> {
    let start = Instant::now();
    let status = Command::new(program)
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .map_err(|e| Error::io(program, e))?;
    let wall_s = start.elapsed().as_secs_f64();
    Ok(Measurement {
        wall_s,
        peak_rss_kib: children_peak_rss_kib(),
        exit_code: status.code().unwrap_or(-1),
    })
}

#[cfg(unix)]
fn children_peak_rss_kib() -> u64 {
    use nix::sys::resource::{getrusage, UsageWho};
    // Linux reports ru_maxrss in KiB.
    getrusage(UsageWho::RUSAGE_CHILDREN).map_or(0, |u| u.max_rss().max(0) as u64)
}

#[cfg(not(unix))]
fn children_peak_rss_kib() -> u64 {
    0
}

/// Times `program args…` through the `measure` wrapper (this executable).
fn timed(program: &Path, args: &[String]) -> Result<Measurement> {
    let exe = std::env::current_exe().map_err(|e| Error::io(Path::new("mandelreel"), e))?;
    let output = Command::new(&exe)
        .arg("measure")
        .arg("--")
        .arg(program)
        .args(args)
        .output()
        .map_err(|e| Error::io(&exe, e))?;
    let text = String::from_utf8_lossy(&output.stdout);
    let m: Measurement = serde_json::from_str(text.trim()).map_err(|e| {
        Error::io(
            &exe,
            std::io::Error::other(format!("measure wrapper: {e}: {text}")),
        )
    })?;
    if m.exit_code != 0 {
        return Err(Error::io(
            program,
            std::io::Error::other(format!(
                "exited with status {} running {}",
                m.exit_code,
                args.join(" ")
            )),
        ));
    }
    Ok(m)
}

/// One benchmark scene: a timeline and, where there is one, its Mandelbulber2 twin.
#[derive(Clone, Debug)]
pub struct BenchScene {
    pub name: String,
    pub timeline: PathBuf,
    pub fract: Option<PathBuf>,
}

/// The timelines in `dir` (sorted by name) with their `.fract` twins in `fract_dir`.
pub fn scenes(dir: &Path, fract_dir: &Path) -> Result<Vec<BenchScene>> {
    let mut found: Vec<BenchScene> = std::fs::read_dir(dir)
        .map_err(|e| Error::io(dir, e))?
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .map(|timeline| {
            let name = timeline
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            let fract = fract_dir.join(format!("{name}.fract"));
            BenchScene {
                name,
                fract: fract.is_file().then_some(fract),
                timeline,
            }
        })
        .collect();
    found.sort_by(|a, b| a.name.cmp(&b.name));
    if found.is_empty() {
        return Err(Error::usage(
            "--scenes",
            format!("no .ron timelines in {}", dir.display()),
        ));
    }
    Ok(found)
}

/// Work one render does, counted by rendering it in this process (the
/// counts do not depend on threads or timing).
#[derive(Clone, Copy, Debug, Default)]
pub struct Work {
    pub frames: u32,
    pub pixels: u64,
    pub stats: FrameStats,
    /// Floating-point operations counted as they were done (the ceiling
    /// loop's); where `None`, the DE iterations' (`flops`).
    pub counted_flops: Option<u64>,
}

impl Work {
    /// The floating-point operations done: those counted, or else
    /// `FLOPS_PER_POWER8_ITERATION` for each DE iteration.
    pub fn flops(&self) -> u64 {
        self.counted_flops
            .unwrap_or(self.stats.de_iterations * FLOPS_PER_POWER8_ITERATION)
    }
}

/// Renders every frame of `timeline` at `size` in this process, keeping only the counts.
pub fn count_work(timeline: &Timeline, size: (u32, u32)) -> Work {
    let mut stats = FrameStats::default();
    let mut film = Film::default();
    for frame in 0..timeline.frame_count {
        let scenes = timeline.scenes_for_frame(frame);
        let (w, h) = size;
        render_frame_into(&mut film, &scenes, frame, w, h, Layers::default(), &|| {});
        stats = stats + film.stats;
    }
    Work {
        frames: timeline.frame_count,
        pixels: size.0 as u64 * size.1 as u64 * timeline.frame_count as u64,
        stats,
        counted_flops: None,
    }
}

/// One row of results.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Row {
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
fn alternate<T>(
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

const MIB: f64 = 1024.0 * 1024.0;

/// Fills the timing columns of `row` from `runs`, and the rates from `work`.
fn timing_row(mut row: Row, runs: &[Measurement], work: Option<&Work>, peak: &Peak) -> Row {
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

fn mpixels_per_s(pixels: u64, seconds: f64) -> f64 {
    pixels as f64 / seconds.max(1e-9) / 1e6
}

fn log(quiet: bool, message: &str) {
    if !quiet {
        eprintln!("{message}");
    }
}

/// The arguments of a mandelreel render of `scene` into `out`.
fn render_args(timeline: &Path, out: &Path, threads: usize, extra: &[&str]) -> Vec<String> {
    let mut args: Vec<String> = vec![
        "render".into(),
        timeline.display().to_string(),
        "--out".into(),
        out.display().to_string(),
        "--force".into(),
        "--quiet".into(),
        "--threads".into(),
        threads.to_string(),
    ];
    args.extend(extra.iter().map(|s| s.to_string()));
    args
}

/// The arguments of a Mandelbulber2 render of `fract` into `out` (a folder).
fn mandelbulber_args(fract: &Path, out: &Path, keyframed: bool) -> Vec<String> {
    let mut args: Vec<String> = vec!["-n".into(), "-C".into()];
    if keyframed {
        args.push("-K".into());
    }
    let target = if keyframed {
        format!("{}/", out.display())
    } else {
        out.join("frame.png").display().to_string()
    };
    args.extend([
        "-f".into(),
        "png".into(),
        "-o".into(),
        target,
        "-O".into(),
        "opencl_enabled=0".into(),
        fract.display().to_string(),
    ]);
    args
}

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
pub fn run(options: &Options) -> Result<Vec<Row>> {
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

/// The timeline of `scene`, and the work of rendering it at its size.
fn load_counted(scene: &BenchScene) -> Result<(Timeline, Work)> {
    let timeline = Timeline::load(&scene.timeline)?;
    let work = count_work(&timeline, (timeline.width, timeline.height));
    Ok((timeline, work))
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

/// Frame 0 of `timeline` rendered in this process on each of `pools`
/// (`thread_pools` of `options.threads`), alternating, medians over
/// `options.runs`.
fn render_only_rows(
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
fn thread_pools(threads: &[usize]) -> Result<Vec<(usize, rayon::ThreadPool)>> {
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
fn pool_rows(
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
fn thread_rows<'w>(
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

/// What Mandelbulber2 writes for a pixel whose ray met nothing.
const MANDELBULBER_NO_HIT: u16 = u16::MAX;

/// Mandelbulber2's 16-bit z-buffer (`<name>_zbuffer.png`) as values in 0..1
/// (its log(z / z_min) / log(z_max / z_min)), `None` where its ray missed.
/// The file keeps no z_min or z_max, so absolute depths need `fit_log_depths`.
pub fn read_mandelbulber_zbuffer(path: &Path) -> Result<(u32, u32, Vec<Option<f64>>)> {
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let bad = |why: String| Error::Image {
        path: path.to_path_buf(),
        message: why,
    };
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .map_err(|e| bad(e.to_string()))?;
    let info = reader.info();
    if info.color_type != png::ColorType::Grayscale || info.bit_depth != png::BitDepth::Sixteen {
        return Err(bad("not a 16-bit greyscale z-buffer".into()));
    }
    let (w, h) = (info.width, info.height);
    let mut bytes = vec![0; reader.output_buffer_size().unwrap_or(0)];
    reader
        .next_frame(&mut bytes)
        .map_err(|e| bad(e.to_string()))?;
    let values = bytes
        .chunks_exact(2)
        .map(|b| u16::from_be_bytes([b[0], b[1]]))
        .map(|v| (v != MANDELBULBER_NO_HIT).then_some(v as f64 / 60000.0))
        .collect();
    Ok((w, h, values))
}

/// Absolute depths for Mandelbulber2's log-scaled z-buffer values: the
/// least-squares line ln(depth) = a + b·value through the pixels where it
/// and the reference both hit. The most favourable scaling there is, so the
/// error left over is a lower bound on Mandelbulber2's. `cos` per pixel turns
/// distance along the ray into distance along the view axis (all 1 for
/// distances along the ray); the fit is made in that measure and the result
/// given along the ray. Returns the depths and the fit's mean squared residual.
pub fn fit_log_depths(
    values: &[Option<f64>],
    reference: &[Option<Real>],
    cos: &[Real],
) -> (Vec<Option<Real>>, f64) {
    let pairs: Vec<(f64, f64)> = values
        .iter()
        .zip(reference)
        .zip(cos)
        .filter_map(|((v, r), c)| Some((v.as_ref()?, r.as_ref()?, c)))
        .map(|(&v, &r, &c)| (v, (r * c).ln()))
        // A hit at distance 0 (a camera inside the set) has no logarithm.
        .filter(|(v, l)| v.is_finite() && l.is_finite())
        .collect();
    let n = pairs.len().max(1) as f64;
    let (mx, my) = pairs
        .iter()
        .fold((0.0, 0.0), |(x, y), (v, l)| (x + v / n, y + l / n));
    let (sxy, sxx) = pairs.iter().fold((0.0, 0.0), |(xy, xx), (v, l)| {
        (xy + (v - mx) * (l - my), xx + (v - mx) * (v - mx))
    });
    let b = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    let a = my - b * mx;
    let residual = pairs
        .iter()
        .map(|(v, l)| (a + b * v - l).powi(2))
        .sum::<f64>()
        / n;
    let depths = values
        .iter()
        .zip(cos)
        .map(|(v, c)| v.map(|v| (a + b * v).exp() / c))
        .collect();
    (depths, residual)
}

/// The membership walk step whose depth error `bench` reports.
const WALK_STEP: Real = 0.25;

/// Depth rows for the first scene at `size`: mandelreel's frame, and
/// Mandelbulber2's z-buffer where it is installed, against the membership
/// reference of the accuracy sweep.
fn depth_rows(
    scene: &BenchScene,
    timeline: &Timeline,
    options: &Options,
    (w, h): (u32, u32),
    out: &Path,
    base: Row,
) -> Result<Vec<Row>> {
    use crate::accuracy::{depth_errors, film_hits, footprints_at, reference_depths};
    let frame = timeline.scene_at(0);
    let reference_scene = crate::accuracy::reference_scene(&frame);
    let (reference, _) = reference_depths(&reference_scene, w, h, crate::accuracy::REFERENCE_STEP);
    let footprints = footprints_at(&frame, w, h, &reference);
    let row = |renderer: &str, e: crate::accuracy::DepthErrors| Row {
        scene: format!("{} depth@{w}x{h}", scene.name),
        renderer: renderer.into(),
        frames: 1,
        pixels: w as u64 * h as u64,
        depth_error_mean_px: Some(e.mean_px),
        depth_error_p99_px: Some(e.p99_px),
        hit_mismatch: Some(e.hit_mismatch),
        ..base.clone()
    };
    let film = crate::render::render_frame(&frame, 0, w, h, &|| {});
    let hits = film_hits(&film);
    // The same fit as Mandelbulber2's gets (a line through ln depth is a
    // line through its log-scaled values), to compare like with like.
    let ln_hits: Vec<Option<f64>> = hits.iter().map(|t| t.map(f64::ln)).collect();
    let (fitted, _) = fit_log_depths(&ln_hits, &reference, &vec![1.0; hits.len()]);
    let mut rows = vec![
        row("mandelreel", depth_errors(&hits, &reference, &footprints)),
        row(
            "mandelreel (fitted)",
            depth_errors(&fitted, &reference, &footprints),
        ),
    ];
    // The membership walk, for its error beside the estimate's (its cost
    // is in `mandelreel accuracy`'s table).
    let mut walking = frame.clone();
    walking.quality.membership_step = WALK_STEP;
    let walked = film_hits(&crate::render::render_frame(&walking, 0, w, h, &|| {}));
    rows.push(row(
        &format!("mandelreel (membership_step {WALK_STEP})"),
        depth_errors(&walked, &reference, &footprints),
    ));
    let (Some(program), Some(fract)) = (&options.mandelbulber, &scene.fract) else {
        return Ok(rows);
    };
    let status = Command::new(program)
        .args(["-n", "-C", "-f", "png", "-r", &format!("{w}x{h}"), "-o"])
        .arg(out.join("depth"))
        .args(["-O", "opencl_enabled=0#zbuffer_enabled=1"])
        .arg(fract)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .map_err(|e| Error::io(program, e))?;
    let zbuffer = out.join("depth_zbuffer.png");
    if !status.success() || !zbuffer.exists() {
        log(
            options.quiet,
            "depth: Mandelbulber2 wrote no z-buffer; its depth row is left out",
        );
        return Ok(rows);
    }
    let (zw, zh, values) = match read_mandelbulber_zbuffer(&zbuffer) {
        Ok(read) => read,
        Err(e) => {
            log(
                options.quiet,
                &format!("depth: {e}; Mandelbulber2's depth row is left out"),
            );
            return Ok(rows);
        }
    };
    if (zw, zh) != (w, h) {
        log(
            options.quiet,
            &format!("depth: Mandelbulber2's z-buffer is {zw}x{zh}, not {w}x{h}"),
        );
        return Ok(rows);
    }
    // Its z may be distance along the ray or along the view axis: fit both,
    // keep the one that fits better.
    let camera = frame.camera.frame();
    let along_axis: Vec<Real> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            camera
                .ray(x as Real + 0.5, y as Real + 0.5, w, h)
                .dir
                .dot(camera.forward)
        })
        .collect();
    let along_ray = vec![1.0; along_axis.len()];
    let (ray_fit, ray_residual) = fit_log_depths(&values, &reference, &along_ray);
    let (axis_fit, axis_residual) = fit_log_depths(&values, &reference, &along_axis);
    let depths = if axis_residual < ray_residual {
        axis_fit
    } else {
        ray_fit
    };
    rows.push(row(
        "mandelbulber2 (fitted)",
        depth_errors(&depths, &reference, &footprints),
    ));
    Ok(rows)
}

/// Measures DE iterations per second of the analytic estimator at points on
/// a shell just outside the bulb of `timeline`'s first frame (where the
/// marcher spends most of its estimates), on a pool of each size in
/// `options.threads`, alternating: the kernel's own thread scaling, with no
/// start-up, scheduling of rows or file writing in it.
pub fn kernel_rows(
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

/// The scene name of the machine's own ceiling rows (`ceiling_rows`).
pub const CEILING: &str = "fma ceiling";

/// The scene name of the kernel's rows (`kernel_rows`).
pub const KERNEL: &str = "kernel";

/// Independent chains in the ceiling loop: more than the 8 that two FMA
/// units of 4 cycles' latency need to stay busy, few enough to stay in
/// registers (16 with AVX2, 32 with AVX-512).
const CEILING_CHAINS: usize = 12;

/// The multiplier of each chain's `acc ← acc·m + 1`: below 1, so every
/// chain tends to 1 / (1 − m) = 1024 and stays a normal number.
const CEILING_FACTOR: f64 = 1.0 - 1.0 / 1024.0;

/// `rounds` rounds of `CEILING_CHAINS` fused multiply-adds on the widest
/// f64 vectors this processor has (pulp's choice, as the kernel's), with
/// nothing but registers: the most floating-point work a core of this
/// machine does, measured rather than assumed. Returns the sum of every
/// chain's lanes (chain k's each `k·mʳ + (1 − mʳ) / (1 − m)`) and the
/// flops done (2 per lane per fused multiply-add).
pub fn fma_ceiling(rounds: u64) -> (f64, u64) {
    pulp::Arch::new().dispatch(Ceiling { rounds })
}

struct Ceiling {
    rounds: u64,
}

impl pulp::WithSimd for Ceiling {
    type Output = (f64, u64);

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) -> (f64, u64) {
        let (m, one) = (simd.splat_f64s(CEILING_FACTOR), simd.splat_f64s(1.0));
        // Chain k starts at k: no two chains alike, so none can be merged.
        let mut chains: [S::f64s; CEILING_CHAINS] =
            std::array::from_fn(|k| simd.splat_f64s(k as f64));
        for _ in 0..std::hint::black_box(self.rounds) {
            for c in &mut chains {
                *c = simd.mul_add_f64s(*c, m, one);
            }
        }
        let sum = chains.iter().map(|&c| simd.reduce_sum_f64s(c)).sum();
        let flops = self.rounds * (CEILING_CHAINS * S::F64_LANES * 2) as u64;
        (sum, flops)
    }
}

/// The machine's ceiling on each of `pools`: `fma_ceiling` on every thread
/// of the pool at once, the same rounds shared among them, alternating
/// between pools, medians over `options.runs` samples of about 0.2 s on
/// the widest pool. Each row's GFLOP/s is what the loop did, its share of
/// the peak the nominal peak of its threads, its speed-up over the
/// one-thread pool the machine's own thread scaling: what the kernel's and
/// the renders' figures can be held against.
pub fn ceiling_rows(
    pools: &[(usize, rayon::ThreadPool)],
    options: &Options,
    base: Row,
) -> Vec<Row> {
    // `rounds` shared among the pool's threads: the flops done.
    let pass = |pool: &rayon::ThreadPool, rounds: u64| -> u64 {
        let share = rounds.div_ceil(pool.current_num_threads() as u64);
        let done = pool.broadcast(|_| fma_ceiling(share));
        std::hint::black_box(done.iter().map(|d| d.0).sum::<f64>());
        done.iter().map(|d| d.1).sum()
    };
    let (_, walls, flops) = sampled_passes(pools, options, (1 << 16, 1 << 22), pass);
    let works: Vec<Work> = flops
        .into_iter()
        .map(|flops| Work {
            counted_flops: Some(flops),
            ..Work::default()
        })
        .collect();
    pool_rows(CEILING, pools, walls, &works, &options.peak, base)
}

/// `pass(pool, amount)` timed on each of `pools`, as the kernel's and the
/// ceiling's rows time it: `warm` on every pool first (its threads started,
/// its data in cache); then `trial` on the widest pool, scaled to the
/// amount that lasts about 0.2 s there (longer on fewer threads); then
/// `options.runs` samples of that amount on each pool, alternating, each
/// sample one call of `pass`. The amount, each pool's wall times, and what
/// its last sample returned.
fn sampled_passes<R: Default + Clone>(
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

/// The rows as CSV, one header line first.
pub fn to_csv(rows: &[Row]) -> String {
    crate::output::csv::csv_text(rows)
}

/// The Markdown tables of docs/performance.md, made from the rows.
pub fn to_markdown(rows: &[Row], peak: &Peak) -> String {
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

/// A file-name-safe default machine name: cores, CPU model and vector
/// width, so two machines that report one model name (AMD EPYCs with and
/// without AVX-512) keep their results apart.
pub fn default_machine_name(peak: &Peak) -> String {
    let model: String = peak
        .cpu
        .to_lowercase()
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect();
    let model = model
        .split('-')
        .filter(|s| !s.is_empty() && *s != "r" && *s != "tm")
        .collect::<Vec<_>>()
        .join("-");
    let width = match peak.lanes {
        8 => "avx512",
        4 => "avx2",
        _ if cfg!(target_arch = "x86_64") => "sse",
        lanes => return format!("{}core-{model}-{lanes}lane", peak.cores),
    };
    format!("{}core-{model}-{width}", peak.cores)
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
    fn a_mandelbulber_zbuffer_fits_back_to_its_depths() {
        // Depths written as Mandelbulber2 writes them (log-scaled between
        // their minimum and maximum, ×60000, 65535 for a miss) come back
        // through the fit to within the 16-bit steps; a wrong scale would not.
        let truth: Vec<Option<Real>> = (0..64)
            .map(|i| (i % 7 != 3).then(|| 1.3 + 0.9 * ((i * 37 % 64) as Real / 63.0)))
            .collect();
        let (lo, hi) = (1.3_f64, 2.2_f64);
        let words: Vec<u16> = truth
            .iter()
            .map(|t| match t {
                Some(z) => ((z / lo).ln() / (hi / lo).ln() * 60000.0) as u16,
                None => MANDELBULBER_NO_HIT,
            })
            .collect();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x_zbuffer.png");
        let mut encoder = png::Encoder::new(std::fs::File::create(&path).unwrap(), 8, 8);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Sixteen);
        let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_be_bytes()).collect();
        let mut writer = encoder.write_header().unwrap();
        writer.write_image_data(&bytes).unwrap();
        writer.finish().unwrap();
        let (w, h, values) = read_mandelbulber_zbuffer(&path).unwrap();
        assert_eq!((w, h), (8, 8));
        assert_eq!(values.iter().filter(|v| v.is_none()).count(), 9);
        let ones = vec![1.0; 64];
        let (depths, residual) = fit_log_depths(&values, &truth, &ones);
        assert!(residual < 1e-8, "{residual}");
        for (d, t) in depths.iter().zip(&truth) {
            match (d, t) {
                (Some(d), Some(t)) => assert!((d / t - 1.0).abs() < 1e-4, "{d} vs {t}"),
                (None, None) => {}
                _ => panic!("hit and miss differ"),
            }
        }
        // Measured along the view axis, the right cosines fit as well and
        // give back distances along the ray.
        let cos: Vec<Real> = (0..64).map(|i| 0.8 + 0.003 * i as Real).collect();
        let axial: Vec<Option<f64>> = truth
            .iter()
            .zip(&cos)
            .map(|(t, c)| {
                t.map(|t| ((t * c / lo).ln() / (hi / lo).ln() * 60000.0).floor() / 60000.0)
            })
            .collect();
        let (depths, residual) = fit_log_depths(&axial, &truth, &cos);
        assert!(residual < 1e-8, "{residual}");
        let (_, wrong) = fit_log_depths(&axial, &truth, &ones);
        assert!(wrong > 100.0 * residual, "{wrong} vs {residual}");
        for (d, t) in depths
            .iter()
            .zip(&truth)
            .filter_map(|(d, t)| Some((d.as_ref()?, t.as_ref()?)))
        {
            assert!((d / t - 1.0).abs() < 1e-4, "{d} vs {t}");
        }
    }

    #[test]
    fn peak_is_the_product_of_its_factors() {
        let p = Peak {
            cpu: "test".into(),
            cores: 2,
            clock_ghz: 2.5,
            lanes: 4,
        };
        assert_eq!(p.gflops(), 2.0 * 2.0 * 4.0 * 2.0 * 2.5);
        // More threads than cores get no more peak.
        assert_eq!(p.gflops_for(1), p.gflops() / 2.0);
        assert_eq!(p.gflops_for(8), p.gflops());
        assert_eq!(default_machine_name(&p), "2core-test-avx2");
        let wide = Peak { lanes: 8, ..p };
        assert_eq!(default_machine_name(&wide), "2core-test-avx512");
    }

    #[test]
    fn the_ceiling_loop_does_the_work_it_counts() {
        // Two flops per lane of each chain's fused multiply-add, each round.
        let per_round = (CEILING_CHAINS * 2) as u64;
        let lanes = fma_ceiling(1).1 / per_round;
        for rounds in [0, 1, 7, 5000] {
            let (sum, flops) = fma_ceiling(rounds);
            assert_eq!(flops, rounds * per_round * lanes);
            assert!([1, 2, 4, 8].contains(&lanes), "{lanes} lanes");
            // As wide as the peak counts (`Peak::lanes`).
            assert_eq!(lanes, vector_lanes() as u64);
            // Each lane of chain k: its start k shrunk by mʳ, plus the
            // geometric series 1 + m + … + mʳ⁻¹.
            let m = CEILING_FACTOR;
            let mr = m.powi(rounds as i32);
            let series = (1.0 - mr) / (1.0 - m);
            let chains: f64 = (0..CEILING_CHAINS).map(|k| k as f64 * mr + series).sum();
            let expected = chains * lanes as f64;
            let tolerance = 1e-9 * expected;
            assert!(
                (sum - expected).abs() <= tolerance,
                "{rounds}: {sum} vs {expected}"
            );
        }
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // The loop runs on vectors as wide as the peak assumes.
            let (_, flops) = fma_ceiling(1);
            assert!(flops / (CEILING_CHAINS as u64 * 2) >= 4);
        }
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
