//! The command line: clap arguments checked into a job before any pixel is
//! rendered, the subcommands (`render`, `info`, `pick`, `sheet`, `status`,
//! `accuracy`, `bench`), progress bars, and exit codes.

use crate::error::{Error, Result};
use crate::march::{march, normal};
use crate::output::{self, Format};
use crate::render::FrameStats;
use crate::timeline::{Timeline, Track, ZOOM_TRACK};
use clap::{Parser, Subcommand};
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use serde::Serialize;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// `println!` that returns an error instead of panicking when standard
/// output is gone (`mandelreel info t.ron | head`): `OutputClosed`, which
/// `run` turns into a quiet success.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout(), $($arg)*).map_err(stdout_error)?
    }};
}

/// Standard output was closed by its reader (`| head`): the command stops
/// there, with no message and exit code 0, as a command killed by the
/// broken pipe would have printed nothing more either.
#[derive(Debug, thiserror::Error)]
#[error("standard output was closed")]
struct OutputClosed;

/// `OutputClosed` for a broken pipe; any other failure to write is an error.
fn stdout_error(error: std::io::Error) -> anyhow::Error {
    if error.kind() == std::io::ErrorKind::BrokenPipe {
        OutputClosed.into()
    } else {
        anyhow::Error::new(error).context("cannot write to standard output")
    }
}

/// Exit status: success.
pub const EXIT_OK: u8 = 0;
/// Exit status: the work failed (a file could not be read or written).
pub const EXIT_FAILURE: u8 = 1;
/// Exit status: a command-line argument is wrong (clap uses 2 as well).
pub const EXIT_USAGE: u8 = 2;
/// Exit status: the timeline is malformed or invalid.
pub const EXIT_INVALID_TIMELINE: u8 = 3;
/// Exit status of `status`: the sequence is not complete yet.
pub const EXIT_INCOMPLETE: u8 = 4;

#[derive(Debug, Parser)]
#[command(
    name = "mandelreel",
    version,
    about = "Render keyframed Mandelbulb timelines (RON) to numbered PNG/EXR frames",
    after_help = "Exit status: 0 success, 1 failure (I/O), 2 bad command-line argument, 3 invalid timeline,\n\
                  4 (status only) the sequence is not complete; a render stopped by Ctrl-C or SIGTERM\n\
                  cleans up, says what is done and ends by that signal (130 or 143 in a shell).\n\
                  Timeline format and examples: README.md and timelines/*.ron."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Render a timeline to numbered frames, skipping frames already complete and current.
    Render(RenderArgs),
    /// Validate a timeline and print its frames, duration, tracks and effects.
    Info {
        /// The RON timeline file.
        timeline: PathBuf,
    },
    /// Print the world-space point that the ray through one pixel hits.
    Pick(PickArgs),
    /// Tile rendered PNG frames from a folder into one contact-sheet image.
    Sheet(SheetArgs),
    /// Which frames of a sequence are complete, stale, missing or in progress; exit
    /// status 0 only when every frame is complete and current (4 otherwise).
    Status(StatusArgs),
    /// Measure what accuracy costs: sweep every quality knob, distance estimator and
    /// precision on one frame against a reference; write accuracy.csv, .md and .png.
    Accuracy(AccuracyArgs),
    /// Time the benchmark scenes (timelines/bench) against Mandelbulber2 where it is
    /// installed, measure the kernel against the FMA peak and the machine's own
    /// measured ceiling, thread scaling and peak memory; write
    /// bench/results/<machine>.csv and .md.
    Bench(BenchArgs),
    /// Run a program and print its wall time and peak memory as JSON (used by `bench`).
    #[command(hide = true)]
    Measure {
        program: PathBuf,
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
}

#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    /// Folder of benchmark timelines.
    #[arg(long, default_value = "timelines/bench")]
    pub scenes: PathBuf,
    /// Folder of the matching Mandelbulber2 settings files (<timeline name>.fract).
    #[arg(long, default_value = "bench/mandelbulber2")]
    pub fract_dir: PathBuf,
    /// The Mandelbulber2 program; compared only if it runs.
    #[arg(long, default_value = "mandelbulber2")]
    pub mandelbulber: PathBuf,
    /// Skip Mandelbulber2 even if it is installed.
    #[arg(long)]
    pub no_mandelbulber: bool,
    /// Runs of each renderer per scene, and samples per thread count of the
    /// in-process, kernel and ceiling rows (alternating); medians are reported.
    #[arg(long, default_value_t = 5)]
    pub runs: usize,
    /// Thread counts for the scaling rows, comma-separated [default: 1, 2, 4, … up to every logical CPU].
    #[arg(long, value_delimiter = ',')]
    pub threads: Vec<usize>,
    /// Size of the peak-memory EXR render, or `none` to skip it.
    #[arg(long, default_value = "3840x2160")]
    pub memory_size: String,
    /// Size of the depth comparison against the accuracy reference (first scene), or `none`.
    #[arg(long, default_value = "160x120")]
    pub depth_size: String,
    /// Folder for <machine>.csv and <machine>.md.
    #[arg(long, default_value = "bench/results")]
    pub results: PathBuf,
    /// Name of this machine in the results [default: cores and CPU model].
    #[arg(long)]
    pub machine: Option<String>,
    /// No progress lines; the table is still printed.
    #[arg(long, short)]
    pub quiet: bool,
}

#[derive(Debug, clap::Args)]
pub struct AccuracyArgs {
    /// The RON timeline file.
    pub timeline: PathBuf,
    /// Frame to measure.
    #[arg(long, default_value_t = 0)]
    pub frame: u32,
    /// Size to measure at [default: the timeline's aspect, 160 pixels wide at most].
    #[arg(long, value_name = "WxH")]
    pub size: Option<String>,
    /// Override the timeline's samples_per_pixel for the scene measured.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub samples: Option<u32>,
    /// Folder for accuracy.csv, accuracy.md and accuracy.png [default: out/<timeline name>].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Worker threads [default: all cores].
    #[arg(long)]
    pub threads: Option<usize>,
    /// No progress lines; the table is still printed.
    #[arg(long, short)]
    pub quiet: bool,
}

