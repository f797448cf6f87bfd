//! Checkpoints: the accumulation of a frame still rendering, saved exactly
//! under its light's hash so a resumed frame ends identical.

use crate::error::{Error, Result};
use crate::output::atomic::write_atomic;
use serde::Serialize;
use std::fs::File;
use std::io::Write;
use std::path::Path;

const CHECKPOINT_MAGIC: &[u8] = b"mandelreel-checkpoint-1\n";

#[derive(Serialize, serde::Deserialize)]
struct CheckpointHeader {
    hash: String,
    width: u32,
    height: u32,
    samples_done: u32,
    layers: [bool; 3],
    /// Whether each pixel's adaptive-sampling spread follows the layers.
    #[serde(default)]
    spreads: bool,
    /// Whether each pixel's samples within the picture follow (a fisheye's).
    #[serde(default)]
    inside: bool,
    stats: crate::render::FrameStats,
}

/// Saves `acc` for the frame with content `hash`, atomically.
pub fn write_checkpoint(path: &Path, acc: &crate::render::Accumulation, hash: &str) -> Result<()> {
    let header = CheckpointHeader {
        hash: hash.to_string(),
        width: acc.width,
        height: acc.height,
        samples_done: acc.samples_done,
        layers: [
            !acc.normal.is_empty(),
            !acc.albedo.is_empty(),
            !acc.traps.is_empty(),
        ],
        spreads: !acc.spread.is_empty(),
        inside: !acc.inside.is_empty(),
        stats: acc.stats,
    };
    // Streamed through the file's buffer, not assembled first: the
    // accumulation of a large frame is hundreds of megabytes.
    write_atomic(path, |w, temp| {
        let mut put = |bytes: &[u8]| w.write_all(bytes).map_err(|e| Error::io(temp, e));
        put(CHECKPOINT_MAGIC)?;
        put(&serde_json::to_vec(&header).expect("a header serialises"))?;
        put(b"\n")?;
        // Raw little-endian arrays: exact bits, so a resumed frame ends identical.
        for c in &acc.colour {
            for v in c {
                put(&v.to_le_bytes())?;
            }
        }
        for v in &acc.hits {
            put(&v.to_le_bytes())?;
        }
        for v in &acc.depth {
            put(&v.to_le_bytes())?;
        }
        for v in &acc.spent {
            put(&v.to_le_bytes())?;
        }
        for v in acc.normal.iter().chain(&acc.albedo) {
            for x in v.to_array() {
                put(&x.to_le_bytes())?;
            }
        }
        for v in &acc.traps {
            for x in v {
                put(&x.to_le_bytes())?;
            }
        }
        for p in &acc.spread {
            put(&p.taken.to_le_bytes())?;
            put(&p.grazes.to_le_bytes())?;
            put(&p.sum.to_le_bytes())?;
            put(&p.squares.to_le_bytes())?;
        }
        for v in &acc.inside {
            put(&v.to_le_bytes())?;
        }
        Ok(())
    })
}

/// Whether the checkpoint at `path` was saved for a frame with this
/// `hash`, size and layers (by its header: what `status` calls resumable).
pub fn checkpoint_is_for(
    path: &Path,
    hash: &str,
    width: u32,
    height: u32,
    layers: crate::render::Layers,
) -> bool {
    checkpoint_header(path, hash, width, height, layers).is_some()
}

/// The checkpoint's header, if it was saved for a frame with this `hash`,
/// size and layers, and the file positioned at its arrays.
fn checkpoint_header(
    path: &Path,
    hash: &str,
    width: u32,
    height: u32,
    layers: crate::render::Layers,
) -> Option<(std::io::BufReader<File>, CheckpointHeader)> {
    use std::io::{BufRead, Read};
    let mut file = std::io::BufReader::new(crate::input::open_regular(path).ok()?);
    let mut magic = vec![0; CHECKPOINT_MAGIC.len()];
    file.read_exact(&mut magic).ok()?;
    if magic != CHECKPOINT_MAGIC {
        return None;
    }
    let mut line = Vec::new();
    file.read_until(b'\n', &mut line).ok()?;
    let header: CheckpointHeader = serde_json::from_slice(line.strip_suffix(b"\n")?).ok()?;
    let wanted = [layers.normal, layers.albedo, layers.traps];
    let fits = header.hash == hash
        && header.width == width
        && header.height == height
        && header.layers == wanted;
    fits.then_some((file, header))
}

