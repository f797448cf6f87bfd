//! The subcommands' arguments as clap declares them, and their conversion
//! into the job's plain `Request` and `Sequence`.

use crate::job::{Request, Sequence};
use crate::output::names::FrameName;
use crate::output::{self, Format};
use std::path::PathBuf;

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
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=crate::job::request::MAX_SAMPLES as i64))]
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
    /// Folder holding PNG frames (frame_00000.png, …).
    pub dir: PathBuf,
    /// How the frames are named, as render's --frame-name [default: what the
    /// folder's mandelreel-job.json records, else frame_#####].
    #[arg(long, value_name = "PATTERN")]
    pub frame_name: Option<FrameName>,
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
    /// Mark each thumbnail with its frame number (the number its name's # run holds),
    /// light on a dark box in its top-left corner.
    #[arg(long)]
    pub labels: bool,
}

#[derive(Debug, clap::Args)]
pub struct QualityArgs {
    /// Folder holding the PNG frames to measure (frame_00000.png, …).
    pub dir: PathBuf,
    /// Folder of a reference render of the same frames (more samples, finer
    /// settings): each frame's PSNR is measured against the frame of its number there.
    #[arg(long, value_name = "REFDIR")]
    pub reference: Option<PathBuf>,
    /// Frames to measure, by number, as a Rust range: 0..4 is frames 0 to 3, 0..=4
    /// frames 0 to 4; also A.., ..B, or N [default: every frame in DIR].
    #[arg(long, value_name = "A..B")]
    pub frames: Option<String>,
    /// How the frames are named in both folders, as render's --frame-name [default:
    /// what each folder's mandelreel-job.json records, else frame_#####].
    #[arg(long, value_name = "PATTERN")]
    pub frame_name: Option<FrameName>,
    /// Print the measures as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
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
          value_parser = clap::value_parser!(u32).range(1..=crate::job::request::MAX_SAMPLES as i64))]
    pub samples: Option<u32>,
    /// Extra EXR layers, comma-separated (needs --format exr): normal, albedo, traps, steps.
    #[arg(long, value_enum, value_delimiter = ',')]
    pub aov: Vec<output::Aov>,
    /// EXR compression: zip (default), piz, rle, zips and none keep every
    /// sample; pxr24, b44, b44a, dwaa and dwab are lossy.
    #[arg(long, value_enum, value_name = "METHOD", hide_possible_values = true)]
    pub exr_compression: Option<output::exr::ExrCompression>,
    /// Name frame files by this pattern: one run of # is the frame number,
    /// zero-padded to its length (shot_#### gives shot_0042.png) [default: frame_#####].
    #[arg(long, value_name = "PATTERN")]
    pub frame_name: Option<FrameName>,
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
    /// An output folder (uses what it records; --frames and --format pick a part),
    /// or a timeline (with the same --out, --size, --format, --aov, --samples,
    /// --frames and --preview as its render). Every frame of the film counts
    /// unless --frames names some.
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
pub struct ExploreArgs {
    /// The RON timeline to explore and edit; none starts a new one, saved
    /// under a name you give in the page.
    pub timeline: Option<PathBuf>,
    /// The address to listen on. Anything but loopback lets other machines
    /// reach the page (they still need its token), and needs --network.
    #[arg(long, default_value = "127.0.0.1", value_name = "ADDRESS")]
    pub bind: std::net::IpAddr,
    /// Serve other machines, with a --bind address other than loopback. The
    /// page, its token and your edits travel as plain HTTP, which anyone on
    /// the way can read: use it on a network you trust.
    #[arg(long)]
    pub network: bool,
    /// The port to listen on; 0 takes any free one.
    #[arg(long, default_value = "0", value_name = "PORT")]
    pub port: u16,
}

impl TryFrom<ExploreArgs> for crate::explore::Options {
    type Error = crate::error::Error;

    /// Refuses an address beyond loopback without --network.
    fn try_from(args: ExploreArgs) -> Result<Self, Self::Error> {
        if !args.bind.is_loopback() && !args.network {
            return Err(crate::error::Error::usage(
                "--bind",
                format!(
                    "{} lets other machines reach the page, over plain HTTP: add --network to mean it",
                    args.bind
                ),
            ));
        }
        Ok(crate::explore::Options {
            timeline: args.timeline,
            bind: args.bind,
            port: args.port,
        })
    }
}

#[derive(Debug, clap::Args)]
pub struct PickArgs {
    /// The RON timeline file.
    pub timeline: PathBuf,
    /// Frame whose camera and fractal are used.
    #[arg(long, default_value_t = 0)]
    pub frame: u32,
    /// Pixel column and row, from the top-left corner.
    #[arg(long, value_name = "X,Y", required_unless_present = "refine")]
    pub pixel: Option<String>,
    /// Re-centre the target on the surface under the centre of the view,
    /// zooming in steps (up to a thousand times closer each) from a
    /// thousandth of the target's size down to this frame's camera
    /// distance; prints the new `target:` line with all the digits that
    /// depth needs, and checks that its orbit resolves the frame's pixels.
    #[arg(long, conflicts_with = "pixel")]
    pub refine: bool,
    /// Image size the pixel refers to [default: the timeline's].
    #[arg(long, value_name = "WxH")]
    pub size: Option<String>,
    /// Write the point (the hit, or the re-centred target) into TIMELINE as
    /// its `camera.target`, keeping the rest of the file as written.
    #[arg(long, conflicts_with = "json")]
    pub aim: bool,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

impl SequenceArgs {
    /// The sequence asked for, as the job takes it.
    pub fn request(&self) -> Sequence {
        Sequence {
            out: self.out.clone(),
            frames: self.frames.clone(),
            size: self.size.clone(),
            formats: self.format.clone(),
            preview: self.preview,
            samples: self.samples,
            aovs: self.aov.clone(),
            exr_compression: self.exr_compression,
            frame_name: self.frame_name.clone(),
        }
    }
}

impl RenderArgs {
    /// The render asked for, as the job takes it.
    pub fn request(&self) -> Request {
        Request {
            timeline: self.timeline.clone(),
            sequence: self.sequence.request(),
            threads: self.threads,
            force: self.force,
            replace: self.replace,
            shard: self.shard.clone(),
            claim: self.claim,
            claim_timeout: self.claim_timeout,
            verify: self.verify,
            checkpoint_every: self.checkpoint_seconds,
        }
    }
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