#[derive(Debug, clap::Args)]
pub struct SheetArgs {
    /// Folder holding frame_NNNNN.png files.
    pub dir: PathBuf,
    /// Number of frames to show, evenly spaced over the sequence (first and last included).
    #[arg(long, default_value_t = 12)]
    pub count: usize,
    /// Thumbnails per row.
    #[arg(long, default_value_t = 4)]
    pub columns: u32,
    /// Width of each thumbnail in pixels.
    #[arg(long, default_value_t = 240)]
    pub thumb_width: u32,
    /// Where to write the sheet [default: <dir>/sheet.png].
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// What a sequence is made of: shared by `render` and `status`, so both
/// compute the same frames and hashes.
#[derive(Debug, clap::Args)]
pub struct SequenceArgs {
    /// Output folder [default: out/<timeline name>].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Frames, as a Rust range: 0..4 is frames 0 to 3, 0..=4 frames 0 to 4; also A.., ..B, or N.
    #[arg(long, value_name = "A..B")]
    pub frames: Option<String>,
    /// Override the timeline's output size (nothing else is scaled).
    #[arg(long, value_name = "WxH")]
    pub size: Option<String>,
    /// Output formats, comma-separated [default: png].
    #[arg(long, value_enum, value_delimiter = ',')]
    pub format: Vec<Format>,
    /// Quick look: half width and height, one sample per pixel, in <out>/preview.
    #[arg(long)]
    pub preview: bool,
    /// Override the timeline's samples_per_pixel: anti-aliasing for a final
    /// (4 or 9 takes the flicker out of fine detail; time grows with it).
    #[arg(long, value_name = "N", conflicts_with = "preview",
          value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub samples: Option<u32>,
    /// Extra EXR layers, comma-separated (needs --format exr): normal, albedo, traps, steps.
    #[arg(long, value_enum, value_delimiter = ',')]
    pub aov: Vec<output::Aov>,
}

#[derive(Debug, clap::Args)]
pub struct RenderArgs {
    /// The RON timeline file.
    pub timeline: PathBuf,
    #[command(flatten)]
    pub sequence: SequenceArgs,
    /// Worker threads [default: all cores]. The image does not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Render every frame even if a current one exists (implies --replace).
    #[arg(long)]
    pub force: bool,
    /// Render into a folder that holds another timeline's (by file name) or
    /// another size's frames, replacing them; without it that is refused.
    #[arg(long)]
    pub replace: bool,
    /// No progress bars or summary; errors (and --stats, if asked) still go to stderr.
    #[arg(long, short)]
    pub quiet: bool,
    /// Print distance-estimator evaluations per frame and in total.
    #[arg(long)]
    pub stats: bool,
    /// Render only shard I of N: frames I, I+N, I+2N, … (`auto` takes I and N from
    /// Slurm's SLURM_ARRAY_TASK_ID/_MIN/_COUNT or Kubernetes' JOB_COMPLETION_INDEX
    /// with MANDELREEL_SHARD_COUNT).
    #[arg(long, value_name = "I/N|auto", conflicts_with = "claim")]
    pub shard: Option<String>,
    /// Share the frames with any number of other `--claim` workers on the same
    /// output folder, taking one frame at a time through claim files (with
    /// --force, each worker makes a single pass over the frames).
    #[arg(long)]
    pub claim: bool,
    /// Seconds without a heartbeat after which another worker takes a claimed frame over.
    #[arg(long, default_value = "300", value_name = "SECONDS", value_parser = positive_seconds)]
    pub claim_timeout: std::time::Duration,
    /// Read every byte of each finished frame before skipping it (as `status
    /// --verify`); frames found damaged are rendered again.
    #[arg(long)]
    pub verify: bool,
    /// Frames of several sample waves save their progress this often, so a killed
    /// render resumes them mid-frame (0 = after every wave).
    #[arg(long, default_value = "60", value_name = "SECONDS", value_parser = any_seconds)]
    pub checkpoint_seconds: std::time::Duration,
}

#[derive(Debug, clap::Args)]
pub struct StatusArgs {
    /// An output folder (uses what it records), or a timeline (with the same
    /// --out, --size, --format, --aov, --samples, --frames and --preview as its render).
    pub target: PathBuf,
    #[command(flatten)]
    pub sequence: SequenceArgs,
    /// Seconds without a heartbeat after which a claim counts as abandoned.
    #[arg(long, default_value = "300", value_name = "SECONDS", value_parser = positive_seconds)]
    pub claim_timeout: std::time::Duration,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Read every byte of each finished frame (every PNG chunk's CRC, every
    /// EXR chunk), not only its header and end: finds a damaged byte inside
    /// a PNG, at the cost of reading the whole sequence.
    #[arg(long)]
    pub verify: bool,
}

#[derive(Debug, clap::Args)]
pub struct PickArgs {
    /// The RON timeline file.
    pub timeline: PathBuf,
    /// Frame whose camera and fractal are used.
    #[arg(long, default_value_t = 0)]
    pub frame: u32,
    /// Pixel column and row, from the top-left corner.
    #[arg(long, value_name = "X,Y")]
    pub pixel: String,
    /// Image size the pixel refers to [default: the timeline's].
    #[arg(long, value_name = "WxH")]
    pub size: Option<String>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Exit code for an error chain: input errors are the user's to fix.
pub fn exit_code(error: &anyhow::Error) -> u8 {
    if error.is::<Incomplete>() {
        return EXIT_INCOMPLETE;
    }
    match error.downcast_ref::<Error>() {
        Some(Error::Usage { .. }) => EXIT_USAGE,
        Some(e) if e.is_input_error() => EXIT_INVALID_TIMELINE,
        _ => EXIT_FAILURE,
    }
}

pub fn run(cli: Cli) -> anyhow::Result<()> {
    let result = match cli.command {
        Command::Render(args) => render(args),
        Command::Info { timeline } => info(&timeline),
        Command::Pick(args) => pick(args),
        Command::Sheet(args) => sheet(args),
        Command::Status(args) => status(args),
        Command::Accuracy(args) => accuracy(args),
        Command::Bench(args) => bench(args),
        Command::Measure { program, args } => measure(&program, &args),
    };
    // `status` has already turned a closed output into its exit status.
    unless_output_closed(result)
}

/// `result`, except that a reader that went away (`OutputClosed`) ends the
/// command quietly, as success.
fn unless_output_closed(result: anyhow::Result<()>) -> anyhow::Result<()> {
    match result {
        Err(error) if error.is::<OutputClosed>() => Ok(()),
        other => other,
    }
}

fn measure(program: &Path, args: &[String]) -> anyhow::Result<()> {
    let m = crate::bench::measure_child(program, args)?;
    out!(
        "{}",
        serde_json::to_string(&m).expect("a measurement serialises")
    );
    Ok(())
}

/// Parses `WxH`.
pub fn parse_size(option: &str, text: &str) -> Result<(u32, u32)> {
    let bad = || {
        Error::usage(
            option,
            format!("expected WIDTHxHEIGHT such as 640x360, got {text:?}"),
        )
    };
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    );
    if w == 0 || h == 0 || w > 32_768 || h > 32_768 {
        return Err(Error::usage(
            option,
            format!("width and height must be 1..=32768, got {text:?}"),
        ));
    }
    Ok((w, h))
}

/// Parses a frame range (`A..B`, `A..=B`, `A..`, `..B`, `..=B` or `N`) against `count` frames.
pub fn parse_frames(text: &str, count: u32) -> Result<std::ops::Range<u32>> {
    let bad = |why: String| Error::usage("--frames", why);
    let number = |s: &str, default: u32| -> Result<u32> {
        if s.trim().is_empty() {
            Ok(default)
        } else {
            s.trim().parse().map_err(|_| {
                let hint = if s.contains('-') && !s.trim().starts_with('-') {
                    format!(
                        " (a range is written with two dots: {})",
                        s.replacen('-', "..", 1)
                    )
                } else {
                    String::new()
                };
                bad(format!("{s:?} is not a frame number{hint}"))
            })
        }
    };
    let range = match text.split_once("..") {
        // A..=B, as Rust writes an inclusive range: frames A to B.
        Some((a, b)) if b.starts_with('=') => {
            let last = b[1..].trim();
            if last.is_empty() {
                return Err(bad(format!("{text:?} needs a last frame after ..=")));
            }
            number(a, 0)?..number(last, 0)?.saturating_add(1)
        }
        Some((a, b)) => number(a, 0)?..number(b, count)?,
        None => {
            let n = number(text, 0)?;
            n..n.saturating_add(1)
        }
    };
    if range.start >= range.end {
        return Err(bad(format!(
            "{text:?} is empty (0..4 is frames 0 to 3, 0..=4 frames 0 to 4)"
        )));
    }
    if range.end > count {
        return Err(bad(format!(
            "{text:?} goes past the last frame: the timeline has {count} frames, 0..{count}"
        )));
    }
    Ok(range)
}

/// Quotes a path for a POSIX shell when it needs it.
fn shell_quote(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "/._-+%:=,".contains(c))
    {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// The ffmpeg command that encodes frames `range` in `dir` as an MP4.
pub fn ffmpeg_command(
    dir: &Path,
    name: &str,
    fps: f64,
    range: &std::ops::Range<u32>,
    format: Format,
) -> String {
    // ffmpeg reads `%` in an image sequence's name as a pattern: a folder's
    // own `%` is written `%%`.
    let input = Path::new(&dir.to_string_lossy().replace('%', "%%"))
        .join(output::frames::frame_pattern(format));
    let movie = dir.join(format!("{name}.mp4"));
    // EXR frames are linear light; ask ffmpeg to apply the sRGB curve.
    let trc = if format == Format::Exr {
        "-apply_trc iec61966_2_1 "
    } else {
        ""
    };
    format!(
        "ffmpeg -y -framerate {fps} -start_number {start} {trc}-i {input} -frames:v {count} \
         -vf 'pad=ceil(iw/2)*2:ceil(ih/2)*2' -c:v libx264 -pix_fmt yuv420p -crf 18 {movie}",
        start = range.start,
        count = range.end - range.start,
        input = shell_quote(&input.to_string_lossy()),
        movie = shell_quote(&movie.to_string_lossy()),
    )
}

/// A validated render job: what to render, how big, in which formats, where.
#[derive(Clone)]
struct Plan {
    timeline: Timeline,
    width: u32,
    height: u32,
    range: std::ops::Range<u32>,
    formats: Vec<Format>,
    out_dir: PathBuf,
    preview: bool,
    aovs: Vec<output::Aov>,
    /// `--samples`, applied to the timeline's scene (and recorded).
    samples: Option<u32>,
    /// `--verify`: frame files are read to their last byte before they
    /// count as complete (`output::frames::file_state`).
    verify: bool,
}

impl Plan {
    /// Checks every option; touches nothing on disk.
    fn new(timeline_path: &Path, args: &SequenceArgs) -> anyhow::Result<Plan> {
        let timeline = Timeline::load(timeline_path)?;
        let mut aovs = args.aov.clone();
        aovs.sort();
        aovs.dedup();
        let formats = if args.format.is_empty() {
            vec![Format::Png]
        } else {
            args.format.clone()
        };
        if !aovs.is_empty() && !formats.contains(&Format::Exr) {
            return Err(
                Error::usage("--aov", "extra layers are EXR channels: add --format exr").into(),
            );
        }
        let timeline = timeline.with_samples(args.samples);
        if args.samples.is_some() && timeline.base.effects.motion_blur.is_some() {
            // Under motion blur the samples are instants, each checked.
            timeline
                .check_scene_count()
                .map_err(|(_, message)| Error::usage("--samples", message))?;
            let failing = timeline.first_invalid_frame();
            let failure = failing.and_then(|f| Some((f, timeline.invalid_instant(f)?)));
            if let Some((frame, (time, (field, message)))) = failure {
                let message = format!("frame {frame} (t = {time:.4} s): scene.{field}: {message}");
                return Err(Error::usage("--samples", message).into());
            }
        }
        let (mut width, mut height) = match &args.size {
            Some(s) => parse_size("--size", s)?,
            None => (timeline.width, timeline.height),
        };
        let range = match &args.frames {
            Some(f) => parse_frames(f, timeline.frame_count)?,
            None => 0..timeline.frame_count,
        };
        let mut formats = formats;
        formats.sort_by_key(|f| f.extension());
        formats.dedup();
        let mut out_dir = args
            .out
            .clone()
            .unwrap_or_else(|| Path::new("out").join(&timeline.name));
        let preview = args.preview;
        if preview {
            width = (width / 2).max(1);
            height = (height / 2).max(1);
            out_dir = out_dir.join("preview");
        }
        Ok(Plan {
            timeline,
            width,
            height,
            range,
            formats,
            out_dir,
            preview,
            aovs,
            samples: args.samples,
            verify: false,
        })
    }

    fn layers(&self) -> crate::render::Layers {
        output::layers_for(&self.aovs)
    }

    /// The plans an output folder records, one per format with its own
    /// range, layers and samples (see `crate::job::record::JobRecord`), and the record.
    fn from_folder(dir: &Path) -> anyhow::Result<(Vec<Plan>, crate::job::record::JobRecord)> {
        if !dir.join(crate::job::record::JOB_FILE).exists() {
            let preview = dir.join("preview");
            let hint = if preview.join(crate::job::record::JOB_FILE).exists() {
                format!("; a preview's is in {}", preview.display())
            } else {
                String::new()
            };
            let message = format!(
                "not a mandelreel output folder (no {}){hint}",
                crate::job::record::JOB_FILE
            );
            return Err(Error::usage(&dir.display().to_string(), message).into());
        }
        let job = crate::job::record::JobRecord::read(dir)?;
        let timeline = Timeline::parse(&job.timeline_text, &job.timeline_path)?;
        let plan = |o: crate::job::record::OutputRecord| -> anyhow::Result<Plan> {
            let format = <Format as clap::ValueEnum>::from_str(&o.format, true)
                .map_err(|e| anyhow::anyhow!(e))?;
            let timeline = timeline.clone().with_samples(o.samples);
            Ok(Plan {
                width: job.width,
                height: job.height,
                range: o.frames.0..o.frames.1.min(timeline.frame_count),
                formats: vec![format],
                out_dir: dir.to_path_buf(),
                preview: job.preview,
                aovs: o.aovs,
                samples: o.samples,
                verify: false,
                timeline,
            })
        };
        let plans = job
            .outputs()
            .into_iter()
            .map(plan)
            .collect::<anyhow::Result<_>>()?;
        Ok((plans, job))
    }

    /// This plan as one plan per format, so each format's frames can be
    /// counted on their own.
    fn per_format(&self) -> Vec<Plan> {
        let one = |&format: &Format| Plan {
            formats: vec![format],
            ..self.clone()
        };
        self.formats.iter().map(one).collect()
    }

    /// Refuses a size whose frame would need more memory than this machine
    /// (or this process's address-space limit) has to give, before anything
    /// is written: a frame too large would otherwise fail part-way, or be
    /// killed with the machine short of memory.
    fn check_memory(&self, size_given: bool) -> anyhow::Result<()> {
        // No track animates the sample count: the base scene has it.
        let many_samples = !self.preview && self.timeline.base.samples_per_pixel > 1;
        let exr = self.formats.contains(&Format::Exr);
        let (w, h) = (self.width, self.height);
        let need = crate::render::frame_bytes(w, h, self.layers(), exr, many_samples);
        let Some((have, whose)) = memory_available() else {
            return Ok(());
        };
        if need <= have {
            return Ok(());
        }
        let gib = |bytes: u64| bytes as f64 / (1u64 << 30) as f64;
        let option = if size_given { "--size" } else { "size" };
        Err(Error::usage(
            option,
            format!(
                "{w}x{h} needs about {:.1} GiB for a frame's buffers, and {whose} {:.1} GiB \
                 to give: render it smaller, or with more memory",
                gib(need),
                gib(have)
            ),
        )
        .into())
    }

    fn record(&self) -> anyhow::Result<crate::job::record::JobRecord> {
        let text = crate::timeline::read_text(&self.timeline.source)?;
        Ok(crate::job::record::JobRecord {
            renderer: format!("mandelreel {}", env!("CARGO_PKG_VERSION")),
            timeline_path: std::fs::canonicalize(&self.timeline.source)
                .unwrap_or_else(|_| self.timeline.source.clone()),
            timeline_text: text,
            width: self.width,
            height: self.height,
            formats: self
                .formats
                .iter()
                .map(|f| f.extension().to_string())
                .collect(),
            frames: (self.range.start, self.range.end),
            preview: self.preview,
            aovs: self.aovs.clone(),
            samples: self.samples,
            outputs: self
                .formats
                .iter()
                .map(|&f| crate::job::record::OutputRecord {
                    format: f.extension().to_string(),
                    frames: (self.range.start, self.range.end),
                    // Only EXRs hold extra layers.
                    aovs: if f == Format::Exr {
                        self.aovs.clone()
                    } else {
                        Vec::new()
                    },
                    samples: self.samples,
                })
                .collect(),
        })
    }

    /// The scenes of one frame (one per sample under motion blur) and its content hash.
    fn frame(&self, frame: u32) -> (Vec<crate::scene::Scene>, String) {
        let scenes = if self.preview {
            // A quick look: one sample, one instant.
            let mut scene = self.timeline.scene_at(frame);
            scene.samples_per_pixel = 1;
            vec![scene]
        } else {
            self.timeline.scenes_for_frame(frame)
        };
        let hash = output::frames::frame_hash(&scenes, frame, self.width, self.height);
        (scenes, hash)
    }

    fn path(&self, frame: u32, format: Format) -> PathBuf {
        self.out_dir
            .join(output::frames::frame_file_name(frame, format))
    }

    /// The format a video is encoded from: the PNGs, where rendered.
    fn video_format(&self) -> Format {
        if self.formats.contains(&Format::Png) {
            Format::Png
        } else {
            Format::Exr
        }
    }

    /// Whether `frame`'s file in `format` is whole and current (no hash
    /// is computed where there is no file).
    fn is_current_in(&self, frame: u32, format: Format) -> bool {
        let path = self.path(frame, format);
        if !path.exists() {
            return false;
        }
        let (_, hash) = self.frame(frame);
        let key = output::frames::stored_key(format, &hash, &self.aovs);
        output::frames::file_state(&path, format, &key, self.verify)
            == output::frames::FileState::Current
    }

    /// The ffmpeg command encoding `range` from its `format` files: into
    /// `<name>.mp4` for the whole film, else `<name>_frames_<A>-<B>.mp4`
    /// (`<name>_frame_<A>.mp4` for one).
    fn video_command(&self, range: &std::ops::Range<u32>, format: Format) -> String {
        let name = &self.timeline.name;
        let movie = if *range == (0..self.timeline.frame_count) {
            name.clone()
        } else {
            format!("{name}_{}", frames_text(range).replace(' ', "_"))
        };
        let fps = self.timeline.fps;
        ffmpeg_command(&self.out_dir, &movie, fps, range, format)
    }

    /// The state of each format's file of `frame` against these inputs
    /// (read whole with `--verify`).
    fn file_states(&self, frame: u32, hash: &str) -> Vec<output::frames::FileState> {
        self.formats
            .iter()
            .map(|&f| {
                let key = output::frames::stored_key(f, hash, &self.aovs);
                output::frames::file_state(&self.path(frame, f), f, &key, self.verify)
            })
            .collect()
    }

    /// Whether every format of `frame` exists, whole, and was made from
    /// these inputs.
    fn is_complete(&self, frame: u32, hash: &str) -> bool {
        let states = self.file_states(frame, hash);
        states
            .iter()
            .all(|&s| s == output::frames::FileState::Current)
    }

    /// Renders one frame and writes every format. A frame of one sample per
    /// pixel is rendered band by band (`render_frame_into`), without the
    /// whole frame's running sums. Others run in waves of samples, saving
    /// their accumulation every `checkpoint_every` and continuing from a
    /// saved one for the same inputs; the result is bit-identical either way.
    /// A one-sample frame renders into `film`, whose buffers the frames of a
    /// run share. `say` gets a line when the frame resumes from a checkpoint
    /// and a warning when one cannot be saved: the frame goes on without
    /// (a full disk should not end a night's render whose frames still fit),
    /// keeping any checkpoint saved before. Returns the stats.
    #[allow(clippy::too_many_arguments)]
    fn render_frame(
        &self,
        film: &mut crate::render::Film,
        frame: u32,
        scenes: &[crate::scene::Scene],
        hash: &str,
        checkpoint_every: std::time::Duration,
        on_row: &(dyn Fn() + Sync),
        say: &dyn Fn(Said),
    ) -> anyhow::Result<FrameStats> {
        let n = scenes[0].samples_per_pixel.max(1);
        let layers = self.layers();
        if n == 1 {
            // One sample is one wave: there is never a checkpoint to resume.
            crate::render::render_frame_into(
                film,
                scenes,
                frame,
                self.width,
                self.height,
                layers,
                on_row,
            );
            return self.write_film(frame, film, hash, &scenes[0].look);
        }
        let checkpoint = crate::job::checkpoint::checkpoint_path(&self.out_dir, frame);
        // A checkpoint holds linear light: how a PNG shows it is not its key.
        let light = output::frames::light_hash(hash);
        let saved_acc = crate::job::checkpoint::read_checkpoint(
            &checkpoint,
            light,
            self.width,
            self.height,
            layers,
        )
        .filter(|a| a.samples_done < n);
        let wave = wave_size(n);
        let mut acc = saved_acc
            .unwrap_or_else(|| crate::render::Accumulation::new(self.width, self.height, layers));
        if acc.samples_done > 0 {
            say(Said::Resumed {
                frame,
                samples: acc.samples_done,
                of: n,
            });
        }
        let mut saved = Instant::now();
        let mut saving = true;
        while acc.samples_done < n {
            let until = (acc.samples_done + wave).min(n);
            crate::render::render_samples(scenes, frame, &mut acc, until, on_row);
            if saving && until < n && saved.elapsed() >= checkpoint_every {
                if let Err(e) = crate::job::checkpoint::write_checkpoint(&checkpoint, &acc, light) {
                    say(Said::CheckpointFailed { frame, error: e });
                    saving = false;
                }
                saved = Instant::now();
            }
        }
        let film = acc.finish(n);
        self.write_film(frame, &film, hash, &scenes[0].look)
    }

    /// Writes every format of a finished frame and drops its checkpoint.
    fn write_film(
        &self,
        frame: u32,
        film: &crate::render::Film,
        hash: &str,
        look: &crate::shade::Look,
    ) -> anyhow::Result<FrameStats> {
        for &f in &self.formats {
            output::frames::write_frame(&self.path(frame, f), f, film, hash, &self.aovs, look)?;
        }
        let _ = std::fs::remove_file(crate::job::checkpoint::checkpoint_path(
            &self.out_dir,
            frame,
        ));
        Ok(film.stats)
    }
}

/// Memory this process can still have, where Linux tells, and whose limit
/// that is: the least of what the machine has available (memory and swap,
/// /proc/meminfo), what its control group may still use (cgroup v2's
/// memory.max, or v1's limit, less what it uses: a container's limit),
/// and the process's address-space limit (`ulimit -v`, /proc/self/limits,
/// less what it has mapped).
fn memory_available() -> Option<(u64, &'static str)> {
    let read = |path: &str| std::fs::read_to_string(path).ok();
    let number = |text: Option<String>| text?.trim().parse::<u64>().ok();
    // "Key:  <n> kB" lines of /proc/meminfo and /proc/self/status, in bytes.
    let field = |text: &str, key: &str| -> Option<u64> {
        let line = text.lines().find(|l| l.starts_with(key))?;
        Some(line.split_whitespace().nth(1)?.parse::<u64>().ok()? * 1024)
    };
    let meminfo = read("/proc/meminfo")?;
    let machine = field(&meminfo, "MemAvailable:")? + field(&meminfo, "SwapFree:").unwrap_or(0);
    let mut limits = vec![(machine, "this machine has")];
    // A limit of "max" (v2) parses as none; v1's unlimited is a huge number.
    let group = number(read("/sys/fs/cgroup/memory.max"))
        .zip(number(read("/sys/fs/cgroup/memory.current")))
        .or_else(|| {
            number(read("/sys/fs/cgroup/memory/memory.limit_in_bytes"))
                .zip(number(read("/sys/fs/cgroup/memory/memory.usage_in_bytes")))
        });
    if let Some((max, used)) = group {
        limits.push((max.saturating_sub(used), "this control group has"));
    }
    // "Max address space  <soft> <hard> bytes": "unlimited" parses as none.
    let address_space = read("/proc/self/limits").and_then(|text| {
        let line = text.lines().find(|l| l.starts_with("Max address space"))?;
        line.split_whitespace().nth(3)?.parse::<u64>().ok()
    });
    if let Some(limit) = address_space {
        let mapped = read("/proc/self/status")
            .and_then(|s| field(&s, "VmSize:"))
            .unwrap_or(0);
        limits.push((limit.saturating_sub(mapped), "this process may map"));
    }
    limits.into_iter().min_by_key(|(bytes, _)| *bytes)
}

/// A positive number of seconds (`--claim-timeout`).
fn positive_seconds(text: &str) -> std::result::Result<std::time::Duration, String> {
    seconds(text)
        .filter(|d| !d.is_zero())
        .ok_or_else(|| format!("must be a positive number of seconds, got {text:?}"))
}

/// A number of seconds, 0 or more (`--checkpoint-seconds`).
fn any_seconds(text: &str) -> std::result::Result<std::time::Duration, String> {
    seconds(text).ok_or_else(|| format!("must be a number of seconds, 0 or more, got {text:?}"))
}

/// `text` as a duration: finite, not negative, within `Duration`'s range.
fn seconds(text: &str) -> Option<std::time::Duration> {
    std::time::Duration::try_from_secs_f64(text.trim().parse().ok()?).ok()
}

/// Samples per pixel in one wave: about 16 waves a frame, so a long frame
/// can be checkpointed between them.
fn wave_size(samples_per_pixel: u32) -> u32 {
    samples_per_pixel.div_ceil(16).max(1)
}

/// Parses `--shard I/N` or `auto` from the scheduler's environment.
pub fn parse_shard(text: &str, env: &dyn Fn(&str) -> Option<String>) -> Result<(u32, u32)> {
    let bad = |why: String| Error::usage("--shard", why);
    let number = |name: &str, v: String| -> Result<u32> {
        v.trim()
            .parse()
            .map_err(|_| bad(format!("{name}={v:?} is not a whole number")))
    };
    let (index, count) = if text == "auto" {
        if let (Some(id), Some(count)) = (env("SLURM_ARRAY_TASK_ID"), env("SLURM_ARRAY_TASK_COUNT"))
        {
            // Array indices need not start at 0 (--array=1-8): count from the minimum.
            let min = env("SLURM_ARRAY_TASK_MIN")
                .map(|m| number("SLURM_ARRAY_TASK_MIN", m))
                .transpose()?
                .unwrap_or(0);
            let id = number("SLURM_ARRAY_TASK_ID", id)?;
            (
                id.checked_sub(min)
                    .ok_or_else(|| bad(format!("task id {id} is below the array minimum {min}")))?,
                number("SLURM_ARRAY_TASK_COUNT", count)?,
            )
        } else if let Some(index) = env("JOB_COMPLETION_INDEX") {
            let count = env("MANDELREEL_SHARD_COUNT").ok_or_else(|| {
                bad("JOB_COMPLETION_INDEX is set but MANDELREEL_SHARD_COUNT (the Job's completions) is not".into())
            })?;
            (
                number("JOB_COMPLETION_INDEX", index)?,
                number("MANDELREEL_SHARD_COUNT", count)?,
            )
        } else {
            return Err(bad(
                "auto needs SLURM_ARRAY_TASK_ID and SLURM_ARRAY_TASK_COUNT, or JOB_COMPLETION_INDEX and MANDELREEL_SHARD_COUNT".into(),
            ));
        }
    } else {
        let (i, n) = text
            .split_once('/')
            .ok_or_else(|| bad(format!("expected I/N such as 0/8, or auto; got {text:?}")))?;
        (number("I", i.to_string())?, number("N", n.to_string())?)
    };
    if count == 0 || index >= count {
        return Err(bad(format!(
            "shard {index} of {count} does not exist (0 <= I < N)"
        )));
    }
    Ok((index, count))
}

/// Refuses a render (`record`) into a folder whose job record (`old`) is
/// another sequence's (`JobRecord::same_sequence`), if the folder has
/// frames: the render would replace them, or leave two sequences mixed
/// under one record.
fn refuse_other_sequence(
    out_dir: &Path,
    old: &crate::job::record::JobRecord,
    record: &crate::job::record::JobRecord,
    running: usize,
) -> crate::error::Result<()> {
    let frames: usize = [Format::Png, Format::Exr]
        .into_iter()
        .map(|f| output::frames::frame_files(out_dir, f).map_or(0, |files| files.len()))
        .sum();
    if frames == 0 && running == 0 {
        return Ok(());
    }
    let what = |r: &crate::job::record::JobRecord| {
        let name = r.timeline_path.file_name().unwrap_or_default();
        format!("{} at {}x{}", name.to_string_lossy(), r.width, r.height)
    };
    Err(Error::usage(
        "--out",
        format!(
            "{} holds {frames} frame file(s) of {} (by its {}){}; rendering {} there would \
             replace them or mix two sequences in one folder: choose another folder with \
             --out, or pass --replace to replace them",
            out_dir.display(),
            what(old),
            crate::job::record::JOB_FILE,
            if running > 0 {
                format!(" and {running} render(s) of it still running")
            } else {
                String::new()
            },
            what(record),
        ),
    ))
}

fn render(args: RenderArgs) -> anyhow::Result<()> {
    // Before the timeline, whose frames are checked on the thread pool.
    set_threads(args.threads)?;
    // Everything is checked before the output folder is touched.
    let mut plan = Plan::new(&args.timeline, &args.sequence)?;
    plan.verify = args.verify;
    let shard = args
        .shard
        .as_deref()
        .map(|s| parse_shard(s, &|k| std::env::var(k).ok()))
        .transpose()?;
    let record = plan.record()?;
    let (width, height, out_dir) = (plan.width, plan.height, plan.out_dir.clone());
    plan.check_memory(args.sequence.size.is_some())?;
    if out_dir.exists() && !out_dir.is_dir() {
        let message = format!("{} is a file, not a folder", out_dir.display());
        return Err(Error::usage("--out", message).into());
    }
    // From here on, Ctrl-C and SIGTERM clean up and say what is done. (Where
    // they cannot be caught, they end the render as they always did.)
    let _ = crate::interrupt::install();
    let mine: Vec<u32> = plan
        .range
        .clone()
        .filter(|f| shard.is_none_or(|(i, n)| f % n == i))
        .collect();
    let total = mine.len();
    let tally = Arc::new(Mutex::new(Tally::default()));
    let bars_drawn = Arc::new(std::sync::OnceLock::new());
    let _reported = report_interrupt(&tally, &bars_drawn, total, shard);
    // Removed again, when dropped, if the render ends having written nothing.
    let scaffold = crate::job::record::Scaffold::make(&out_dir)?;
    // Checked under the record's lock, so two renders started at once
    // cannot both pass it.
    let replacing = args.force || args.replace;
    record.clone().record_in(&out_dir, |old| {
        if old.same_sequence(&record) || replacing {
            return Ok(());
        }
        let running = crate::job::claim::live_runs(&out_dir, args.claim_timeout);
        refuse_other_sequence(&out_dir, old, &record, running.len())
    })?;
    let stale = output::atomic::remove_stale_partials(&out_dir)?;
    // Until this render ends, `status` lists it as running.
    let running = crate::job::claim::announce_run(&out_dir, args.claim_timeout)?;

    // Decide which frames need work, so the progress bar and ETA count only
    // those. Their scenes are built again as each renders: kept, a long
    // film's (a scene per sample under motion blur) would fill the memory.
    let mut todo = Vec::new();
    for &frame in &mine {
        let (_, hash) = plan.frame(frame);
        if args.force || !plan.is_complete(frame, &hash) {
            todo.push((frame, hash));
        } else {
            lock(&tally).complete += 1;
        }
    }
    lock(&tally).checked = true;
    let skipped = total - todo.len();

    let show_bars = !args.quiet && std::io::stderr().is_terminal();
    let log_lines = !args.quiet && !show_bars;
    let bars = MultiProgress::with_draw_target(if show_bars {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    });
    let overall = bars.add(ProgressBar::new(todo.len() as u64));
    overall.set_style(
        ProgressStyle::with_template(
            "{prefix:>8} [{bar:32}] {pos}/{len} frames  {elapsed_precise}  ETA {eta_precise}",
        )
        .expect("template is valid")
        .progress_chars("=> "),
    );
    overall.set_prefix("frames");
    let current = bars.add(ProgressBar::new(height as u64));
    current.set_style(
        ProgressStyle::with_template("{prefix:>8} [{bar:32}] {pos}/{len} rows  {msg}")
            .expect("template is valid")
            .progress_chars("=> "),
    );
    let _ = bars_drawn.set([overall.clone(), current.clone()]);
    // Lines printed above the bars when they show, plainly to stderr otherwise.
    let say = |line: String| {
        if show_bars {
            let _ = bars.println(line);
        } else {
            eprintln!("{line}");
        }
    };
    let planned: Vec<u32> = todo.iter().map(|(frame, _)| *frame).collect();
    for warning in warnings(&plan.timeline, &planned, !plan.preview) {
        say(format!("warning: {warning}"));
    }
    // Another render on this folder, where neither shares the frames out
    // (--claim, --shard): not an error, since the frames come out the same,
    // but each frame neither has finished is rendered twice.
    if !args.claim && shard.is_none() && !todo.is_empty() {
        let others: Vec<String> = crate::job::claim::live_runs(&out_dir, args.claim_timeout)
            .iter()
            .filter(|run| run.token != running.token())
            .map(crate::job::claim::ClaimRecord::who)
            .collect();
        if !others.is_empty() {
            say(format!(
                "warning: another render is running on {} ({}): both will render the frames \
                 neither has finished; give every worker --claim to share them",
                out_dir.display(),
                others.join(", ")
            ));
        }
    }
    if !args.quiet && stale > 0 {
        say(format!(
            "removed {stale} temporary file(s) left by an interrupted render"
        ));
    }
    if !args.quiet && skipped > 0 {
        say(format!(
            "{skipped} of {total} frames already complete and current in {}; rendering {}",
            out_dir.display(),
            todo.len()
        ));
    }

    let started = Instant::now();
    let mut totals = FrameStats::default();
    // Frames where many camera rays ran out of steps (said once, at the end).
    let mut short_of_steps = Vec::new();
    let mut rendered = 0usize;
    let mut film = crate::render::Film::default();
    let mut render_one = |frame: u32, hash: &str| -> anyhow::Result<()> {
        let (scene, _) = plan.frame(frame);
        let scene = &scene[..];
        current.reset();
        current.set_prefix(format!("#{frame}"));
        current.set_message(format!("{width}x{height}"));
        let t0 = Instant::now();
        let n = scene[0].samples_per_pixel.max(1);
        current.set_length(height as u64 * n.div_ceil(wave_size(n)) as u64);
        lock(&tally).writing = plan
            .formats
            .iter()
            .map(|&f| {
                (
                    plan.path(frame, f),
                    f,
                    output::frames::stored_key(f, hash, &plan.aovs),
                )
            })
            .collect();
        let stats = plan.render_frame(
            &mut film,
            frame,
            scene,
            hash,
            args.checkpoint_seconds,
            &|| current.inc(1),
            &|said| match said {
                Said::Resumed { frame, samples, of } if !args.quiet => say(format!(
                    "frame {frame}: resuming from a checkpoint at {samples} of {of} samples per pixel"
                )),
                Said::Resumed { .. } => {}
                Said::CheckpointFailed { frame, error } => say(format!(
                    "warning: frame {frame}: could not save a checkpoint ({error}); \
                     going on without one for this frame"
                )),
            },
        )?;
        {
            let mut tally = lock(&tally);
            tally.complete += 1;
            tally.writing.clear();
        }
        totals = totals + stats;
        if out_of_steps_matters(&stats) {
            short_of_steps.push(frame);
        }
        rendered += 1;
        overall.inc(1);
        let seconds = t0.elapsed().as_secs_f64();
        // Asked for, so printed even with --quiet.
        if args.stats {
            say(format!(
                "frame {frame}: {seconds:.2} s, {} DE evaluations ({:.1} per sample, at most {} in one pixel; primary {}, normals {}, shadows {}, occlusion {}, bounces {}, sun {}), {} of {} samples hit ({} out of steps), {} repaired",
                stats.de_evaluations,
                stats.de_evaluations as f64 / stats.samples.max(1) as f64,
                stats.max_pixel_evaluations,
                stats.primary_evaluations,
                stats.normal_evaluations,
                stats.shadow_evaluations,
                stats.occlusion_evaluations,
                stats.bounce_evaluations,
                stats.sun_evaluations,
                stats.hits,
                stats.samples,
                stats.out_of_steps,
                stats.repaired_samples
            ));
        } else if log_lines {
            eprintln!(
                "frame {frame} ({rendered}/{}) rendered in {seconds:.2} s",
                todo.len()
            );
        }
        Ok(())
    };
    if args.claim {
        // Take frames one at a time; wait out frames other live workers hold,
        // so a worker that dies has its frame taken over by one that did not.
        // At most a second: a worker whose last frames others are
        // finishing sees them done that soon.
        let poll = (args.claim_timeout / 4).clamp(
            std::time::Duration::from_millis(100),
            std::time::Duration::from_secs(1),
        );
        // The frames last reported as held by others (said once per change).
        let mut waiting_for = Vec::new();
        // Frames seen finished, here or by others, are not read again: a
        // worker waiting on a farm's shared storage would otherwise check
        // them all every round (read whole, with --verify).
        let mut finished = vec![false; todo.len()];
        loop {
            let mut held = Vec::new();
            for (k, (frame, hash)) in todo.iter().enumerate() {
                if finished[k] {
                    continue;
                }
                if !args.force && plan.is_complete(*frame, hash) {
                    finished[k] = true;
                    lock(&tally).complete += 1;
                    continue;
                }
                match crate::job::claim::try_claim(&out_dir, *frame, args.claim_timeout)? {
                    crate::job::claim::Attempt::Claimed(claim) => {
                        // It may have been finished between the check and the claim.
                        if args.force || !plan.is_complete(*frame, hash) {
                            render_one(*frame, hash)?;
                        } else {
                            lock(&tally).complete += 1;
                        }
                        finished[k] = true;
                        drop(claim);
                    }
                    // Another live worker has it: look again next round.
                    crate::job::claim::Attempt::Held(other) => held.push((k, other)),
                }
            }
            // With --force a worker makes one pass: "complete" cannot tell its
            // own fresh frames from old ones, so waiting would re-render them.
            if args.force {
                break;
            }
            // Frames held when this pass came to them may be done by now.
            held.retain(|(k, _)| {
                let (frame, hash) = &todo[*k];
                finished[*k] = plan.is_complete(*frame, hash);
                lock(&tally).complete += usize::from(finished[*k]);
                !finished[*k]
            });
            if held.is_empty() {
                break;
            }
            let frames: Vec<u32> = held.iter().map(|(k, _)| todo[*k].0).collect();
            if !args.quiet && frames != waiting_for {
                let mut workers: Vec<String> = held.iter().map(|(_, c)| c.who()).collect();
                workers.sort();
                workers.dedup();
                say(format!(
                    "waiting for frame(s) {} claimed by {} (a claim without a heartbeat for {} s is taken over)",
                    ranges(&frames),
                    workers.join(", "),
                    args.claim_timeout.as_secs_f64()
                ));
                waiting_for = frames;
            }
            std::thread::sleep(poll);
        }
    } else {
        for (frame, hash) in &todo {
            render_one(*frame, hash)?;
        }
    }
    current.finish_and_clear();
    overall.finish_and_clear();
    if !short_of_steps.is_empty() {
        eprintln!(
            "warning: {}",
            out_of_steps_warning(&short_of_steps, &plan.timeline)
        );
    }

    if !args.quiet {
        let elapsed = started.elapsed().as_secs_f64();
        eprintln!(
            "{rendered} frame{} rendered in {elapsed:.1} s ({:.2} s/frame), {skipped} skipped; frames in {}",
            if rendered == 1 { "" } else { "s" },
            elapsed / rendered.max(1) as f64,
            out_dir.display()
        );
    }
    if args.stats {
        eprintln!(
            "total DE evaluations: {}, repaired (NaN/inf) samples: {}",
            totals.de_evaluations, totals.repaired_samples
        );
    }
    // This render's frames are all complete now, but where a --force claim
    // worker made its one pass: others may still hold some.
    let known = if args.claim && args.force {
        &[][..]
    } else {
        &mine
    };
    print_video_command(&plan, known, args.quiet)?;
    scaffold.keep();
    Ok(())
}

/// After a render: on stdout (scripts run it, so also with `--quiet`) the
/// ffmpeg command for the whole film once every frame of it is complete;
/// else for this render's range alone, under a name of its own so that no
/// complete video is replaced, if that range is complete; and on stderr
/// what is still missing. `known` frames are complete; the others are
/// looked for on disk.
fn print_video_command(plan: &Plan, known: &[u32], quiet: bool) -> anyhow::Result<()> {
    let format = plan.video_format();
    let known: std::collections::HashSet<u32> = known.iter().copied().collect();
    let missing: Vec<u32> = (0..plan.timeline.frame_count)
        .filter(|f| !known.contains(f) && !plan.is_current_in(*f, format))
        .collect();
    let say = |line: String| {
        if !quiet {
            eprintln!("{line}");
        }
    };
    if missing.is_empty() {
        say("encode the video with:".into());
        out!(
            "{}",
            plan.video_command(&(0..plan.timeline.frame_count), format)
        );
        return Ok(());
    }
    let status = format!(
        "mandelreel status {}",
        shell_quote(&plan.out_dir.to_string_lossy())
    );
    let lacking = format!(
        "frame(s) {} of the film are not complete yet",
        frame_summary(&missing)
    );
    // Another worker's frames in this range: nothing to encode on its own.
    if missing.iter().any(|f| plan.range.contains(f)) {
        say(format!(
            "{lacking}; once they are, {status} prints the command that encodes the video"
        ));
        return Ok(());
    }
    say(format!(
        "{lacking} ({status} tells when, and prints the command for the whole video); \
         to encode {} alone, leaving {}.mp4 as it is:",
        frames_text(&plan.range),
        plan.timeline.name
    ));
    out!("{}", plan.video_command(&plan.range, format));
    Ok(())
}

/// `frame 5`, or `frames 0-2`, for a range of frames.
fn frames_text(range: &std::ops::Range<u32>) -> String {
    match range.len() {
        1 => format!("frame {}", range.start),
        _ => format!("frames {}-{}", range.start, range.end.saturating_sub(1)),
    }
}

/// `ranges` of `frames`, its first few runs only for a long list:
/// `1-7, 9-15, 17-23, 25-31, 33-39, … (1110 frames)`.
fn frame_summary(frames: &[u32]) -> String {
    let all = ranges(frames);
    let runs: Vec<&str> = all.split(", ").collect();
    if runs.len() <= 6 {
        return all;
    }
    format!("{}, … ({} frames)", runs[..5].join(", "), frames.len())
}

/// How far a render has got, for what an interrupt says (`report_interrupt`).
#[derive(Default)]
struct Tally {
    /// Whether every frame of the render has been checked for being complete.
    checked: bool,
    /// Frames of this render's share complete: found so, or rendered.
    complete: usize,
    /// The files of the frame being rendered, and the key each will hold:
    /// they may be in place a moment before `complete` counts the frame.
    writing: Vec<(PathBuf, Format, String)>,
}

/// `tally`, locked (a panic elsewhere does not make its numbers wrong).
fn lock(tally: &Mutex<Tally>) -> std::sync::MutexGuard<'_, Tally> {
    tally.lock().unwrap_or_else(|e| e.into_inner())
}

/// On Ctrl-C or SIGTERM, once the render's files are cleaned up (see
/// `interrupt`): clears the progress bars and says how many of the `total`
/// frames of this render (of its `shard`) are complete.
fn report_interrupt(
    tally: &Arc<Mutex<Tally>>,
    bars: &Arc<std::sync::OnceLock<[ProgressBar; 2]>>,
    total: usize,
    shard: Option<(u32, u32)>,
) -> crate::interrupt::Registered {
    let (tally, bars) = (tally.clone(), bars.clone());
    crate::interrupt::report_on_interrupt(move |stop| {
        use std::io::Write as _;
        if let Some(bars) = bars.get() {
            if stop.echoed && !bars[0].is_hidden() {
                // The `^C` went past the bars' last column, onto a line of
                // its own: wipe it, and go back up to where they end.
                let _ = write!(std::io::stderr(), "\r\x1b[2K\x1b[1A");
            }
            // As at the end of a render; rows still finishing draw nothing.
            for bar in bars {
                bar.finish_and_clear();
            }
        }
        let tally = lock(&tally);
        let written = !tally.writing.is_empty()
            && tally.writing.iter().all(|(path, format, key)| {
                output::frames::file_state(path, *format, key, false)
                    == output::frames::FileState::Current
            });
        let share = match shard {
            Some((i, n)) if n > 1 => format!(" (shard {i}/{n})"),
            _ => String::new(),
        };
        let done = if tally.checked {
            let complete = tally.complete + usize::from(written);
            format!(": {complete} of {total} frames complete{share}")
        } else {
            format!(" while checking which of {total} frames are complete{share}")
        };
        // Not `eprintln!`, which panics if standard error is gone.
        let _ = writeln!(
            std::io::stderr(),
            "interrupted{done}; the same command resumes"
        );
    })
}

/// What `Plan::render_frame` has to say while a frame renders.
enum Said {
    /// It goes on from a checkpoint holding `samples` of its `of` samples a pixel.
    Resumed { frame: u32, samples: u32, of: u32 },
    /// A checkpoint could not be saved; the frame goes on without.
    CheckpointFailed { frame: u32, error: Error },
}

/// The state of one frame in an output folder.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum FrameState {
    // In the order `status` lists them.
    /// Every format exists and carries the current hash.
    Complete,
    /// A live claim or a fresh temporary file: some worker is on it.
    InProgress,
    /// A checkpoint holds part of its samples: a render will continue it.
    Resumable,
    /// A file exists but was made from other inputs (the timeline changed).
    Stale,
    /// A file exists but cannot be read, or is not whole (cut short by a
    /// copy or a full disk, or damaged): a render writes it again.
    Damaged,
    /// Nothing of it yet.
    Missing,
}

impl FrameState {
    /// A frame's state over the `states` of its formats: complete if each
    /// is, else the one that says most of what is left (a live worker, a
    /// checkpoint, a damaged file, a stale one, in that order).
    fn of_formats(states: &[FrameState]) -> FrameState {
        use FrameState::*;
        let order = [InProgress, Resumable, Damaged, Stale, Missing];
        order
            .into_iter()
            .find(|s| states.contains(s))
            .unwrap_or(Complete)
    }

