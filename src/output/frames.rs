//! Frame files: their names, the hash of the inputs each records, whether a
//! file on disk is current, writing one, and listing a folder's frames and
//! the ones being written.

use super::atomic::write_atomic;
use super::{Aov, Format};
use crate::error::{Error, Result};
use crate::render::Film;
use crate::scene::Scene;
use serde::Serialize;
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// Digits in frame numbers: `frame_00042.png`.
pub const FRAME_DIGITS: usize = 5;

/// `frame_00042.png` for frame 42.
pub fn frame_file_name(frame_index: u32, format: Format) -> String {
    format!(
        "frame_{frame_index:0width$}.{}",
        format.extension(),
        width = FRAME_DIGITS
    )
}

/// The frame number a frame file's name carries: its last run of digits
/// before the extension, whatever comes first (`frame_00042.png` and
/// `shot_v2_0042.exr` are both 42), so names from any pattern are read.
pub fn frame_number(path: &Path) -> Option<u64> {
    let stem = path.file_stem()?.to_str()?;
    let before_digits = stem.trim_end_matches(|c: char| c.is_ascii_digit());
    stem[before_digits.len()..].parse().ok()
}

/// The ffmpeg input pattern matching `frame_file_name`.
pub fn frame_pattern(format: Format) -> String {
    format!("frame_%0{FRAME_DIGITS}d.{}", format.extension())
}

/// Hash of everything that decides a frame's pixels: the effective scenes
/// (one, or one per sample under motion blur), the frame index (it seeds the
/// sampler), the size and the renderer's revision. Not the extra EXR
/// layers, which add channels but change no pixel (`stored_key`). How a
/// PNG shows the light (`Look::exposure`, `Look::tone_map`) follows the
/// hash of the light itself after a `~` (`~exposure=2,Filmic`), where it is
/// not the default: an EXR, which holds the linear light, and a
/// checkpoint are keyed on the light alone (`light_hash`), so a change of
/// grade re-renders no EXR-only sequence and keeps checkpoints.
pub fn frame_hash(scenes: &[Scene], frame_index: u32, width: u32, height: u32) -> String {
    let look = &scenes[0].look;
    let plain = scenes.iter().all(|s| s.look.display_transform().is_plain());
    if plain {
        return light_digest(scenes, frame_index, width, height);
    }
    let light: Vec<Scene> = scenes
        .iter()
        .map(|s| {
            let mut s = s.clone();
            s.look.exposure = 1.0;
            s.look.tone_map = crate::color::ToneMap::Clip;
            s
        })
        .collect();
    let digest = light_digest(&light, frame_index, width, height);
    format!("{digest}~exposure={},{:?}", look.exposure, look.tone_map)
}

/// The part of a `frame_hash` that the linear light depends on.
pub fn light_hash(hash: &str) -> &str {
    hash.split('~').next().unwrap_or(hash)
}

fn light_digest(scenes: &[Scene], frame_index: u32, width: u32, height: u32) -> String {
    #[derive(Serialize)]
    struct Inputs<'a> {
        renderer: &'a str,
        revision: u32,
        frame_index: u32,
        width: u32,
        height: u32,
        scenes: &'a [Scene],
    }
    let inputs = Inputs {
        renderer: env!("CARGO_PKG_VERSION"),
        revision: crate::RENDERER_REVISION,
        frame_index,
        width,
        height,
        scenes,
    };
    let json = serde_json::to_vec(&inputs).expect("a scene of plain numbers always serialises");
    let digest = Sha256::digest(&json);
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

/// What a frame file holds, against the inputs it should record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileState {
    /// No file.
    Missing,
    /// A file that cannot be read, or that records these inputs but is not
    /// whole (cut short by a copy or a full disk, a PNG chunk whose CRC
    /// fails, bytes after its end).
    Damaged,
    /// A readable file made from other inputs, or not by mandelreel.
    Stale,
    /// Made from these inputs, and whole.
    Current,
}

/// The state of the frame file at `path` for inputs `key` (`stored_key`).
/// The header's hash is read first: a stale file costs no more than its
/// header. A file that records `key` is then checked for being whole: by
/// its end (a PNG's IEND chunk is its last bytes; an EXR's last chunk, by
/// its offset table, ends where the file does), which finds a file cut
/// short by a copy or a full disk, or one with bytes after its end, in a
/// few small reads; `thorough` reads every byte instead (every PNG chunk's
/// CRC, every EXR chunk read, not decompressed), which also finds a
/// damaged byte inside a PNG, at the cost of reading the whole file.
pub fn file_state(path: &Path, format: Format, key: &str, thorough: bool) -> FileState {
    // Regular files only: a FIFO under a frame's name would block the open.
    let file = match crate::input::open_regular(path) {
        Ok(file) => std::io::BufReader::new(file),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return FileState::Missing,
        Err(_) => return FileState::Damaged,
    };
    match format {
        Format::Png => super::png::file_state(file, path, key, thorough),
        Format::Exr => super::exr::file_state(file, path, key, thorough),
    }
}

/// What a frame file of `format` records of its inputs: the frame's `hash`,
/// and for an EXR the extra layers it holds too (`hash+normal,steps`), so
/// asking for other layers re-renders the EXR but not the PNG beside it.
pub fn stored_key(format: Format, hash: &str, aovs: &[Aov]) -> String {
    match format {
        Format::Exr if !aovs.is_empty() => {
            let names: Vec<&str> = aovs.iter().map(|a| a.name()).collect();
            format!("{}+{}", light_hash(hash), names.join(","))
        }
        Format::Exr => light_hash(hash).to_string(),
        Format::Png => hash.to_string(),
    }
}

/// Writes `film` as `path` in `format`, atomically: the bytes go to a
/// temporary file of a unique name in the same folder (so two renders into one
/// folder never write into each other's file), are flushed to disk, and only
/// then renamed over the final name.
/// `display` decides how a PNG shows the film's linear light (exposure and
/// tone map); an EXR holds the linear light as it is.
pub fn write_frame(
    path: &Path,
    format: Format,
    film: &Film,
    hash: &str,
    aovs: &[Aov],
    display: crate::color::Display,
) -> Result<()> {
    let image_error = |temp: &Path, message: String| Error::Image {
        path: temp.to_path_buf(),
        message,
    };
    let key = stored_key(format, hash, aovs);
    write_atomic(path, |writer, temp| match format {
        Format::Png => {
            super::png::encode(writer, film, &key, display).map_err(|m| image_error(temp, m))
        }
        Format::Exr => {
            super::exr::encode(writer, film, &key, aovs).map_err(|m| image_error(temp, m))
        }
    })
}

/// Frames a live writer is working on: those with a temporary file (frame,
/// claim or checkpoint) that is not stale.
pub fn frames_being_written(dir: &Path) -> std::collections::HashSet<u32> {
    super::atomic::partials(dir)
        .unwrap_or_default()
        .into_iter()
        .filter(|(_, _, stale)| !stale)
        .filter_map(|(_, name, _)| {
            name.strip_prefix(".frame_")?
                .get(..FRAME_DIGITS)?
                .parse::<u32>()
                .ok()
        })
        .collect()
}

/// The final frame files of `format` in `dir`, in frame order.
pub fn frame_files(dir: &Path, format: Format) -> Result<Vec<PathBuf>> {
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    let suffix = format!(".{}", format.extension());
    let mut frames: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            let name = p
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            name.strip_prefix("frame_")
                .and_then(|rest| rest.strip_suffix(&suffix))
                .is_some_and(|digits| {
                    !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit())
                })
        })
        .collect();
    frames.sort();
    Ok(frames)
}
