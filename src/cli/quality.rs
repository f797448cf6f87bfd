//! `quality`: reads a folder's PNG frames (and a reference folder's), has
//! the `quality` module measure them, and prints its table or JSON.

use super::QualityArgs;
use crate::error::Error;
use crate::output::names::FrameName;
use crate::output::{self, Format};
use crate::quality::{report, FrameImage, Meter};
use anyhow::Context as _;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Measures the frames and prints what was found.
pub fn quality(args: QualityArgs) -> anyhow::Result<()> {
    let names = names_in(&args.dir, &args.frame_name);
    let mut frames = numbered_frames(&args.dir, &names)?;
    if let Some(text) = &args.frames {
        frames = in_range(frames, text, &args.dir)?;
    }
    let pairs = match &args.reference {
        Some(dir) => with_reference(frames, dir, &names_in(dir, &args.frame_name))?,
        None => frames.into_iter().map(|(n, p)| (n, p, None)).collect(),
    };
    let measured = measure(&pairs);
    let context = match &args.reference {
        Some(r) => format!("{} against {}", args.dir.display(), r.display()),
        None => args.dir.display().to_string(),
    };
    let measured = measured.context(context)?;
    if args.json {
        let json = serde_json::to_string_pretty(&measured).expect("measures serialise");
        out!("{json}");
    } else {
        out!("{}", report::markdown(&measured));
        out!("{}", report::summary(&measured));
    }
    Ok(())
}

/// The frame names `--frame-name` gives, else those `dir` records.
fn names_in(dir: &Path, given: &Option<FrameName>) -> FrameName {
    given
        .clone()
        .unwrap_or_else(|| super::sheet::recorded_names(dir))
}

/// `dir`'s PNG frames of `names`, with their numbers, in frame order; an
/// error if there are none.
fn numbered_frames(dir: &Path, names: &FrameName) -> anyhow::Result<Vec<(u32, PathBuf)>> {
    let files = output::frames::frame_files(dir, Format::Png, names)?;
    let frames: Vec<(u32, PathBuf)> = files
        .into_iter()
        .filter_map(|p| {
            let name = p.file_name()?.to_string_lossy().into_owned();
            Some((names.frame_of(&name, Format::Png)?, p))
        })
        .collect();
    if frames.is_empty() {
        let message =
            format!("no PNG frames named {names} in this folder (--frame-name names others)");
        return Err(Error::usage(&dir.display().to_string(), message).into());
    }
    Ok(frames)
}

/// The frames of `--frames` `text`; an error if that leaves none.
fn in_range(
    frames: Vec<(u32, PathBuf)>,
    text: &str,
    dir: &Path,
) -> anyhow::Result<Vec<(u32, PathBuf)>> {
    // The folder, not a timeline, says how many frames there are.
    let range = crate::job::frames::parse_frames(text, u32::MAX)?;
    let numbers: Vec<u32> = frames.iter().map(|(n, _)| *n).collect();
    let kept: Vec<(u32, PathBuf)> = frames
        .into_iter()
        .filter(|(n, _)| range.contains(n))
        .collect();
    if kept.is_empty() {
        let has = crate::job::frames::frame_summary(&numbers);
        let message = format!("no frames of {text} in {} (it has {has})", dir.display());
        return Err(Error::usage("--frames", message).into());
    }
    Ok(kept)
}

/// Each of `frames` with its reference frame file in `dir`, by number;
/// an error naming the first frame `dir` lacks.
fn with_reference(
    frames: Vec<(u32, PathBuf)>,
    dir: &Path,
    names: &FrameName,
) -> anyhow::Result<Vec<FrameFiles>> {
    let mut pairs = Vec::with_capacity(frames.len());
    for (frame, path) in frames {
        let reference = dir.join(names.file_name(frame, Format::Png));
        if !reference.is_file() {
            let missing = reference.display();
            let message = format!("the reference has no such frame: {missing} is missing");
            return Err(Error::Frame { frame, message }.into());
        }
        pairs.push((frame, path, Some(reference)));
    }
    Ok(pairs)
}

/// A frame's number, its file, and its reference's file if there is one.
type FrameFiles = (u32, PathBuf, Option<PathBuf>);

/// Reads and measures the frames a few at a time (decoding in parallel),
/// so a long sequence is never all in memory.
fn measure(pairs: &[FrameFiles]) -> crate::error::Result<crate::quality::SequenceQuality> {
    let mut meter = Meter::default();
    for batch in pairs.chunks(batch_size(pairs)) {
        let decoded: Vec<(FrameImage, Option<image::RgbImage>)> = batch
            .par_iter()
            .map(|(frame, path, reference)| {
                let image = read_png(path)?;
                let reference = reference.as_deref().map(read_png).transpose()?;
                Ok((
                    FrameImage {
                        frame: *frame,
                        image,
                    },
                    reference,
                ))
            })
            .collect::<crate::error::Result<_>>()?;
        for (frame, reference) in &decoded {
            meter.add(frame, reference.as_ref())?;
        }
    }
    meter.finish()
}

/// About the most memory the frames decoded at once may take.
const BATCH_BYTES: u64 = 1 << 30;

/// Frames decoded at once: two a thread, fewer where the frames are so
/// large that they would pass `BATCH_BYTES` (a frame and its reference take
/// about 16 bytes a pixel decoded and measured), at least one.
fn batch_size(pairs: &[FrameFiles]) -> usize {
    let pixels = pairs
        .first()
        .and_then(|(_, path, _)| image::image_dimensions(path).ok())
        .map_or(0, |(w, h)| w as u64 * h as u64);
    let fit = BATCH_BYTES / (16 * pixels).max(1);
    (2 * rayon::current_num_threads()).min(fit as usize).max(1)
}

/// A PNG as 8-bit RGB: 16-bit ones scaled down, alpha dropped.
fn read_png(path: &Path) -> crate::error::Result<image::RgbImage> {
    let file = crate::input::open_regular(path).map_err(|e| Error::io(path, e))?;
    let mut reader = image::ImageReader::new(std::io::BufReader::new(file));
    reader.set_format(image::ImageFormat::Png);
    let decoded = reader.decode().map_err(|e| Error::Image {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    Ok(decoded.to_rgb8())
}