    /// The state's name in `status --json` (`in progress` in the text).
    pub fn name(self) -> &'static str {
        match self {
            FrameState::Complete => "complete",
            FrameState::Stale => "stale",
            FrameState::Damaged => "damaged",
            FrameState::InProgress => "in_progress",
            FrameState::Resumable => "resumable",
            FrameState::Missing => "missing",
        }
    }
}

/// Orbit iterations (`iteration_weight`) the camera-inside check of
/// `warnings` may spend, about a fifth of a second on two cores: beyond,
/// it checks frames evenly spread.
const INSIDE_CHECK_ITERATIONS: u64 = 10_000_000;

/// Seconds after which the camera-inside check stops where it is: where
/// orbits are slower than their weight says (a camera on a power's pole
/// axis, where whole powers take the trigonometric form too).
const INSIDE_CHECK_SECONDS: f64 = 0.4;

/// What is allowed but likely not what the author meant, in `frames` of
/// `timeline`: `render` and `info` print these. `samples_matter` is false
/// for previews, which take one sample whatever the timeline says. Nothing
/// is kept per frame but its number where a warning names it.
fn warnings(timeline: &Timeline, frames: &[u32], samples_matter: bool) -> Vec<String> {
    let mut said = Vec::new();
    // Keys all on one side of the film: the track never changes a frame.
    let end = timeline.time_of(timeline.frame_count - 1);
    // (A looping film's keys all lie in its period, and repeat.)
    let animating = |t: &&Track| !timeline.looping && t.key_times.len() > 1;
    for track in timeline.tracks.iter().filter(animating) {
        let (first, last) = (
            track.key_times[0],
            track.key_times[track.key_times.len() - 1],
        );
        let (side, held) = if first > end {
            (format!("after the last frame (t = {end:.3} s)"), "first")
        } else if last < 0.0 {
            ("before the first frame (t = 0 s)".to_string(), "last")
        } else {
            continue;
        };
        said.push(format!(
            "every key of track \"{}\" ({first} s .. {last} s) is {side}: it does not animate, \
             every frame holds its {held} key's value",
            track.name
        ));
    }
    if let Some(message) = camera_inside(timeline, frames) {
        said.push(message);
    }
    // Effects that need several samples a pixel, declared with too few:
    // not an error (a test render may want it), but not what they look like.
    // No track animates the samples or the shutter; one may open the lens.
    if samples_matter {
        use crate::scene::{LENS_SAMPLES, MOTION_BLUR_SAMPLES};
        let base = &timeline.base;
        let lens = timeline.with_tracks(|name| name == "camera.aperture_radius");
        let short_for_lens: Vec<u32> = if base.samples_per_pixel < LENS_SAMPLES {
            frames
                .par_iter()
                .copied()
                .filter(|&f| lens.scene_at(f).camera.frame().has_lens())
                .collect()
        } else {
            Vec::new()
        };
        let short_for_blur =
            if base.effects.motion_blur.is_some() && base.samples_per_pixel < MOTION_BLUR_SAMPLES {
                frames.to_vec()
            } else {
                Vec::new()
            };
        let needs = [
            (
                short_for_lens,
                "depth of field",
                LENS_SAMPLES,
                "to be smooth",
            ),
            (
                short_for_blur,
                "motion blur",
                MOTION_BLUR_SAMPLES,
                "to blur rather than ghost",
            ),
        ];
        for (short, effect, n, why) in needs {
            if !short.is_empty() {
                said.push(format!(
                    "{effect} needs samples_per_pixel of {n} or more {why}; frame(s) {} have fewer",
                    ranges(&short)
                ));
            }
        }
    }
    said
}

