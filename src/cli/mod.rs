//! The command line: clap arguments, one file per subcommand (`render`,
//! `info`, `pick`, `explore`, `sheet`, `status`, `accuracy`, `quality`, `bench`) that turns them
//! into a job's request and prints what comes back, and exit codes.

use crate::error::Error;
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};

/// `println!` that returns an error instead of panicking when standard
/// output is gone (`mandelreel info t.ron | head`): `OutputClosed`, which
/// `run` turns into a quiet success.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout(), $($arg)*).map_err($crate::cli::stdout_error)?
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

mod accuracy;
mod args;
mod bench;
mod info;
mod pick;
mod quality;
mod render;
mod sheet;
mod status;
mod values;

pub use args::{
    AccuracyArgs, BenchArgs, ExploreArgs, PickArgs, QualityArgs, RenderArgs, SequenceArgs,
    SheetArgs, StatusArgs,
};

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
                  Timeline format and examples: docs/timeline.md and timelines/*.ron."
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
    /// Fly around a timeline's fractal in the browser and make its keys there:
    /// starts a local server and prints the page's address.
    Explore(ExploreArgs),
    /// Tile rendered PNG frames from a folder into one contact-sheet image.
    Sheet(SheetArgs),
    /// Which frames of a sequence are complete, stale, missing or in progress; exit
    /// status 0 only when every frame of the film (or of --frames) is complete and
    /// current (4 otherwise).
    Status(StatusArgs),
    /// Measure what accuracy costs: sweep every quality knob, distance estimator and
    /// precision on one frame against a reference; write accuracy.csv, .md and .png.
    Accuracy(AccuracyArgs),
    /// Measure a rendered sequence's image quality: PSNR against a reference render,
    /// speckles and frame-to-frame pops.
    Quality(QualityArgs),
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
    crate::interrupt::survive_file_size_limit();
    let result = match cli.command {
        Command::Render(args) => render::render(args),
        Command::Info { timeline } => info::info(&timeline),
        Command::Pick(args) => pick::pick(args),
        Command::Explore(args) => crate::explore::serve(args.try_into()?),
        Command::Sheet(args) => sheet::sheet(args),
        Command::Status(args) => status::status(args),
        Command::Accuracy(args) => accuracy::accuracy(args),
        Command::Quality(args) => quality::quality(args),
        Command::Bench(args) => bench::bench(args),
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
