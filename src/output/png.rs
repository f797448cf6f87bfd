//! PNG frames: 8-bit sRGB through the film's display transform, with the
//! frame's hash and statistics in text chunks, and the checks that tell a
//! whole PNG from one cut short or damaged.

use super::frames::FileState;
use super::{stats_text, HASH_KEY, STATS_KEY};
use crate::render::Film;
use std::fs::File;
use std::io::{BufReader, Write};
use std::path::Path;

pub(crate) fn encode(
    out: &mut impl Write,
    film: &Film,
    hash: &str,
    display: crate::color::Display,
) -> std::result::Result<(), String> {
    let mut encoder = png::Encoder::new(out, film.width, film.height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let text = [
        (HASH_KEY, hash.to_string()),
        (STATS_KEY, stats_text(film)),
        (
            "Software",
            format!("mandelreel {}", env!("CARGO_PKG_VERSION")),
        ),
    ];
    for (key, value) in text {
        encoder
            .add_text_chunk(key.to_string(), value)
            .map_err(|e| e.to_string())?;
    }
    // fdeflate: several times faster than the default level for a few
    // per cent more bytes; encoding is the one serial stage of a frame.
    encoder.set_compression(png::Compression::Fast);
    // Paeth on every row rather than the adaptive choice among five: on
    // our frames both faster (640×480: 0.99 → 0.77 ms) and smaller (1–6%
    // on S1 and frames of zoom, effects and julia_morph; one-off).
    encoder.set_filter(png::Filter::Paeth);
    let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
    // The sRGB codes come from a table (a powf per channel cost as much as
    // a twentieth of a small frame), a row at a time straight into place on
    // every thread.
    use rayon::prelude::*;
    let srgb = crate::color::SrgbBytes::get();
    let plain = display.is_plain();
    let row = (film.width as usize).max(1);
    let mut bytes = vec![0u8; film.colour.len() * 3];
    bytes
        .par_chunks_mut(3 * row)
        .zip(film.colour.par_chunks(row))
        .for_each(|(bytes, colour)| {
            for (rgb, c) in bytes.chunks_exact_mut(3).zip(colour) {
                for (byte, v) in rgb.iter_mut().zip([c.x, c.y, c.z]) {
                    // At the default display the light is coded as it is.
                    *byte = srgb.byte(if plain { v } else { display.apply(v) });
                }
            }
        });
    writer.write_image_data(&bytes).map_err(|e| e.to_string())?;
    writer.finish().map_err(|e| e.to_string())
}

/// `frames::file_state` for a PNG opened as `file`: stale unless its text
/// records `key`; then current if whole, by its end or, `thorough`, by
/// every chunk's CRC.
pub(crate) fn file_state(
    file: BufReader<File>,
    path: &Path,
    key: &str,
    thorough: bool,
) -> FileState {
    let Ok(reader) = png::Decoder::new(file).read_info() else {
        return FileState::Damaged;
    };
    let text = &reader.info().uncompressed_latin1_text;
    if !text.iter().any(|t| t.keyword == HASH_KEY && t.text == key) {
        return FileState::Stale;
    }
    let whole = if thorough {
        png_is_whole(path)
    } else {
        png_ends_with_iend(path)
    };
    if whole {
        FileState::Current
    } else {
        FileState::Damaged
    }
}

/// Whether a PNG file's last 12 bytes are its IEND chunk.
fn png_ends_with_iend(path: &Path) -> bool {
    use std::io::{Read, Seek, SeekFrom};
    const IEND: [u8; 12] = [0, 0, 0, 0, b'I', b'E', b'N', b'D', 0xAE, 0x42, 0x60, 0x82];
    let mut tail = [0u8; 12];
    crate::input::open_regular(path)
        .and_then(|mut f| {
            f.seek(SeekFrom::End(-12))?;
            f.read_exact(&mut tail)
        })
        .is_ok()
        && tail == IEND
}

/// Whether a PNG file is whole: its signature, then chunks whose CRCs all
/// match their bytes, up to the IEND chunk at the very end. Catches a file
/// cut short and any damaged byte, without decompressing the image.
fn png_is_whole(path: &Path) -> bool {
    use std::io::Read;
    const SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n'];
    let walk = || -> std::io::Result<bool> {
        let mut file =
            std::io::BufReader::with_capacity(1 << 16, crate::input::open_regular(path)?);
        let mut signature = [0u8; 8];
        file.read_exact(&mut signature)?;
        if signature != SIGNATURE {
            return Ok(false);
        }
        let mut buffer = vec![0u8; 1 << 16];
        loop {
            // Length (4 bytes, big-endian), type (4), data, CRC of type and data (4).
            let mut head = [0u8; 8];
            file.read_exact(&mut head)?;
            let mut left = u32::from_be_bytes([head[0], head[1], head[2], head[3]]) as usize;
            let mut crc = crc32fast::Hasher::new();
            crc.update(&head[4..]);
            while left > 0 {
                let piece = &mut buffer[..left.min(1 << 16)];
                file.read_exact(piece)?;
                crc.update(piece);
                left -= piece.len();
            }
            let mut stored = [0u8; 4];
            file.read_exact(&mut stored)?;
            if crc.finalize() != u32::from_be_bytes(stored) {
                return Ok(false);
            }
            if &head[4..] == b"IEND" {
                return Ok(file.read(&mut [0u8; 1])? == 0);
            }
        }
    };
    walk().unwrap_or(false)
}