/// The warning for `frames` of `timeline` whose camera is inside the
/// fractal, if any: not an error (a fly-through may pass through the
/// surface), but those frames show only the inside, since every ray starts
/// in the set. A point inside costs the full iterations to tell, so past
/// `INSIDE_CHECK_ITERATIONS` in all, frames evenly spread are checked.
fn camera_inside(timeline: &Timeline, frames: &[u32]) -> Option<String> {
    // Scenes with only the tracks that matter are quicker to build.
    let counting =
        timeline.with_tracks(|name| ["fractal.iterations", "fractal.power"].contains(&name));
    let cost: u64 = frames
        .par_iter()
        .map(|&f| {
            let fractal = counting.scene_at(f).fractal;
            fractal.iterations as u64 * iteration_weight(&fractal)
        })
        .sum();
    let moving = ["camera.position", "camera.target", ZOOM_TRACK];
    let timeline =
        &timeline.with_tracks(|name| moving.contains(&name) || name.starts_with("fractal."));
    let stride = cost.div_ceil(INSIDE_CHECK_ITERATIONS).max(1) as usize;
    let checked: Vec<u32> = frames.iter().step_by(stride).copied().collect();
    let (inside, done) = frames_inside(timeline, &checked);
    if inside.is_empty() {
        return None;
    }
    let which = if stride == 1 && done == checked.len() {
        let frames: Vec<u32> = inside.iter().map(|&k| checked[k]).collect();
        format!("{} frame(s) ({})", frames.len(), ranges(&frames))
    } else {
        // Runs of frames checked one after another, each from its first
        // frame to its last.
        let mut runs: Vec<(usize, usize)> = Vec::new();
        for &k in &inside {
            match runs.last_mut() {
                Some((_, last)) if *last + 1 == k => *last = k,
                _ => runs.push((k, k)),
            }
        }
        let shown: Vec<String> = runs
            .iter()
            .map(|&(a, b)| match (checked[a], checked[b]) {
                (a, b) if a == b => a.to_string(),
                (a, b) => format!("{a}-{b}"),
            })
            .collect();
        let spread = if stride > 1 {
            format!(", one in {stride} of {}", frames.len())
        } else {
            String::new()
        };
        let stopped = if done < checked.len() {
            format!(
                ", up to frame {}: slow to check for this fractal",
                checked[done - 1]
            )
        } else {
            String::new()
        };
        format!(
            "{} of the {done} frames checked{spread}{stopped} ({})",
            inside.len(),
            shown.join(", ")
        )
    };
    Some(format!(
        "the camera is inside the fractal in {which}; they render as a flat inside colour"
    ))
}

