//! Frame files: their names, the hash of the inputs each records, whether a
//! file on disk is current, writing one, and listing a folder's frames and
//! the ones being written.

use super::atomic::write_atomic;
use super::names::FrameName;
use super::{Aov, Codec, Encoding, FileState, Format, PngKind};
use crate::error::{Error, Result};
use crate::render::Film;
use crate::scene::Scene;
use serde::Serialize;
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// Hash of everything that decides a frame's pixels: the effective scenes
/// (one, or one per sample under motion blur), the frame index (it seeds the
/// sampler), the size and the renderer's revision. Not the extra EXR
/// layers, which add channels but change no pixel (`stored_key`). How a
/// PNG shows the light (`Look::exposure`, `Look::tone_map`) follows the
/// hash of the light itself after a `~` (`~exposure=2,Filmic`), where it is
/// not the default: an EXR, which holds the linear light, and a
/// checkpoint are keyed on the light alone (`light_hash`), so a change of
/// grade re-renders no EXR-only sequence and keeps checkpoints. Not under
/// adaptive sampling, whose samples go where the graded image is noisy:
/// there the grade is part of the light.
pub fn frame_hash(scenes: &[Scene], frame_index: u32, width: u32, height: u32) -> String {
    let look = &scenes[0].look;
    let plain = scenes.iter().all(|s| s.look.display_transform().is_plain());
    if plain || scenes[0].adaptive.is_some() {
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
        /// Only in a deep frame's, so that other frames keep their hashes.
        #[serde(skip_serializing_if = "Option::is_none")]
        deep: Option<u32>,
        /// Only where f32 was asked for and f64 renders (`deep::f32_too_coarse`).
        #[serde(skip_serializing_if = "std::ops::Not::not")]
        f32_in_f64: bool,
        /// Only where a frame renders in f32.
        #[serde(skip_serializing_if = "Option::is_none")]
        f32: Option<u32>,
        /// Only where hits are checked (`MarchSettings::confirm_hits`), so
        /// that the check's frames go stale when it changes and others do not.
        #[serde(skip_serializing_if = "Option::is_none")]
        confirm: Option<u32>,
    }
    let deep = scenes
        .iter()
        .any(|s| crate::deep::needed(s, [width, height]));
    let inputs = Inputs {
        renderer: env!("CARGO_PKG_VERSION"),
        revision: crate::RENDERER_REVISION,
        frame_index,
        width,
        height,
        scenes,
        deep: deep.then_some(crate::deep::DEEP_REVISION),
        f32_in_f64: scenes
            .iter()
            .any(|s| crate::deep::f32_too_coarse(s, [width, height])),
        f32: scenes
            .iter()
            .any(|s| crate::deep::renders_in_f32(s, [width, height]))
            .then_some(crate::fractal::F32_REVISION),
        confirm: scenes
            .iter()
            .any(|s| s.quality.confirm_hits)
            .then_some(crate::march::CONFIRM_REVISION),
    };
    let json = serde_json::to_vec(&inputs).expect("a scene of plain numbers always serialises");
    let digest = Sha256::digest(&json);
    digest.iter().map(|b| format!("{b:02x}")).collect()
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
    match format.codec() {
        Codec::Exr => super::exr::file_state(file, path, key, thorough),
        Codec::Png(_) => super::png::file_state(file, path, key, thorough),
    }
}

/// What a frame file of `format` records of its inputs: the frame's `hash`;
/// for a PNG other than the 8-bit kind, its kind too (`hash+png16`), and for
/// an EXR a lossy compression and the extra layers it holds
/// (`hash+dwaa+normal,steps`, the light's hash alone, as an EXR holds the
/// light undisplayed). So asking for other layers, another PNG kind or a
/// lossy compression re-renders that file but not the one beside it.
pub fn stored_key(
    format: Format,
    hash: &str,
    aovs: &[Aov],
    compression: super::exr::ExrCompression,
) -> String {
    match format.codec() {
        Codec::Exr => {
            // Lossless compressions hold the same samples: any of them is current.
            let mut key = light_hash(hash).to_string();
            if !compression.is_lossless() {
                key = format!("{key}+{}", compression.name());
            }
            if !aovs.is_empty() {
                let names: Vec<&str> = aovs.iter().map(|a| a.name()).collect();
                key = format!("{key}+{}", names.join(","));
            }
            key
        }
        Codec::Png(PngKind::Rgb8) => hash.to_string(),
        Codec::Png(PngKind::Rgb16 | PngKind::Rgba16) => format!("{hash}+{}", format.name()),
    }
}

/// Writes `film` as `path` in `format`, atomically: the bytes go to a
/// temporary file of a unique name in the same folder (so two renders into one
/// folder never write into each other's file), are flushed to disk, and only
/// then renamed over the final name.
/// `encoding` decides how a PNG shows the film's linear light (exposure and
/// tone map; an EXR holds the linear light as it is), whether the
/// background is transparent, and the EXR's compression.
pub fn write_frame(
    path: &Path,
    format: Format,
    film: &Film,
    hash: &str,
    aovs: &[Aov],
    encoding: &Encoding,
) -> Result<()> {
    let image_error = |named: &Path, message: String| Error::Image {
        path: named.to_path_buf(),
        message,
    };
    let key = stored_key(format, hash, aovs, encoding.exr_compression);
    write_atomic(path, |writer, named| match format.codec() {
        Codec::Exr => super::exr::encode(writer, film, &key, aovs, encoding)
            .map_err(|m| image_error(named, m)),
        Codec::Png(kind) => super::png::encode(writer, film, &key, kind, encoding)
            .map_err(|m| image_error(named, m)),
    })
}

/// Frames of `names` a live writer is working on: those with a temporary
/// file of a frame or checkpoint that is not stale.
pub fn frames_being_written(dir: &Path, names: &FrameName) -> std::collections::HashSet<u32> {
    super::atomic::partials(dir)
        .unwrap_or_default()
        .into_iter()
        .filter(|(_, _, stale)| !stale)
        .filter_map(|(_, name, _)| names.hidden_kind(&name))
        // A claim's temporary says nothing of pixels: the claim itself,
        // once there, says whether the frame is in progress.
        .filter(|&(_, kind)| kind != "claim")
        .map(|(frame, _)| frame)
        .collect()
}

/// The final frame files of `format` named by `names` in `dir`, in frame
/// order (frames of other names beside them are not listed).
pub fn frame_files(dir: &Path, format: Format, names: &FrameName) -> Result<Vec<PathBuf>> {
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    let mut frames: Vec<(u32, PathBuf)> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter_map(|p| {
            let name = p.file_name()?.to_string_lossy().into_owned();
            Some((names.frame_of(&name, format)?, p))
        })
        .collect();
    frames.sort();
    Ok(frames.into_iter().map(|(_, p)| p).collect())
}