/// The saved accumulation at `path`, if it is whole and belongs to a frame
/// with this `hash`, size and layers.
pub fn read_checkpoint(
    path: &Path,
    hash: &str,
    width: u32,
    height: u32,
    layers: crate::render::Layers,
) -> Option<crate::render::Accumulation> {
    // Read as it is parsed, so resuming holds the accumulation once, not
    // also the file's bytes.
    use std::io::Read;
    let (mut file, header) = checkpoint_header(path, hash, width, height, layers)?;
    let mut acc = crate::render::Accumulation::new(width, height, layers);
    fn take<const N: usize>(file: &mut impl Read) -> Option<[u8; N]> {
        let mut bytes = [0; N];
        file.read_exact(&mut bytes).ok()?;
        Some(bytes)
    }
    for c in acc.colour.iter_mut() {
        for v in c.iter_mut() {
            *v = f64::from_le_bytes(take(&mut file)?);
        }
    }
    for v in acc.hits.iter_mut() {
        *v = u32::from_le_bytes(take(&mut file)?);
    }
    for v in acc.depth.iter_mut() {
        *v = f32::from_le_bytes(take(&mut file)?);
    }
    for v in acc.spent.iter_mut() {
        *v = u64::from_le_bytes(take(&mut file)?);
    }
    for v in acc.normal.iter_mut().chain(acc.albedo.iter_mut()) {
        for k in 0..3 {
            v[k] = f32::from_le_bytes(take(&mut file)?);
        }
    }
    for v in acc.traps.iter_mut() {
        for x in v.iter_mut() {
            *x = f32::from_le_bytes(take(&mut file)?);
        }
    }
    if header.spreads {
        acc.spread.resize(acc.colour.len(), Default::default());
        for p in acc.spread.iter_mut() {
            p.taken = u32::from_le_bytes(take(&mut file)?);
            p.grazes = u32::from_le_bytes(take(&mut file)?);
            p.sum = f64::from_le_bytes(take(&mut file)?);
            p.squares = f64::from_le_bytes(take(&mut file)?);
            if p.taken > header.samples_done || p.grazes > p.taken {
                return None;
            }
        }
    }
    if header.inside {
        acc.inside.resize(acc.colour.len(), 0);
        for v in acc.inside.iter_mut() {
            *v = u32::from_le_bytes(take(&mut file)?);
        }
    }
    // Whole: nothing after the arrays.
    if file.read(&mut [0u8; 1]).ok()? != 0 {
        return None;
    }
    acc.samples_done = header.samples_done;
    acc.stats = header.stats;
    Some(acc)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    #[test]
    fn checkpoints_round_trip_exactly_and_refuse_other_frames() {
        use crate::render::{render_samples, Accumulation, Layers};
        let dir = tempfile::tempdir().unwrap();
        let scene = Scene {
            samples_per_pixel: 4,
            ..Scene::default()
        };
        let layers = Layers {
            normal: true,
            albedo: false,
            traps: true,
        };
        let mut acc = Accumulation::new(12, 8, layers);
        render_samples(std::slice::from_ref(&scene), 0, &mut acc, 2, &|| {});
        let path = dir.path().join(".frame_00000.ckpt");
        write_checkpoint(&path, &acc, "h1").unwrap();
        assert_eq!(
            read_checkpoint(&path, "h1", 12, 8, layers).as_ref(),
            Some(&acc)
        );
        assert!(read_checkpoint(&path, "h2", 12, 8, layers).is_none());
        assert!(read_checkpoint(&path, "h1", 12, 9, layers).is_none());
        assert!(read_checkpoint(&path, "h1", 12, 8, Layers::default()).is_none());
        // A cut-short file is refused, not half-read, and so is one with
        // anything after its arrays.
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() - 3]).unwrap();
        assert!(read_checkpoint(&path, "h1", 12, 8, layers).is_none());
        std::fs::write(&path, [&bytes[..], b"x"].concat()).unwrap();
        assert!(read_checkpoint(&path, "h1", 12, 8, layers).is_none());
        std::fs::write(&path, &bytes).unwrap();
        assert!(read_checkpoint(&path, "h1", 12, 8, layers).is_some());
    }

    #[test]
    fn a_fisheyes_checkpoint_keeps_each_pixels_samples_in_the_picture() {
        use crate::render::{render_samples, Accumulation, Layers};
        let dir = tempfile::tempdir().unwrap();
        let mut scene = Scene {
            samples_per_pixel: 4,
            ..Scene::default()
        };
        scene.camera.projection = crate::camera::Projection::Fisheye { degrees: 180.0 };
        let mut acc = Accumulation::new(12, 8, Layers::default());
        render_samples(std::slice::from_ref(&scene), 0, &mut acc, 2, &|| {});
        assert_eq!(acc.inside[0], 0, "a corner is outside the circle");
        assert_eq!(acc.inside[4 * 12 + 6], 2, "the centre is inside");
        let path = dir.path().join(".frame_00000.ckpt");
        write_checkpoint(&path, &acc, "h").unwrap();
        let read = read_checkpoint(&path, "h", 12, 8, Layers::default());
        assert_eq!(read.as_ref(), Some(&acc));
    }

    #[test]
    fn adaptive_checkpoints_keep_each_pixels_spread_and_resume_alike() {
        use crate::render::{next_wave, render_samples, Accumulation, Layers};
        let dir = tempfile::tempdir().unwrap();
        let scene = Scene {
            samples_per_pixel: 16,
            adaptive: Some(crate::scene::Adaptive::default()),
            ..Scene::default()
        };
        let scenes = std::slice::from_ref(&scene);
        let wave = |acc: &mut Accumulation| {
            let until = next_wave(&scene, acc.samples_done);
            render_samples(scenes, 0, acc, until, &|| {});
        };
        let mut straight = Accumulation::new(24, 16, Layers::default());
        wave(&mut straight);
        wave(&mut straight);
        let path = dir.path().join(".frame_00000.ckpt");
        write_checkpoint(&path, &straight, "h").unwrap();
        let mut resumed = read_checkpoint(&path, "h", 24, 16, Layers::default()).unwrap();
        assert_eq!(resumed, straight);
        assert!(!resumed.spread.is_empty());
        while straight.samples_done < 16 {
            wave(&mut straight);
            wave(&mut resumed);
        }
        assert_eq!(resumed, straight);
        let taken: Vec<u32> = straight.spread.iter().map(|p| p.taken).collect();
        // Some pixels stopped early, after a checkpoint or before it.
        assert!(
            taken.iter().any(|&n| n < 16) && taken.contains(&16),
            "{taken:?}"
        );
    }
}