/// Which of `frames` (their indices) have the camera inside the fractal,
/// and how many were checked: all of them, unless `INSIDE_CHECK_SECONDS`
/// ran out first. A frame whose camera and fractal are those of the frame
/// before is not checked again.
fn frames_inside(timeline: &Timeline, frames: &[u32]) -> (Vec<usize>, usize) {
    let started = Instant::now();
    let (mut inside, mut done) = (Vec::new(), 0);
    for block in frames.chunks(256) {
        let found: Vec<bool> = block
            .par_chunks(16)
            .flat_map_iter(|run| {
                let mut last: Option<(crate::scene::Scene, bool)> = None;
                run.iter().map(move |&f| {
                    let s = timeline.scene_at(f);
                    let same = |(l, _): &&(crate::scene::Scene, bool)| {
                        l.camera.position == s.camera.position && l.fractal == s.fractal
                    };
                    if let Some((_, was)) = last.as_ref().filter(same) {
                        return *was;
                    }
                    let is = s.fractal.contains(s.camera.position);
                    last = Some((s, is));
                    is
                })
            })
            .collect();
        let found = found.iter().enumerate().filter(|(_, &is)| is);
        inside.extend(found.map(|(k, _)| done + k));
        done += block.len();
        if started.elapsed().as_secs_f64() > INSIDE_CHECK_SECONDS {
            break;
        }
    }
    (inside, done)
}

/// What an orbit iteration of `fractal` costs, in iterations of a whole
/// power (complex squaring): other powers take the trigonometric form,
/// about eight times as long.
fn iteration_weight(fractal: &crate::fractal::Fractal) -> u64 {
    if crate::fractal::whole_power(fractal.power).is_some() {
        1
    } else {
        8
    }
}

/// Whether enough of a frame's camera rays ran out of steps to say so: 1%.
fn out_of_steps_matters(stats: &FrameStats) -> bool {
    stats.out_of_steps * 100 >= stats.samples.max(1)
}

/// What to say of `frames`, in each of which 1% or more of the camera rays
/// ran out of `quality.max_steps`.
fn out_of_steps_warning(frames: &[u32], timeline: &Timeline) -> String {
    let quality = &timeline.scene_at(frames[0]).quality;
    format!(
        "in frame(s) {}, 1% or more of the camera rays ran out of quality.max_steps ({}) and \
         count as hits where they stopped (a false surface in the background): raise max_steps{}",
        ranges(frames),
        quality.max_steps,
        if quality.fudge < 0.5 {
            format!(", or quality.fudge ({}): a step of a fudge of the estimate needs about 1/fudge times the steps", quality.fudge)
        } else {
            String::new()
        }
    )
}

