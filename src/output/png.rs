//! PNG frames: sRGB through the film's display transform (8-bit dithered,
//! 16-bit, or 16-bit with alpha), with the
//! frame's hash and statistics in text chunks, and the checks that tell a
//! whole PNG from one cut short or damaged.

use super::{stats_text, Encoding, FileState, PngKind, HASH_KEY, STATS_KEY};
use crate::render::Film;
use std::fs::File;
use std::io::{BufReader, Write};
use std::path::Path;

pub(crate) fn encode(
    out: &mut impl Write,
    film: &Film,
    hash: &str,
    kind: PngKind,
    encoding: &Encoding,
) -> std::result::Result<(), String> {
    let kind = Kind::of(kind, encoding);
    let mut encoder = png::Encoder::new(out, film.width, film.height);
    encoder.set_color(kind.colour);
    encoder.set_depth(kind.depth);
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
    let bytes = pixel_bytes(film, kind, encoding.display);
    writer.write_image_data(&bytes).map_err(|e| e.to_string())?;
    writer.finish().map_err(|e| e.to_string())
}

/// What a PNG of `format` holds.
#[derive(Clone, Copy)]
struct Kind {
    colour: png::ColorType,
    depth: png::BitDepth,
    /// Alpha is the film's hit coverage where the background is
    /// transparent (else the picture's coverage, `Film::coverage`).
    transparent: bool,
}

impl Kind {
    fn of(kind: PngKind, encoding: &Encoding) -> Kind {
        let (colour, depth) = match kind {
            PngKind::Rgb8 => (png::ColorType::Rgb, png::BitDepth::Eight),
            PngKind::Rgb16 => (png::ColorType::Rgb, png::BitDepth::Sixteen),
            PngKind::Rgba16 => (png::ColorType::Rgba, png::BitDepth::Sixteen),
        };
        Kind {
            colour,
            depth,
            transparent: encoding.transparent,
        }
    }

    fn bytes_per_pixel(self) -> usize {
        let channels = if self.colour == png::ColorType::Rgba {
            4
        } else {
            3
        };
        let bytes = if self.depth == png::BitDepth::Sixteen {
            2
        } else {
            1
        };
        channels * bytes
    }
}

/// The image's bytes, a row at a time straight into place on every thread.
fn pixel_bytes(film: &Film, kind: Kind, display: crate::color::Display) -> Vec<u8> {
    use rayon::prelude::*;
    let painter = Painter {
        kind,
        display,
        plain: display.is_plain(),
        curve: crate::color::SrgbCurve::get(),
    };
    let row = (film.width as usize).max(1);
    let size = kind.bytes_per_pixel();
    let mut bytes = vec![0u8; film.colour.len() * size];
    // Beyond a fisheye's circle is no part of the picture, whatever the
    // background: there an opaque frame's alpha is the picture's coverage.
    let alpha = match (kind.transparent, film.coverage.as_deref()) {
        (true, _) => Some(&film.alpha[..]),
        (false, coverage) => coverage,
    };
    bytes
        .par_chunks_mut(size * row)
        .zip(film.colour.par_chunks(row))
        .enumerate()
        .for_each(|(y, (bytes, colour))| {
            let alpha = alpha.map(|a| &a[y * row..][..colour.len()]);
            for (x, (out, c)) in bytes.chunks_exact_mut(size).zip(colour).enumerate() {
                let a = alpha.map(|a| a[x]);
                painter.put(out, [c.x, c.y, c.z], a, (x as u32, y as u32));
            }
        });
    bytes
}

/// What turns a frame's pixels into one kind of PNG's codes, set up once
/// a frame.
struct Painter {
    kind: Kind,
    display: crate::color::Display,
    /// The display changes nothing: light is coded as it is.
    plain: bool,
    curve: &'static crate::color::SrgbCurve,
}

impl Painter {
    #[inline]
    fn show(&self, v: f32) -> f32 {
        if self.plain {
            v
        } else {
            self.display.apply(v)
        }
    }

    /// One pixel's codes into `out`. PNG colour is straight: a pixel with
    /// alpha (`Some`: its coverage) shows its colour divided by it; one
    /// without shows the film's colour, which, where the background is
    /// transparent, is the fractal over black. 8-bit codes are dithered by
    /// the pixel's offset.
    #[inline]
    fn put(&self, out: &mut [u8], rgb: [f32; 3], alpha: Option<f32>, (x, y): (u32, u32)) {
        let (kind, curve) = (self.kind, self.curve);
        let show = |v: f32| self.show(v);
        if kind.depth == png::BitDepth::Eight {
            let offset = crate::color::dither_offset(x, y);
            for (byte, v) in out.iter_mut().zip(rgb) {
                *byte = curve.dithered_byte(show(v), offset);
            }
            return;
        }
        let (shown, alpha) = match (kind.colour, alpha) {
            (png::ColorType::Rgba, Some(a)) => {
                let a = a.clamp(0.0, 1.0);
                (straight_shown(rgb, a, show), Some(a))
            }
            (png::ColorType::Rgba, None) => (rgb.map(show), Some(1.0)),
            _ => (rgb.map(show), None),
        };
        let codes = shown.map(|v| curve.code16(v));
        let alpha = alpha.map(|a| (a * 65535.0 + 0.5) as u16);
        for (pair, code) in out.chunks_exact_mut(2).zip(codes.into_iter().chain(alpha)) {
            pair.copy_from_slice(&code.to_be_bytes());
        }
    }
}

/// The straight colour of premultiplied `rgb` at coverage `a`, as shown.
/// Light with no coverage (glow at a partly covered pixel) can make it
/// brighter than the display holds: it is then scaled down whole, keeping
/// its hue (clipped channel by channel it would turn white), to what a
/// fully covered pixel of the same light would show.
fn straight_shown(rgb: [f32; 3], a: f32, show: impl Fn(f32) -> f32) -> [f32; 3] {
    if a <= 0.0 {
        return [0.0; 3];
    }
    let peak = |c: [f32; 3]| c[0].max(c[1]).max(c[2]);
    let shown = rgb.map(|v| show(v / a));
    let limit = peak(rgb.map(&show)).max(1.0);
    if peak(shown) > limit {
        let scale = limit / peak(shown);
        shown.map(|v| v * scale)
    } else {
        shown
    }
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
