//! What a user asks for, as plain values built from the command line's
//! arguments (`Request`, `Sequence`), and the parsing of its text options
//! (sizes, shards, thread counts) into checked ones.

use crate::error::{Error, Result};
use crate::output::names::FrameName;
use crate::output::{Aov, Format};
use crate::timeline::Timeline;
use std::path::PathBuf;
use std::time::Duration;

/// What a sequence is made of, as given: shared by `render` and `status`,
/// so both compute the same frames and hashes (`Plan::new` checks it).
#[derive(Clone, Debug, Default)]
pub struct Sequence {
    /// Output folder [default: out/<timeline name>].
    pub out: Option<PathBuf>,
    /// Frames, as a Rust range (`parse_frames`).
    pub frames: Option<String>,
    /// The output size as `WxH`, overriding the timeline's.
    pub size: Option<String>,
    /// Output formats [default: png].
    pub formats: Vec<Format>,
    /// Quick look: half size, one sample per pixel, in <out>/preview.
    pub preview: bool,
    /// Overrides the timeline's samples_per_pixel.
    pub samples: Option<u32>,
    /// Extra EXR layers.
    pub aovs: Vec<Aov>,
    /// [default: zip]
    pub exr_compression: Option<crate::output::exr::ExrCompression>,
    /// How frame files are named [default: `frame_#####`].
    pub frame_name: Option<FrameName>,
}

/// A render, as asked for: what `job::run` needs, nothing of how it is shown.
#[derive(Clone, Debug)]
pub struct Request {
    pub timeline: PathBuf,
    pub sequence: Sequence,
    /// Worker threads [default: all cores].
    pub threads: Option<usize>,
    /// Render every frame even if a current one exists (implies `replace`).
    pub force: bool,
    /// Render into a folder that holds another sequence's frames.
    pub replace: bool,
    /// `I/N` or `auto` (`parse_shard`).
    pub shard: Option<String>,
    /// Share frames with other workers through claim files.
    pub claim: bool,
    /// Time without a heartbeat after which a claim is taken over.
    pub claim_timeout: Duration,
    /// Read every byte of each finished frame before skipping it.
    pub verify: bool,
    /// How often a frame of several waves saves its progress.
    pub checkpoint_every: Duration,
}

/// The most samples per pixel `--samples` (and the explorer) take.
pub use crate::timeline::MAX_SAMPLES;

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
    let side = crate::timeline::MAX_SIDE;
    if w == 0 || h == 0 || w > side || h > side {
        return Err(Error::usage(
            option,
            format!("width and height must be 1..={side}, got {text:?}"),
        ));
    }
    Ok((w, h))
}

/// Refuses a `--size` that splits `t`'s stereo pair unevenly.
pub fn check_eyes(t: &Timeline, (width, height): (u32, u32)) -> Result<()> {
    match t.base.camera.uneven_eyes([width, height]) {
        Some(message) => Err(Error::usage("--size", message)),
        None => Ok(()),
    }
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

/// Rejects a `--frame` past the timeline's last frame.
pub fn check_frame(t: &Timeline, frame: u32) -> Result<()> {
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
pub fn set_threads(threads: Option<usize>) -> Result<()> {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_reject_zero() {
        assert_eq!(parse_size("--size", "640x360").unwrap(), (640, 360));
        assert!(parse_size("--size", "0x360").is_err());
        assert!(parse_size("--size", "640").is_err());
    }
}