/// `0-3, 7, 9-12` for sorted frame numbers.
fn ranges(frames: &[u32]) -> String {
    let mut parts = Vec::new();
    let mut i = 0;
    while i < frames.len() {
        let mut j = i;
        while j + 1 < frames.len() && frames[j + 1] == frames[j] + 1 {
            j += 1;
        }
        parts.push(if i == j {
            frames[i].to_string()
        } else {
            format!("{}-{}", frames[i], frames[j])
        });
        i = j + 1;
    }
    parts.join(", ")
}

fn status(args: StatusArgs) -> anyhow::Result<()> {
    // One plan per format, and the folder's record: read once.
    let (parts, job) = if args.target.is_dir() {
        let s = &args.sequence;
        // The folder records these; only the frames may be narrowed.
        let given = [
            ("--out", s.out.is_some()),
            ("--size", s.size.is_some()),
            ("--format", !s.format.is_empty()),
            ("--aov", !s.aov.is_empty()),
            ("--preview", s.preview),
            ("--samples", s.samples.is_some()),
        ];
        if let Some((option, _)) = given.iter().find(|(_, given)| *given) {
            return Err(Error::usage(
                option,
                format!(
                    "{} is an output folder, which records its own size, samples, formats and layers: \
                     give the timeline instead (status TIMELINE {option} …) or leave {option} out",
                    args.target.display()
                ),
            )
            .into());
        }
        let (mut parts, job) = Plan::from_folder(&args.target)?;
        for part in &mut parts {
            if let Some(frames) = &s.frames {
                part.range = parse_frames(frames, part.timeline.frame_count)?;
            }
        }
        (parts, Some(job))
    } else {
        let plan = Plan::new(&args.target, &args.sequence)?;
        let job = crate::job::record::JobRecord::read(&plan.out_dir).ok();
        (plan.per_format(), job)
    };
    let parts: Vec<Plan> = parts
        .into_iter()
        .map(|part| Plan {
            verify: args.verify,
            ..part
        })
        .collect();
    // What the formats share, over the span of their ranges.
    let Some(first) = parts.first() else {
        let message = format!("{} records no output format", crate::job::record::JOB_FILE);
        return Err(Error::usage(&args.target.display().to_string(), message).into());
    };
    let plan = Plan {
        range: parts.iter().map(|p| p.range.start).min().unwrap_or(0)
            ..parts.iter().map(|p| p.range.end).max().unwrap_or(0),
        ..first.clone()
    };
    // Fresh temporary files, by frame: a writer is finishing that frame.
    let writing = output::frames::frames_being_written(&plan.out_dir);
    let mut by_state: std::collections::BTreeMap<FrameState, Vec<u32>> = Default::default();
    let mut by_format = vec![std::collections::BTreeMap::new(); parts.len()];
    // Renders running on the folder (`claim::announce_run`), and below, any
    // other worker holding a claim.
    let mut workers: std::collections::BTreeSet<String> =
        crate::job::claim::live_runs(&plan.out_dir, args.claim_timeout)
            .iter()
            .map(crate::job::claim::ClaimRecord::who)
            .collect();
    for frame in plan.range.clone() {
        let mut states = Vec::new();
        for (part, by_state) in parts.iter().zip(&mut by_format) {
            if part.range.contains(&frame) {
                let (state, worker) = frame_state(part, frame, &writing, args.claim_timeout);
                workers.extend(worker);
                by_state.entry(state).or_insert_with(Vec::new).push(frame);
                states.push(state);
            }
        }
        // A frame in a gap between formats' ranges is no format's to hold.
        if !states.is_empty() {
            by_state
                .entry(FrameState::of_formats(&states))
                .or_default()
                .push(frame);
        }
    }
    let total: usize = by_state.values().map(Vec::len).sum();
    let complete = by_state.get(&FrameState::Complete).map_or(0, Vec::len);
    let formats: std::collections::BTreeMap<&str, FormatStatus> = parts
        .iter()
        .zip(&by_format)
        .map(|(part, by_state)| {
            (
                part.formats[0].extension(),
                FormatStatus::of(part, by_state),
            )
        })
        .collect();
    // Once the video's frames are all there: the command that encodes them.
    let video = parts
        .iter()
        .find(|p| p.formats[0] == plan.video_format())
        .unwrap_or(first);
    let video_command = formats
        .get(video.formats[0].extension())
        .filter(|f| f.total > 0 && f.complete == f.total)
        .map(|_| video.video_command(&video.range, video.formats[0]));
    // A folder last rendered from another timeline file (with --force).
    let other_timeline = job
        .as_ref()
        .filter(|job| !job.of_timeline(&plan.timeline.source))
        .map(|job| job.timeline_path.clone());
    let changed = other_timeline.is_none()
        && crate::timeline::read_text(&plan.timeline.source)
            .ok()
            .zip(job)
            .is_some_and(|(now, job)| now != job.timeline_text);
    // The exit status says whether the sequence is complete even when the
    // report's reader has gone (`status out/zoom | head -1`).
    let report = || -> anyhow::Result<()> {
        if args.json {
            #[derive(Serialize)]
            struct StatusReport<'a> {
                folder: &'a Path,
                timeline: &'a Path,
                frames: (u32, u32),
                /// The timeline's own frame count (`frames` may be fewer).
                timeline_frames: u32,
                total: usize,
                complete: usize,
                states: std::collections::BTreeMap<&'a str, &'a Vec<u32>>,
                workers: Vec<String>,
                timeline_changed_since_render: bool,
                /// The timeline the folder was last rendered from, where that
                /// is another file.
                folder_rendered_from: Option<&'a Path>,
                /// Each format's frames, counted on their own.
                formats: &'a std::collections::BTreeMap<&'a str, FormatStatus<'a>>,
                /// The ffmpeg command for the frames counted, once they
                /// are complete in the format a video is made from.
                video_command: Option<&'a str>,
            }
            out!(
                "{}",
                serde_json::to_string(&StatusReport {
                    folder: &plan.out_dir,
                    timeline: &plan.timeline.source,
                    frames: (plan.range.start, plan.range.end),
                    timeline_frames: plan.timeline.frame_count,
                    total,
                    complete,
                    states: by_state.iter().map(|(s, f)| (s.name(), f)).collect(),
                    workers: workers.iter().cloned().collect(),
                    timeline_changed_since_render: changed,
                    folder_rendered_from: other_timeline.as_deref(),
                    formats: &formats,
                    video_command: video_command.as_deref(),
                })?
            );
        } else {
            out!(
                "{}: {complete} of {total} frames complete and current (frames {}..{} of {}, {}x{})",
                plan.out_dir.display(),
                plan.range.start,
                plan.range.end,
                plan.timeline.source.display(),
                plan.width,
                plan.height
            );
            for (state, frames) in &by_state {
                out!(
                    "  {:<12} {:>6}  {}",
                    state.name().replace('_', " "),
                    frames.len(),
                    ranges(frames)
                );
            }
            // Several formats: each on its own line, with what it lacks.
            for (name, f) in formats.iter().filter(|_| formats.len() > 1) {
                let lacking: Vec<String> = (f.states.iter())
                    .filter(|(state, _)| **state != FrameState::Complete.name())
                    .map(|(state, frames)| {
                        format!("; {} {}", state.replace('_', " "), ranges(frames))
                    })
                    .collect();
                out!(
                    "  {name}: {} of {} complete and current (frames {}..{}){}",
                    f.complete,
                    f.total,
                    f.frames.0,
                    f.frames.1,
                    lacking.concat()
                );
            }
            if !workers.is_empty() {
                out!(
                    "  running: {}",
                    workers.iter().cloned().collect::<Vec<_>>().join(", ")
                );
            }
            let all = plan.timeline.frame_count;
            if plan.range != (0..all) {
                out!(
                    "  note: {} has {all} frames; these are the ones counted{}",
                    plan.timeline.source.display(),
                    if args.target.is_dir() && args.sequence.frames.is_none() {
                        format!(" (the ranges rendered into this folder; --frames 0..{all} counts them all)")
                    } else {
                        String::new()
                    }
                );
            }
            if changed {
                out!(
                    "  note: {} has changed since this folder's last render started",
                    plan.timeline.source.display()
                );
            }
            if let Some(other) = &other_timeline {
                out!(
                    "  note: this folder was last rendered from {}, not {}",
                    other.display(),
                    plan.timeline.source.display()
                );
            }
            if let Some(command) = &video_command {
                out!("  encode: {command}");
            }
        }
        Ok(())
    };
    unless_output_closed(report())?;
    if complete == total {
        Ok(())
    } else {
        Err(Incomplete { complete, total }.into())
    }
}

/// The state of `frame` in the one format of `part`, and the worker
/// holding its claim, if a live one does. `writing` holds the frames with
/// a live writer's temporary file.
fn frame_state(
    part: &Plan,
    frame: u32,
    writing: &std::collections::HashSet<u32>,
    claim_timeout: std::time::Duration,
) -> (FrameState, Option<String>) {
    let (_, hash) = part.frame(frame);
    // Each file's header read once, and a file read whole only where
    // its header records these inputs.
    let files = part.file_states(frame, &hash);
    if files
        .iter()
        .all(|&s| s == output::frames::FileState::Current)
    {
        return (FrameState::Complete, None);
    }
    let claim = crate::job::claim::read_claim(&crate::job::claim::claim_path(&part.out_dir, frame))
        .filter(|c| crate::job::claim::is_live(c, claim_timeout));
    if let Some(claim) = claim {
        return (FrameState::InProgress, Some(claim.who()));
    }
    let state = if writing.contains(&frame) {
        FrameState::InProgress
    } else if crate::job::checkpoint::checkpoint_is_for(
        &crate::job::checkpoint::checkpoint_path(&part.out_dir, frame),
        output::frames::light_hash(&hash),
        part.width,
        part.height,
        part.layers(),
    ) {
        FrameState::Resumable
    } else if files.contains(&output::frames::FileState::Damaged) {
        FrameState::Damaged
    } else if files.contains(&output::frames::FileState::Stale) {
        FrameState::Stale
    } else {
        FrameState::Missing
    };
    (state, None)
}

/// One format's frames in a `status` report.
#[derive(Serialize)]
struct FormatStatus<'a> {
    frames: (u32, u32),
    total: usize,
    complete: usize,
    states: std::collections::BTreeMap<&'a str, &'a Vec<u32>>,
}

impl<'a> FormatStatus<'a> {
    fn of(part: &Plan, by_state: &'a std::collections::BTreeMap<FrameState, Vec<u32>>) -> Self {
        FormatStatus {
            frames: (part.range.start, part.range.end),
            total: by_state.values().map(Vec::len).sum(),
            complete: by_state.get(&FrameState::Complete).map_or(0, Vec::len),
            states: by_state.iter().map(|(s, f)| (s.name(), f)).collect(),
        }
    }
}

/// `status` found frames still to do: exit code 4, not an error message.
#[derive(Debug)]
pub struct Incomplete {
    pub complete: usize,
    pub total: usize,
}

impl std::fmt::Display for Incomplete {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} of {} frames are not complete",
            self.total - self.complete,
            self.total
        )
    }
}

impl std::error::Error for Incomplete {}

fn info(path: &Path) -> anyhow::Result<()> {
    let t = Timeline::load(path)?;
    let first = t.scene_at(0);
    let base = &first;
    out!("timeline: {}", path.display());
    out!(
        "frames:   {} at {} fps ({:.3} s), {}x{} pixels, {} sample(s) per pixel",
        t.frame_count,
        t.fps,
        t.duration_seconds(),
        t.width,
        t.height,
        base.samples_per_pixel
    );
    if t.looping {
        out!(
            "loop:     seamless: every track repeats every {:.3} s, so frame {} would be frame 0 again",
            t.duration_seconds(),
            t.frame_count
        );
    }
    let f = &base.fractal;
    let animated_julia = t.tracks.iter().any(|tr| tr.name == "fractal.julia");
    let mode = match (f.julia, animated_julia) {
        (_, true) => "Julia mode (constant animated)".to_string(),
        (Some(k), false) => format!("Julia mode, c = ({}, {}, {})", k.x, k.y, k.z),
        (None, false) => "Mandelbrot mode".to_string(),
    };
    out!(
        "fractal:  {mode}, formula {}, power {}, {} iterations, bailout {} (at frame 0)",
        f.formula.name(),
        f.power,
        f.iterations,
        f.bailout
    );
    let walk = match base.quality.membership_step {
        0.0 => String::new(),
        step => format!(", membership walk in steps of {step} x footprint"),
    };
    out!(
        "quality:  DE {} in {}, hit threshold {} x footprint{walk}, fudge {}, {} max steps",
        f.de.name(),
        f.precision.name(),
        base.quality.hit_threshold,
        base.quality.fudge,
        base.quality.max_steps
    );
    if t.tracks.is_empty() {
        out!("tracks:   none (a still)");
    } else {
        out!("tracks:");
        for tr in &t.tracks {
            let first = tr.key_times[0];
            let last = tr.key_times[tr.key_times.len() - 1];
            let mut line = format!(
                "  {:<24} {:<10} {} key(s), {first:.3} s .. {last:.3} s",
                tr.name,
                format!("{:?}", tr.interpolation),
                tr.key_times.len()
            );
            if tr.name == ZOOM_TRACK {
                let (mut a, mut b) = (tr.sample(first)[0], tr.sample(last)[0]);
                if t.looping {
                    // The last key may be the first again: the zoom's
                    // reach is between its farthest and nearest frames.
                    // (Every frame, or 10 000 spread over a longer film.)
                    let step = (t.frame_count / 10_000).max(1) as usize;
                    let frames = (0..t.frame_count).step_by(step);
                    let d: Vec<f64> = frames.map(|f| tr.sample(t.time_of(f))[0]).collect();
                    a = d.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                    b = d.iter().copied().fold(f64::INFINITY, f64::min);
                }
                line += &format!(
                    "  (log-space zoom {a:.3e} -> {b:.3e}, {:.1} decades)",
                    (a / b).log10().abs()
                );
            }
            out!("{line}");
        }
    }
    let effects = &base.effects;
    let enabled = effects.enabled();
    out!(
        "effects:  {}",
        if enabled.is_empty() {
            "none enabled (baseline shading: Lambert light + ambient, orbit-trap colour)"
                .to_string()
        } else {
            enabled.join(", ")
        }
    );
    // The render plan: which stages run per camera sample, and their cost in
    // distance estimates relative to marching (about 20 per ray at this size).
    let cones = match (base.cone_rays(), base.march_alone_reason()) {
        (1, Some(why)) => format!("each camera ray alone, {why}"),
        (1, None) => "each camera ray alone".to_string(),
        (n, _) => {
            let (columns, rows) = crate::march::cone_block(n);
            format!("blocks of {columns}×{rows} camera rays share a cone first")
        }
    };
    out!("plan:     per sample: primary march ({cones}); per hit: normal (4 estimates)");
    if let Some(sh) = &effects.shadows {
        out!(
            "          + shadow march towards the light, up to {} estimates per lit hit ({})",
            sh.max_steps,
            if sh.softness > 0.0 {
                format!("soft, k = {}", sh.softness)
            } else {
                "hard".into()
            }
        );
    }
    if let Some(ao) = &effects.ambient_occlusion {
        out!(
            "          + ambient occlusion, {} estimates per hit",
            ao.samples
        );
    }
    if effects.specular.is_some() {
        out!("          + specular highlight (no estimates)");
    }
    if effects.fog.is_some() {
        out!("          + fog over hit distance (no estimates)");
    }
    if effects.glow.is_some() {
        out!("          + glow from each ray's nearest approach (no estimates; its rays march without cones)");
    }
    if let Some(pt) = &effects.path_tracing {
        out!(
            "          + path tracing per hit: up to {} bounces (Russian roulette from the third), each with a march and a normal, plus a ray to the {}° sun",
            pt.max_bounces, pt.sun_angle_degrees
        );
    }
    if let Some(m) = &effects.motion_blur {
        out!(
            "          + motion blur: each of the {} samples sees the timeline at its own time over {} of the frame interval",
            base.samples_per_pixel, m.shutter
        );
    }
    let lens = base.camera.frame();
    if lens.has_lens() {
        out!(
            "          + depth of field: thin lens of radius {}, focused at {:.4} (rays from the lens; needs samples_per_pixel of {} or more)",
            lens.aperture_radius, lens.focus_distance, crate::scene::LENS_SAMPLES
        );
    }
    out!(
        "          {} sample(s) per pixel: {}x the per-sample work",
        base.samples_per_pixel,
        base.samples_per_pixel
    );
    // Measured, not guessed: frame 0 as a thumbnail, as declared and with
    // every effect off, counting the estimates.
    let probe = cost_probe(&t);
    match &probe {
        Some(p) => out!(
            "cost:     frame 0 at {}x{}{}: {} estimates, {:.2}x the same frame without effects ({})",
            p.width,
            p.height,
            if p.samples < base.samples_per_pixel {
                format!(" with {} of its {} samples per pixel", p.samples, base.samples_per_pixel)
            } else {
                String::new()
            },
            p.with.de_evaluations,
            p.with.de_evaluations as f64 / p.without.de_evaluations.max(1) as f64,
            p.without.de_evaluations
        ),
        None => out!(
            "cost:     not measured: one sample of frame 0 could compute {} orbits of {} \
             iterations (every march to quality.max_steps); render it with --frames 0 --stats",
            worst_orbits_per_sample(base),
            base.fractal.iterations
        ),
    }
    let probe_short = probe.is_some_and(|p| out_of_steps_matters(&p.with));
    out!("output:   out/{}/ by default", t.name);
    let all: Vec<u32> = (0..t.frame_count).collect();
    for warning in warnings(&t, &all, true) {
        out!("warning:  {warning}");
    }
    if probe_short {
        out!(
            "warning:  {} (of the thumbnail)",
            out_of_steps_warning(&[0], &t)
        );
    }
    Ok(())
}

/// The side of the largest thumbnail `info` measures a frame's cost on.
const PROBE_SIDE: u32 = 64;
/// The most samples per pixel a thumbnail takes.
const PROBE_SAMPLES: u32 = 16;
/// Orbit iterations the first thumbnail may take at the very worst (every
/// march to its last step, every orbit to its last iteration): under a
/// second on one core.
const PROBE_WORST_ITERATIONS: u64 = 25_000_000;
/// Orbit iterations a larger thumbnail may be expected to take, from the
/// orbits the one before it took: about half a second on two cores.
const PROBE_ITERATIONS: u64 = 30_000_000;
/// Seconds a thumbnail may take for the next, four times as large, to be
/// rendered: where orbits are slower than their weight says.
const PROBE_STAGE_SECONDS: f64 = 0.1;

/// Frame 0 rendered small by `cost_probe`, as declared (`with`) and with
/// every effect off.
struct Probe {
    width: u32,
    height: u32,
    samples: u32,
    with: FrameStats,
    without: FrameStats,
}

/// A frame's size scaled to fit in `side`×`side` pixels, aspect kept, at
/// least 1×1 (a tall, narrow frame makes a tall, narrow thumbnail, not a
/// 64-pixel-wide one thousands of pixels high).
fn thumbnail_size(width: u32, height: u32, side: u32) -> (u32, u32) {
    let long = width.max(height) as u64;
    let scale = |n: u32| ((n as u64 * side as u64) / long).max(1) as u32;
    (scale(width), scale(height))
}

/// The most orbits one camera sample of `s` can compute: its march to the
/// last step and bisection (about 1 100 at most) and a normal; each
/// light's shadow march; every occlusion sample; each bounce's march,
/// normal and march towards each light. Gradient estimators take five
/// orbits an estimate.
fn worst_orbits_per_sample(s: &crate::scene::Scene) -> u64 {
    let march = s.quality.max_steps as u64 + 1_200 + 6;
    let lights = 1 + s.look.extra_lights.len() as u64;
    let e = &s.effects;
    let shadows = e
        .shadows
        .as_ref()
        .map_or(0, |sh| lights * sh.max_steps as u64);
    let occlusion = e
        .ambient_occlusion
        .as_ref()
        .map_or(0, |ao| ao.samples as u64);
    let bounces = e
        .path_tracing
        .as_ref()
        .map_or(0, |pt| pt.max_bounces as u64 * (1 + lights) * march);
    let orbits = match s.fractal.de {
        crate::fractal::DeMethod::Analytic | crate::fractal::DeMethod::Jacobian => 1,
        _ => 5,
    };
    (march + shadows + occlusion + bounces) * orbits
}

/// Frame 0 of `t` as thumbnails of growing size, so that `info` answers
/// at once whatever the timeline asks: the first small enough that even
/// its worst case stays within `PROBE_WORST_ITERATIONS`, then each twice
/// as wide while the orbits the last one took, scaled up, stay within
/// `PROBE_ITERATIONS`, up to `PROBE_SIDE`. None if one sample alone could
/// take more.
fn cost_probe(t: &Timeline) -> Option<Probe> {
    let mut samples = t.base.samples_per_pixel.min(PROBE_SAMPLES);
    let scenes = |samples: u32| t.clone().with_samples(Some(samples)).scenes_for_frame(0);
    let first = &scenes(1)[0];
    let iterations = first.fractal.iterations as u64 * iteration_weight(&first.fractal);
    let per_sample = worst_orbits_per_sample(first) * iterations;
    let pixels = |side: u32| {
        let (w, h) = thumbnail_size(t.width, t.height, side);
        w as u64 * h as u64
    };
    let mut side = 8;
    while side > 1 && pixels(side) * samples as u64 * per_sample > PROBE_WORST_ITERATIONS {
        side /= 2;
    }
    while samples > 1 && samples as u64 * per_sample > PROBE_WORST_ITERATIONS {
        samples /= 2;
    }
    if per_sample > PROBE_WORST_ITERATIONS {
        return None;
    }
    // Frame 0's instants and iterations (a track may animate them) at the
    // thumbnail's samples.
    let scenes = scenes(samples);
    let iterations = scenes
        .iter()
        .map(|s| s.fractal.iterations as u64 * iteration_weight(&s.fractal))
        .max()?;
    let render = |scenes: &[crate::scene::Scene], side: u32| {
        let (w, h) = thumbnail_size(t.width, t.height, side);
        let mut film = crate::render::Film::default();
        let layers = crate::render::Layers::default();
        crate::render::render_frame_into(&mut film, scenes, 0, w, h, layers, &|| {});
        film.stats
    };
    let mut started = Instant::now();
    let mut with = render(&scenes, side);
    while side < PROBE_SIDE {
        let grown = with.de_evaluations * pixels(side * 2) / pixels(side).max(1);
        let slow = started.elapsed().as_secs_f64() > PROBE_STAGE_SECONDS;
        if slow || grown.saturating_mul(iterations) > PROBE_ITERATIONS {
            break;
        }
        side *= 2;
        started = Instant::now();
        with = render(&scenes, side);
    }
    let plain: Vec<_> = scenes
        .iter()
        .map(|s| crate::scene::Scene {
            effects: crate::shade::Effects {
                motion_blur: s.effects.motion_blur.clone(),
                ..Default::default()
            },
            ..s.clone()
        })
        .collect();
    let (width, height) = thumbnail_size(t.width, t.height, side);
    Some(Probe {
        width,
        height,
        samples,
        with,
        without: render(&plain, side),
    })
}

#[derive(Serialize)]
struct PickReport {
    frame: u32,
    pixel: [u32; 2],
    size: [u32; 2],
    ray_origin: [f64; 3],
    ray_direction: [f64; 3],
    hit: bool,
    point: Option<[f64; 3]>,
    distance: Option<f64>,
    normal: Option<[f64; 3]>,
    /// Width of the pixel's cone at the hit, or at the far side of the
    /// bounding sphere; none where the ray misses the sphere.
    pixel_footprint: Option<f64>,
    fractal: PickFractal,
}

#[derive(Serialize)]
struct PickFractal {
    formula: &'static str,
    power: f64,
    iterations: u32,
    bailout: f64,
    julia: Option<[f64; 3]>,
}

fn pick(args: PickArgs) -> anyhow::Result<()> {
    let t = Timeline::load(&args.timeline)?;
    let (width, height) = match &args.size {
        Some(s) => parse_size("--size", s)?,
        None => (t.width, t.height),
    };
    check_frame(&t, args.frame)?;
    let bad = || {
        Error::usage(
            "--pixel",
            format!("expected X,Y inside {width}x{height}, got {:?}", args.pixel),
        )
    };
    let (x, y) = args.pixel.split_once(',').ok_or_else(bad)?;
    let (x, y): (u32, u32) = (
        x.trim().parse().map_err(|_| bad())?,
        y.trim().parse().map_err(|_| bad())?,
    );
    if x >= width || y >= height {
        return Err(bad().into());
    }
    let scene = t.scene_at(args.frame);
    let camera = scene.camera.frame();
    let ray = camera.ray(x as f64 + 0.5, y as f64 + 0.5, width, height);
    let result = march(&ray, &scene.fractal, &scene.quality);
    let hit = result
        .hit
        .map(|h| (h, normal(&ray, &h, &scene.fractal, &scene.quality).0));
    let arr = |v: crate::math::DVec3| [v.x, v.y, v.z];
    let report = PickReport {
        frame: args.frame,
        pixel: [x, y],
        size: [width, height],
        ray_origin: arr(ray.origin),
        ray_direction: arr(ray.dir),
        hit: hit.is_some(),
        point: hit.map(|(h, _)| arr(h.point)),
        distance: hit.map(|(h, _)| h.t),
        normal: hit.map(|(_, n)| arr(n)),
        pixel_footprint: hit
            .map(|(h, _)| h.t)
            .or_else(|| scene.quality.interval(&ray).map(|(_, far)| far))
            .map(|t| ray.footprint(t)),
        fractal: PickFractal {
            formula: scene.fractal.formula.name(),
            power: scene.fractal.power,
            iterations: scene.fractal.iterations,
            bailout: scene.fractal.bailout,
            julia: scene.fractal.julia.map(arr),
        },
    };
    if args.json {
        out!("{}", serde_json::to_string(&report)?);
        return Ok(());
    }
    out!("frame {}, pixel ({x}, {y}) of {width}x{height}", args.frame);
    match hit {
        Some((h, n)) => {
            out!(
                "hit:       ({:.12}, {:.12}, {:.12})",
                h.point.x,
                h.point.y,
                h.point.z
            );
            out!("distance:  {:.6e} along the ray from the camera", h.t);
            out!("normal:    ({:.4}, {:.4}, {:.4})", n.x, n.y, n.z);
            out!(
                "footprint: {:.3e} (one pixel's width there)",
                ray.footprint(h.t)
            );
            out!(
                "As a zoom target:  target: ({:.12}, {:.12}, {:.12})",
                h.point.x,
                h.point.y,
                h.point.z
            );
        }
        None => out!("miss: the ray leaves the bounding sphere without meeting the fractal"),
    }
    Ok(())
}

/// Rejects a `--frame` past the timeline's last frame.
fn check_frame(t: &Timeline, frame: u32) -> Result<()> {
    if frame >= t.frame_count {
        return Err(Error::usage(
            "--frame",
            format!(
                "frame {frame} is past the last frame ({})",
                t.frame_count - 1
            ),
        ));
    }
    Ok(())
}

/// Sizes rayon's pool to `--threads` when given.
fn set_threads(threads: Option<usize>) -> Result<()> {
    if let Some(n) = threads {
        // More threads than cores only cost their start-up (10 000 took
        // 44 s for a 64×36 frame): a thousand is past any machine's cores.
        const MAX_THREADS: usize = 1024;
        if !(1..=MAX_THREADS).contains(&n) {
            return Err(Error::usage(
                "--threads",
                format!("must be 1..={MAX_THREADS}, got {n}"),
            ));
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| Error::usage("--threads", e.to_string()))?;
    }
    Ok(())
}

fn accuracy(args: AccuracyArgs) -> anyhow::Result<()> {
    // Before the timeline, whose frames are checked on the thread pool.
    set_threads(args.threads)?;
    let t = Timeline::load(&args.timeline)?.with_samples(args.samples);
    let (width, height) = match &args.size {
        Some(s) => parse_size("--size", s)?,
        None => {
            let w = t.width.min(160);
            (
                w,
                ((w as u64 * t.height as u64) / t.width as u64).max(1) as u32,
            )
        }
    };
    check_frame(&t, args.frame)?;
    let out_dir = args
        .out
        .clone()
        .unwrap_or_else(|| Path::new("out").join(&t.name));
    std::fs::create_dir_all(&out_dir).map_err(|e| Error::io(&out_dir, e))?;
    let scene = t.scene_at(args.frame);
    let quiet = args.quiet;
    let report = crate::accuracy::measure(&scene, args.frame, width, height, &|i, n, v| {
        if !quiet {
            eprintln!("[{}/{}] {} = {}", i + 1, n, v.knob, v.setting);
        }
    });
    let title = format!(
        "What accuracy costs: {} frame {} at {width}x{height}, {} threads",
        t.name,
        args.frame,
        rayon::current_num_threads()
    );
    let csv = out_dir.join("accuracy.csv");
    let md = out_dir.join("accuracy.md");
    let png = out_dir.join("accuracy.png");
    let table = crate::accuracy::to_markdown(&report, &format!("## {title}"));
    std::fs::write(&csv, crate::accuracy::to_csv(&report.rows)).map_err(|e| Error::io(&csv, e))?;
    std::fs::write(&md, &table).map_err(|e| Error::io(&md, e))?;
    crate::accuracy::write_chart(&report.rows, &title, &png)?;
    out!("{table}");
    eprintln!(
        "wrote {}, {} and {}",
        csv.display(),
        md.display(),
        png.display()
    );
    Ok(())
}

fn sheet(args: SheetArgs) -> anyhow::Result<()> {
    if args.count == 0 || args.columns == 0 || args.thumb_width == 0 {
        return Err(Error::usage("--count/--columns/--thumb-width", "must be at least 1").into());
    }
    let out = args.out.unwrap_or_else(|| args.dir.join("sheet.png"));
    if !out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"))
    {
        let message = format!("the sheet is a PNG: name it .png, not {}", out.display());
        return Err(Error::usage("--out", message).into());
    }
    let frames = output::frames::frame_files(&args.dir, Format::Png)?;
    if frames.is_empty() {
        // A --preview render's frames are a folder further down.
        let preview = args.dir.join("preview");
        let hint =
            if output::frames::frame_files(&preview, Format::Png).is_ok_and(|f| !f.is_empty()) {
                format!(" (a preview's are in {})", preview.display())
            } else {
                String::new()
            };
        return Err(Error::usage(
            &args.dir.display().to_string(),
            format!("no frame_NNNNN.png files in this folder{hint}"),
        )
        .into());
    }
    let shown = output::sheet::evenly_spaced(&frames, args.count);
    output::sheet::write_contact_sheet(&shown, args.columns, args.thumb_width, &out)?;
    out!(
        "{} frames of {} tiled into {}",
        shown.len(),
        frames.len(),
        out.display()
    );
    Ok(())
}

/// `bench`: checks the options, runs the benchmark, prints the tables.
fn bench(args: BenchArgs) -> anyhow::Result<()> {
    let peak = crate::bench::Peak::detect();
    let logical_cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
    let memory_size = match args.memory_size.as_str() {
        "none" => None,
        text => Some(parse_size("--memory-size", text)?),
    };
    let depth_size = match args.depth_size.as_str() {
        "none" => None,
        text => Some(parse_size("--depth-size", text)?),
    };
    if args.runs == 0 {
        return Err(Error::usage("--runs", "must be at least 1").into());
    }
    let threads = if args.threads.is_empty() {
        let mut t: Vec<usize> = std::iter::successors(Some(1), |n| Some(n * 2))
            .take_while(|&n| n < logical_cpus)
            .collect();
        t.push(logical_cpus);
        t
    } else {
        args.threads.clone()
    };
    if threads.contains(&0) {
        return Err(Error::usage("--threads", "thread counts must be at least 1").into());
    }
    let mandelbulber = (!args.no_mandelbulber)
        .then(|| {
            std::process::Command::new(&args.mandelbulber)
                .arg("--version")
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::null())
                .status()
                .is_ok_and(|s| s.success())
                .then(|| args.mandelbulber.clone())
        })
        .flatten();
    if mandelbulber.is_none() && !args.quiet {
        eprintln!(
            "Mandelbulber2 not compared ({}): install it (Debian: apt-get install mandelbulber2) for the A/B rows",
            if args.no_mandelbulber { "--no-mandelbulber" } else { "not found" }
        );
    }
    let options = crate::bench::Options {
        scenes: args.scenes,
        fract_dir: args.fract_dir,
        mandelbulber,
        runs: args.runs,
        threads,
        memory_size,
        depth_size,
        results: args.results.clone(),
        machine: args
            .machine
            .unwrap_or_else(|| crate::bench::default_machine_name(&peak)),
        peak,
        quiet: args.quiet,
    };
    let md = crate::bench::run_and_write(&options)?;
    out!("{md}");
    out!(
        "written: {}",
        options
            .results
            .join(format!("{}.csv", options.machine))
            .display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_ranges_are_read_as_rust_writes_them() {
        assert_eq!(parse_frames("0..4", 10).unwrap(), 0..4);
        assert_eq!(parse_frames("0..=3", 10).unwrap(), 0..4);
        assert_eq!(parse_frames("..=9", 10).unwrap(), 0..10);
        assert!(parse_frames("0..=10", 10).is_err());
        assert!(parse_frames("3..=", 10).is_err());
        assert!(parse_frames("4..=3", 10).is_err());
        assert_eq!(parse_frames("3..", 10).unwrap(), 3..10);
        assert_eq!(parse_frames("..2", 10).unwrap(), 0..2);
        assert_eq!(parse_frames("7", 10).unwrap(), 7..8);
        assert!(parse_frames("4..4", 10).is_err());
        assert!(parse_frames("5..11", 10)
            .unwrap_err()
            .to_string()
            .contains("10 frames"));
        assert!(parse_frames("a..b", 10).is_err());
        // A dash, as other tools write ranges: the two-dot form is suggested.
        let e = parse_frames("0-3", 10).unwrap_err().to_string();
        assert!(e.contains("written with two dots: 0..3"), "{e}");
        let e = parse_frames("-3", 10).unwrap_err().to_string();
        assert!(!e.contains("two dots"), "{e}");
    }

    #[test]
    fn a_long_list_of_missing_frames_is_cut_short() {
        assert_eq!(frame_summary(&[1, 2, 3, 7]), "1-3, 7");
        let every_other: Vec<u32> = (0..100).step_by(2).collect();
        assert_eq!(frame_summary(&every_other), "0, 2, 4, 6, 8, … (50 frames)");
        assert_eq!(frames_text(&(5..6)), "frame 5");
        assert_eq!(frames_text(&(0..3)), "frames 0-2");
    }

    #[test]
    fn cost_thumbnails_keep_the_aspect_within_64_pixels_a_side() {
        // A tall, narrow frame made a thumbnail 64 wide and two million
        // high; now no frame's has more than 64×64 pixels.
        assert_eq!(thumbnail_size(320, 180, 64), (64, 36));
        assert_eq!(thumbnail_size(48, 27, 64), (64, 36));
        assert_eq!(thumbnail_size(1, 32_768, 64), (1, 64));
        assert_eq!(thumbnail_size(1, 135, 64), (1, 64));
        assert_eq!(thumbnail_size(32_768, 1, 8), (8, 1));
        for (w, h) in [(1, 1), (3, 32_768), (32_768, 32_768), (777, 5)] {
            let (tw, th) = thumbnail_size(w, h, PROBE_SIDE);
            assert!((1..=PROBE_SIDE).contains(&tw) && (1..=PROBE_SIDE).contains(&th));
        }
    }

    #[test]
    fn sizes_parse_and_reject_zero() {
        assert_eq!(parse_size("--size", "640x360").unwrap(), (640, 360));
        assert!(parse_size("--size", "0x360").is_err());
        assert!(parse_size("--size", "640").is_err());
    }

    #[test]
    fn ffmpeg_command_has_rate_start_and_count() {
        let c = ffmpeg_command(Path::new("out/zoom"), "zoom", 24.0, &(10..20), Format::Png);
        assert!(
            c.contains("-framerate 24 -start_number 10 -i out/zoom/frame_%05d.png -frames:v 10"),
            "{c}"
        );
        assert!(c.ends_with("out/zoom/zoom.mp4"));
        let spaced = ffmpeg_command(Path::new("my out"), "z", 30.0, &(0..5), Format::Exr);
        assert!(
            spaced.contains("-apply_trc iec61966_2_1 -i 'my out/frame_%05d.exr'"),
            "{spaced}"
        );
        let percent = ffmpeg_command(Path::new("take 100%"), "z", 24.0, &(0..5), Format::Png);
        assert!(
            percent.contains("-i 'take 100%%/frame_%05d.png'")
                && percent.ends_with("'take 100%/z.mp4'"),
            "{percent}"
        );
    }
}
