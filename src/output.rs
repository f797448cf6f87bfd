//! Frames on disk: naming, PNG (8-bit sRGB) and EXR (linear half-float RGBA plus
//! a float Z) writing, write-to-temporary-then-rename, and the content hash that
//! each file carries in its own metadata so resume can tell a current frame from
//! a stale one.

use crate::error::{Error, Result};
use crate::render::Film;
use crate::scene::Scene;
use serde::Serialize;
use sha2::{Digest, Sha256};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Metadata key under which every frame stores the hash of what made it.
pub const HASH_KEY: &str = "mandelreel-hash";
/// Metadata key for the frame's render statistics.
pub const STATS_KEY: &str = "mandelreel-stats";
/// Digits in frame numbers: `frame_00042.png`.
pub const FRAME_DIGITS: usize = 5;

/// An output file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum Format {
    /// 8-bit sRGB PNG.
    Png,
    /// OpenEXR: linear half-float R, G, B, A and a float Z (camera distance),
    /// plus the layers --aov asks for.
    Exr,
}

impl Format {
    pub fn extension(self) -> &'static str {
        match self {
            Format::Png => "png",
            Format::Exr => "exr",
        }
    }
}

/// Extra EXR layers (arbitrary output variables) a render can write.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Hash,
    PartialOrd,
    Ord,
    clap::ValueEnum,
    Serialize,
    serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Aov {
    /// Surface normal: N.X, N.Y, N.Z.
    Normal,
    /// Orbit-trap albedo: albedo.R, albedo.G, albedo.B.
    Albedo,
    /// Orbit traps: trap.origin (smallest |z|²), trap.x, trap.y, trap.z.
    Traps,
    /// Distance estimates spent per pixel: DE (a cost heat map).
    Steps,
}

impl Aov {
    /// The layer's name, as `--aov` takes it.
    pub fn name(self) -> &'static str {
        match self {
            Aov::Normal => "normal",
            Aov::Albedo => "albedo",
            Aov::Traps => "traps",
            Aov::Steps => "steps",
        }
    }
}

/// The render layers `aovs` need.
pub fn layers_for(aovs: &[Aov]) -> crate::render::Layers {
    crate::render::Layers {
        normal: aovs.contains(&Aov::Normal),
        albedo: aovs.contains(&Aov::Albedo),
        traps: aovs.contains(&Aov::Traps),
    }
}

/// `frame_00042.png` for frame 42.
pub fn frame_file_name(frame_index: u32, format: Format) -> String {
    format!(
        "frame_{frame_index:0width$}.{}",
        format.extension(),
        width = FRAME_DIGITS
    )
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
    let plain = scenes.iter().all(|s| s.look.is_plain_display());
    if plain {
        return light_digest(scenes, frame_index, width, height);
    }
    let light: Vec<Scene> = scenes
        .iter()
        .map(|s| {
            let mut s = s.clone();
            s.look.exposure = 1.0;
            s.look.tone_map = crate::shade::ToneMap::Clip;
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
    let whole = match format {
        Format::Png => {
            let Ok(reader) = png::Decoder::new(file).read_info() else {
                return FileState::Damaged;
            };
            let text = &reader.info().uncompressed_latin1_text;
            if !text.iter().any(|t| t.keyword == HASH_KEY && t.text == key) {
                return FileState::Stale;
            }
            if thorough {
                png_is_whole(path)
            } else {
                png_ends_with_iend(path)
            }
        }
        Format::Exr => {
            // The header, read once: its hash, then the offset table after it.
            let mut file = file;
            let Ok(meta) = exr::meta::MetaData::read_from_buffered(&mut file, false) else {
                return FileState::Damaged;
            };
            let recorded = meta.headers.first().and_then(|header| {
                match header
                    .own_attributes
                    .other
                    .get(&exr::prelude::Text::from(HASH_KEY))
                {
                    Some(exr::meta::attribute::AttributeValue::Text(t)) => Some(t.to_string()),
                    _ => None,
                }
            });
            if recorded.as_deref() != Some(key) {
                return FileState::Stale;
            }
            // Thorough reading adds every chunk read whole to the end check
            // (pedantic reading refuses bytes after the last).
            let every_chunk = || {
                let file = std::io::BufReader::new(crate::input::open_regular(path).ok()?);
                let chunks = exr::block::read(file, true).ok()?.all_chunks(true).ok()?;
                Some(chunks.into_iter().all(|chunk| chunk.is_ok()))
            };
            exr_ends_with_its_last_chunk(&mut file, &meta).unwrap_or(false)
                && (!thorough || every_chunk() == Some(true))
        }
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

/// Whether a single-part EXR (as `write_frame` writes them) ends exactly
/// where its last chunk does: the header parsed by exr, then the offset
/// table read, and the chunk at the largest offset (its coordinates: a
/// tile's four numbers or a scan-line block's y; its byte count; its
/// bytes) must reach the file's end and not pass it.
/// `file` stands just after the header `meta` (exr reads a header up to
/// the null byte that ends it, and no further): at the offset table.
fn exr_ends_with_its_last_chunk(
    file: &mut std::io::BufReader<File>,
    meta: &exr::meta::MetaData,
) -> std::io::Result<bool> {
    use std::io::{Read, Seek, SeekFrom};
    let length = file.get_ref().metadata()?.len();
    let [header] = meta.headers.as_slice() else {
        return Ok(false);
    };
    let mut last = 0u64;
    let mut entry = [0u8; 8];
    for _ in 0..header.chunk_count {
        file.read_exact(&mut entry)?;
        last = last.max(u64::from_le_bytes(entry));
    }
    let coordinates = match header.blocks {
        exr::meta::BlockDescription::Tiles(_) => 16,
        exr::meta::BlockDescription::ScanLines => 4,
    };
    if last
        .checked_add(coordinates + 4)
        .is_none_or(|end| end > length)
    {
        return Ok(false);
    }
    file.seek(SeekFrom::Start(last + coordinates))?;
    let mut size = [0u8; 4];
    file.read_exact(&mut size)?;
    let size = i32::from_le_bytes(size);
    Ok(size >= 0 && last + coordinates + 4 + size as u64 == length)
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
/// `look` decides how a PNG shows the film's linear light (its exposure
/// and tone map); an EXR holds the linear light as it is.
pub fn write_frame(
    path: &Path,
    format: Format,
    film: &Film,
    hash: &str,
    aovs: &[Aov],
    look: &crate::shade::Look,
) -> Result<()> {
    let image_error = |temp: &Path, message: String| Error::Image {
        path: temp.to_path_buf(),
        message,
    };
    let key = stored_key(format, hash, aovs);
    write_atomic(path, |writer, temp| match format {
        Format::Png => encode_png(writer, film, &key, look).map_err(|m| image_error(temp, m)),
        Format::Exr => encode_exr(writer, film, &key, aovs).map_err(|m| image_error(temp, m)),
    })
}

/// Replaces `path` whole or not at all: `write` fills a hidden temporary file
/// beside it (`.<name>.<host>.<pid>.<random>.partial`, unique per writer, so a
/// leftover one is never taken for a final file and `remove_stale_partials`
/// knows whose it is), which is flushed, synced and renamed over `path`. On
/// any error the temporary file is deleted. Files are readable by all.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<&File>, &Path) -> Result<()>,
) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut builder = tempfile::Builder::new();
    let prefix = format!(".{}.{}", name.trim_start_matches('.'), writer_tag());
    builder.prefix(&prefix).suffix(".partial");
    #[cfg(unix)]
    {
        // Ordinary files, readable by all (tempfile's default is 0600).
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o644));
    }
    // Created and renamed under the interrupt lock, so Ctrl-C removes
    // every temporary file and none is renamed into place after it.
    let (temp, _removed_on_interrupt) = {
        let mut held = crate::interrupt::hold();
        let temp = builder.tempfile_in(dir).map_err(|e| Error::io(dir, e))?;
        let temp_path = temp.path().to_path_buf();
        let removal = held.on_interrupt(move || {
            let _ = std::fs::remove_file(temp_path);
        });
        (temp, removal)
    };
    let temp_path = temp.path().to_path_buf();
    // Written through the plain file: the temporary file's own writer
    // would add its path to every error, which `Error::io` names already.
    let mut writer = BufWriter::new(temp.as_file());
    write(&mut writer, &temp_path)?;
    writer
        .into_inner()
        .map_err(|e| Error::io(&temp_path, e.into_error()))?
        .sync_all()
        .map_err(|e| Error::io(&temp_path, e))?;
    let held = crate::interrupt::hold();
    temp.persist(path).map_err(|e| Error::io(path, e.error))?;
    drop(held);
    Ok(())
}

fn stats_text(film: &Film) -> String {
    format!(
        "de_evaluations={} primary={} normals={} shadows={} occlusion={} bounces={} sun={} samples={} hits={} max_pixel_evaluations={} repaired_samples={} out_of_steps={}",
        film.stats.de_evaluations,
        film.stats.primary_evaluations,
        film.stats.normal_evaluations,
        film.stats.shadow_evaluations,
        film.stats.occlusion_evaluations,
        film.stats.bounce_evaluations,
        film.stats.sun_evaluations,
        film.stats.samples,
        film.stats.hits,
        film.stats.max_pixel_evaluations,
        film.stats.repaired_samples,
        film.stats.out_of_steps
    )
}

fn encode_png(
    out: &mut impl Write,
    film: &Film,
    hash: &str,
    look: &crate::shade::Look,
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
    let plain = look.is_plain_display();
    let row = (film.width as usize).max(1);
    let mut bytes = vec![0u8; film.colour.len() * 3];
    bytes
        .par_chunks_mut(3 * row)
        .zip(film.colour.par_chunks(row))
        .for_each(|(bytes, colour)| {
            for (rgb, c) in bytes.chunks_exact_mut(3).zip(colour) {
                for (byte, v) in rgb.iter_mut().zip([c.x, c.y, c.z]) {
                    // At the default display the light is coded as it is.
                    *byte = srgb.byte(if plain { v } else { look.display(v) });
                }
            }
        });
    writer.write_image_data(&bytes).map_err(|e| e.to_string())?;
    writer.finish().map_err(|e| e.to_string())
}

/// Where an EXR channel's samples come from in the film.
#[derive(Clone, Copy)]
enum Source {
    /// Component `k` of the colour, the normal or the albedo.
    Colour(usize),
    Normal(usize),
    Albedo(usize),
    Alpha,
    Depth,
    /// Trap `k` (origin, x, y, z).
    Trap(usize),
    /// The distance estimates spent on the pixel (the `steps` layer).
    Steps,
}

/// Every channel a frame's EXR can hold, with its sample type and where
/// its samples come from: the one list the header and the blocks are both
/// made from. A channel whose layer the film lacks is left out.
const EXR_CHANNELS: [(&str, exr::meta::attribute::SampleType, Source); 16] = {
    use exr::meta::attribute::SampleType::{F16, F32, U32};
    use Source::*;
    [
        ("R", F16, Colour(0)),
        ("G", F16, Colour(1)),
        ("B", F16, Colour(2)),
        ("A", F16, Alpha),
        ("Z", F32, Depth),
        ("N.X", F32, Normal(0)),
        ("N.Y", F32, Normal(1)),
        ("N.Z", F32, Normal(2)),
        ("albedo.R", F16, Albedo(0)),
        ("albedo.G", F16, Albedo(1)),
        ("albedo.B", F16, Albedo(2)),
        ("trap.origin", F32, Trap(0)),
        ("trap.x", F32, Trap(1)),
        ("trap.y", F32, Trap(2)),
        ("trap.z", F32, Trap(3)),
        // Cost heat map: distance estimates spent per pixel.
        ("DE", U32, Steps),
    ]
};

// Counts, and only counts, are stored as u32 (`film_block` and `put_line`
// rely on it).
const _: () = {
    let mut i = 0;
    while i < EXR_CHANNELS.len() {
        let (_, sample, source) = EXR_CHANNELS[i];
        assert!(
            matches!(source, Source::Steps)
                == matches!(sample, exr::meta::attribute::SampleType::U32)
        );
        i += 1;
    }
};

fn encode_exr(
    out: &mut (impl Write + std::io::Seek),
    film: &Film,
    hash: &str,
    aovs: &[Aov],
) -> std::result::Result<(), String> {
    use exr::prelude::*;
    // The film's channels, in name order as the format asks.
    let mut channels: Vec<(&str, SampleType, Plane)> = EXR_CHANNELS
        .iter()
        .filter_map(|&(name, sample, source)| Some((name, sample, Plane::of(film, aovs, source)?)))
        .collect();
    channels.sort_by_key(|&(name, ..)| name);
    let mut attributes = LayerAttributes::named("");
    attributes.software_name = Some(Text::from(
        format!("mandelreel {}", env!("CARGO_PKG_VERSION")).as_str(),
    ));
    attributes
        .other
        .insert(Text::from(HASH_KEY), AttributeValue::Text(Text::from(hash)));
    // `other` is a HashMap written in its (per-process random) iteration order:
    // it holds only the hash so the file bytes are reproducible; stats go in a
    // standard attribute.
    attributes.comments = Some(Text::from(
        format!("{STATS_KEY}: {}", stats_text(film)).as_str(),
    ));
    let size = (film.width as usize, film.height as usize);
    let header = exr::meta::header::Header::new(
        Text::from(""),
        size,
        channels
            .iter()
            .map(|&(name, sample, _)| ChannelDescription::named(name, sample))
            .collect(),
    )
    // RLE in 64-pixel tiles (exrs' `FAST_LOSSLESS`), in increasing line
    // order: exrs otherwise orders blocks as its threads finish them, and
    // the bytes would differ run to run.
    .with_encoding(
        Compression::RLE,
        exr::meta::BlockDescription::Tiles(exr::meta::attribute::TileDescription {
            tile_size: Vec2(64, 64),
            level_mode: exr::meta::attribute::LevelMode::Singular,
            rounding_mode: exr::math::RoundingMode::Down,
        }),
        LineOrder::Increasing,
    )
    .with_attributes(attributes);
    let planes: Vec<_> = channels
        .into_iter()
        .map(|(_, sample, plane)| (plane, sample))
        .collect();
    write_exr_blocks(out, header, film, &planes).map_err(|e| e.to_string())
}

/// Writes the one-layer file `header` describes, its blocks filled from
/// the film's `planes` (one per channel, in the header's order) and
/// compressed on rayon's pool, a batch at a time, written in file order.
/// (exrs' own writer fills every block on the calling thread through a
/// per-pixel closure, about 45 ns a pixel: a 1080p frame took about 90 ms,
/// most of a core, while the pool waited; and it compresses on a pool of
/// its own as wide as the machine, whatever `--threads` says.) Here each
/// line of a channel is copied from the film in one loop (`film_block`).
fn write_exr_blocks(
    out: &mut (impl Write + std::io::Seek),
    header: exr::meta::header::Header,
    film: &Film,
    planes: &[(Plane, exr::meta::attribute::SampleType)],
) -> exr::error::UnitResult {
    use exr::block::writer::ChunksWriter;
    use exr::block::UncompressedBlock;
    use rayon::prelude::*;
    let headers: exr::meta::Headers = std::iter::once(header).collect();
    exr::block::write(out, headers, true, |meta, chunks| {
        let blocks: Vec<_> = meta.enumerate_ordered_header_block_indices().collect();
        // Enough blocks a batch to keep every thread busy; few enough that
        // the compressed batch is small beside the film.
        let batch = 16 * rayon::current_num_threads();
        for blocks in blocks.chunks(batch) {
            let compressed: Vec<_> = blocks
                .par_iter()
                .map(|&(in_header, index)| {
                    let data = film_block(film, planes, index);
                    UncompressedBlock { index, data }
                        .compress_to_chunk(&meta.headers)
                        .map(|chunk| (in_header, chunk))
                })
                .collect();
            for chunk in compressed {
                let (in_header, chunk) = chunk?;
                chunks.write_chunk(in_header, chunk)?;
            }
        }
        Ok(())
    })
}

/// `v` as a half float, light past the largest half (65504) held at it:
/// rounded as it comes, it would be infinite in the file.
fn half_float(v: f32) -> exr::prelude::f16 {
    const LARGEST: f32 = 65504.0; // f16::MAX, as an f32 constant
    exr::prelude::f16::from_f32(v.clamp(-LARGEST, LARGEST))
}

/// One line of a channel's samples into `line`, as `sample`s, native-endian.
fn put_line(
    line: &mut [u8],
    values: impl Iterator<Item = f32>,
    sample: exr::meta::attribute::SampleType,
) {
    use exr::meta::attribute::SampleType;
    match sample {
        SampleType::F16 => line
            .chunks_exact_mut(2)
            .zip(values)
            .for_each(|(out, v)| out.copy_from_slice(&half_float(v).to_ne_bytes())),
        SampleType::F32 => line
            .chunks_exact_mut(4)
            .zip(values)
            .for_each(|(out, v)| out.copy_from_slice(&v.to_ne_bytes())),
        SampleType::U32 => unreachable!("EXR_CHANNELS gives float planes float samples"),
    }
}

/// Where a channel's samples live in the film.
enum Plane<'f> {
    /// Component `k` of each vector.
    Vectors(&'f [crate::math::Vec3], usize),
    Floats(&'f [f32]),
    /// Trap `k` of each pixel.
    Traps(&'f [[f32; 4]], usize),
    Counts(&'f [u32]),
}

impl<'f> Plane<'f> {
    /// The plane `source` names, if the film has it (the steps layer only
    /// where `aovs` asks for it).
    fn of(film: &'f Film, aovs: &[Aov], source: Source) -> Option<Plane<'f>> {
        use Plane::*;
        Some(match source {
            Source::Colour(k) => Vectors(&film.colour, k),
            Source::Normal(k) => Vectors(film.normal.as_deref()?, k),
            Source::Albedo(k) => Vectors(film.albedo.as_deref()?, k),
            Source::Alpha => Floats(&film.alpha),
            Source::Depth => Floats(&film.depth),
            Source::Trap(k) => Traps(film.traps.as_deref()?, k),
            Source::Steps => Counts(aovs.contains(&Aov::Steps).then_some(&film.evaluations)?),
        })
    }
}

/// The uncompressed bytes of the block at `index` straight from the film's
/// `planes` (one per channel, from `EXR_CHANNELS`): line by line, each channel's samples of the
/// line in a row, in the header's channel order and sample types,
/// native-endian (exrs' layout).
fn film_block(
    film: &Film,
    planes: &[(Plane, exr::meta::attribute::SampleType)],
    index: exr::block::BlockIndex,
) -> Vec<u8> {
    let (x0, y0) = (index.pixel_position.x(), index.pixel_position.y());
    let (w, h) = (index.pixel_size.width(), index.pixel_size.height());
    let bytes_per_pixel: usize = planes.iter().map(|(_, s)| s.bytes_per_sample()).sum();
    let mut data = vec![0u8; w * h * bytes_per_pixel];
    let mut lines = data.as_mut_slice();
    for y in y0..y0 + h {
        let row = y * film.width as usize + x0..y * film.width as usize + x0 + w;
        for &(ref plane, sample) in planes {
            let (line, rest) =
                std::mem::take(&mut lines).split_at_mut(w * sample.bytes_per_sample());
            lines = rest;
            match *plane {
                Plane::Vectors(v, k) => put_line(line, v[row.clone()].iter().map(|p| p[k]), sample),
                Plane::Floats(v) => put_line(line, v[row.clone()].iter().copied(), sample),
                Plane::Traps(v, k) => put_line(line, v[row.clone()].iter().map(|p| p[k]), sample),
                Plane::Counts(v) => {
                    for (out, count) in line.chunks_exact_mut(4).zip(&v[row.clone()]) {
                        out.copy_from_slice(&count.to_ne_bytes());
                    }
                }
            }
        }
    }
    data
}

/// `rows` as CSV: a header of the field names, then a line per row.
pub fn csv_text<T: Serialize>(rows: &[T]) -> String {
    let mut writer = csv::Writer::from_writer(vec![]);
    for row in rows {
        writer
            .serialize(row)
            .expect("plain records serialise to CSV in memory");
    }
    let bytes = writer.into_inner().expect("writing to memory cannot fail");
    String::from_utf8(bytes).expect("CSV of UTF-8 fields is UTF-8")
}

/// The file in an output folder that records what it holds, so `status` can
/// work from the folder alone.
pub const JOB_FILE: &str = "mandelreel-job.json";

/// The empty file renders lock while they update `JOB_FILE`
/// (`JobRecord::record_in`).
pub const JOB_LOCK: &str = ".mandelreel-job.lock";

/// What an output folder was rendered from: enough to recompute every
/// frame's hash without the original timeline file.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct JobRecord {
    pub renderer: String,
    /// The timeline file as given, and its text when the render started.
    pub timeline_path: PathBuf,
    pub timeline_text: String,
    pub width: u32,
    pub height: u32,
    pub formats: Vec<String>,
    /// Half-open frame range the folder is meant to hold.
    pub frames: (u32, u32),
    pub preview: bool,
    #[serde(default)]
    pub aovs: Vec<Aov>,
    /// `--samples`, where given: the samples per pixel that replaced the
    /// timeline's.
    #[serde(default)]
    pub samples: Option<u32>,
    /// Each format's own range, layers and samples (`outputs`); the fields
    /// above are their union, and the last render's, for older readers.
    #[serde(default)]
    pub outputs: Vec<OutputRecord>,
}

/// What one format's frames in a folder were rendered with: a folder may
/// hold PNGs of the whole film and EXRs of three frames, with other layers
/// or samples, each complete on its own terms.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct OutputRecord {
    /// `png` or `exr`.
    pub format: String,
    /// Half-open span of every range rendered in this format.
    pub frames: (u32, u32),
    #[serde(default)]
    pub aovs: Vec<Aov>,
    #[serde(default)]
    pub samples: Option<u32>,
}

impl JobRecord {
    /// Writes the record into `dir` atomically (concurrent workers of one job
    /// write the same record; the last rename wins whole).
    pub fn write(&self, dir: &Path) -> Result<()> {
        let json = serde_json::to_string_pretty(self).expect("a job record serialises");
        write_atomic(&dir.join(JOB_FILE), |w, temp| {
            w.write_all(json.as_bytes()).map_err(|e| Error::io(temp, e))
        })
    }

    /// Whether the folder was rendered from the timeline at `path`, by file
    /// name (its text may have been edited since, and the folder mounted
    /// at another path).
    pub fn of_timeline(&self, path: &Path) -> bool {
        self.timeline_path.file_name() == path.file_name()
    }

    /// Whether `other` renders the same sequence: the same timeline
    /// (`of_timeline`) at the same size.
    pub fn same_sequence(&self, other: &JobRecord) -> bool {
        self.of_timeline(&other.timeline_path)
            && (self.width, self.height) == (other.width, other.height)
    }

    /// Writes this record into `dir`, spanning the frames of the one there
    /// too if that renders the same sequence (`same_sequence`): a folder is
    /// meant to hold every range rendered into it, so renders in pieces
    /// (`--frames 0..60`, then `60..120`, or both at once on a farm) leave
    /// a record of 0..120 and `status OUTDIR` counts the gaps. An exclusive
    /// lock on the folder's `JOB_LOCK` is held from the read to the write,
    /// so renders started at the same moment each merge into the record the
    /// one before wrote, and none loses another's range. Where the lock
    /// cannot be had (a file system without locks, a lock file this user
    /// cannot open), it goes on without: the record is bookkeeping, not
    /// worth a render. `check` sees the record already there, if any,
    /// under the same lock, and its error stops the write: so a render
    /// refused over another sequence's frames cannot slip in between
    /// another render's check and its write.
    ///
    /// Each format is merged on its own (`merge_outputs`): a render of a
    /// few EXR frames into a folder of PNGs leaves the PNGs' range as it
    /// was, and adds the EXRs'.
    pub fn record_in(self, dir: &Path, check: impl FnOnce(&JobRecord) -> Result<()>) -> Result<()> {
        // Read-only where another user made it (a lock needs no write
        // access), and none at all where it cannot be had.
        // A lock file that is not a regular file (a FIFO would block the
        // open) is none.
        let lock_path = dir.join(JOB_LOCK);
        // Under the interrupt lock: a render stopped before it wrote
        // anything removes the lock file it made (`Scaffold`).
        let held = crate::interrupt::hold();
        let lock = std::fs::OpenOptions::new()
            .create_new(true)
            .write(true)
            .open(&lock_path)
            .or_else(|_| crate::input::open_regular(&lock_path));
        drop(held);
        if let Ok(lock) = &lock {
            let _ = lock.lock();
        }
        let old = JobRecord::read(dir);
        if let Ok(old) = &old {
            check(old)?;
        }
        let record = match old {
            Ok(old) if old.same_sequence(&self) => self.merge_outputs(&old),
            _ => self,
        };
        record.write(dir)
    }

    /// Each format's record: `outputs`, or for a record written before
    /// them, one per format from the shared fields.
    pub fn outputs(&self) -> Vec<OutputRecord> {
        if !self.outputs.is_empty() {
            return self.outputs.clone();
        }
        let output = |format: &String| OutputRecord {
            format: format.clone(),
            frames: self.frames,
            aovs: if format == "exr" {
                self.aovs.clone()
            } else {
                Vec::new()
            },
            samples: self.samples,
        };
        self.formats.iter().map(output).collect()
    }

    /// This record, keeping the formats of `old` (the same sequence) that
    /// it does not render, and the span of its own formats' ranges there.
    fn merge_outputs(self, old: &JobRecord) -> JobRecord {
        let mut outputs = old.outputs();
        for new in self.outputs() {
            match outputs.iter_mut().find(|o| o.format == new.format) {
                Some(o) => {
                    *o = OutputRecord {
                        frames: (o.frames.0.min(new.frames.0), o.frames.1.max(new.frames.1)),
                        ..new
                    }
                }
                None => outputs.push(new),
            }
        }
        outputs.sort_by(|a, b| a.format.cmp(&b.format));
        let span = |f: fn(&OutputRecord) -> u32| outputs.iter().map(f);
        JobRecord {
            formats: outputs.iter().map(|o| o.format.clone()).collect(),
            frames: (
                span(|o| o.frames.0).min().unwrap_or(self.frames.0),
                span(|o| o.frames.1).max().unwrap_or(self.frames.1),
            ),
            outputs,
            ..self
        }
    }

    /// The record in `dir`: a regular file of at most `MAX_JOB_BYTES`.
    pub fn read(dir: &Path) -> Result<JobRecord> {
        let path = dir.join(JOB_FILE);
        let text = crate::input::open_regular(&path)
            .and_then(|file| crate::input::read_at_most(file, MAX_JOB_BYTES))
            .map_err(|e| Error::io(&path, e))?;
        serde_json::from_slice(&text).map_err(|e| Error::Image {
            path,
            message: format!("not a mandelreel job record: {e}"),
        })
    }
}

/// An output folder as a render set it up: the folders it created
/// (outermost first) and the bookkeeping files that were not there yet
/// (`JOB_LOCK`, `JOB_FILE`). A render that ends having written nothing
/// (a disk full from the start, Ctrl-C during its first frame) removes
/// them when this is dropped, or on an interrupt, unless `keep` was
/// called: it leaves the disk as it found it.
pub struct Scaffold {
    made: Option<Made>,
    _undone_on_interrupt: crate::interrupt::Registered,
}

#[derive(Clone)]
struct Made {
    dir: PathBuf,
    dirs: Vec<PathBuf>,
    files: Vec<&'static str>,
}

impl Scaffold {
    /// Creates `dir` and its missing parents, noting what it made.
    pub fn make(dir: &Path) -> Result<Scaffold> {
        let mut dirs: Vec<PathBuf> = dir
            .ancestors()
            .take_while(|d| !d.as_os_str().is_empty() && !d.exists())
            .map(Path::to_path_buf)
            .collect();
        dirs.reverse();
        let mut held = crate::interrupt::hold();
        let mut made = Made {
            dir: dir.to_path_buf(),
            dirs,
            files: Vec::new(),
        };
        if let Err(e) = std::fs::create_dir_all(dir) {
            made.undo();
            return Err(Error::io(dir, e));
        }
        made.files = [JOB_LOCK, JOB_FILE]
            .into_iter()
            .filter(|f| !dir.join(f).exists())
            .collect();
        let undo = made.clone();
        let registered = held.on_interrupt(move || undo.undo());
        drop(held);
        Ok(Scaffold {
            made: Some(made),
            _undone_on_interrupt: registered,
        })
    }

    /// The render wrote what it meant to: nothing is undone.
    pub fn keep(mut self) {
        self.made = None;
    }
}

impl Drop for Scaffold {
    fn drop(&mut self) {
        if let Some(made) = &self.made {
            made.undo();
        }
    }
}

impl Made {
    /// Removes what was made, if the folder holds nothing else: no frame,
    /// checkpoint, claim, or another render's record or files.
    fn undo(&self) {
        let Ok(entries) = std::fs::read_dir(&self.dir) else {
            return self.remove_dirs();
        };
        let only_ours = entries
            .map(|e| e.map(|e| e.file_name()))
            .all(|name| name.is_ok_and(|n| self.files.iter().any(|f| n == *f)));
        if only_ours {
            for f in &self.files {
                let _ = std::fs::remove_file(self.dir.join(f));
            }
            self.remove_dirs();
        }
    }

    /// Removes the folders made, innermost first, while they are empty
    /// (or were never made: `create_dir_all` may stop part-way).
    fn remove_dirs(&self) {
        for dir in self.dirs.iter().rev() {
            match std::fs::remove_dir(dir) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => return,
                _ => {}
            }
        }
    }
}
/// The longest job record read: it holds the timeline's text (at most
/// 1 MiB), which JSON may write up to six bytes a byte.
const MAX_JOB_BYTES: u64 = 8 << 20;

/// `.frame_00042.ckpt`: the saved accumulation of a frame still rendering.
pub fn checkpoint_path(dir: &Path, frame_index: u32) -> PathBuf {
    dir.join(format!(
        ".frame_{frame_index:0width$}.ckpt",
        width = FRAME_DIGITS
    ))
}

const CHECKPOINT_MAGIC: &[u8] = b"mandelreel-checkpoint-1\n";

#[derive(Serialize, serde::Deserialize)]
struct CheckpointHeader {
    hash: String,
    width: u32,
    height: u32,
    samples_done: u32,
    layers: [bool; 3],
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
    // Whole: nothing after the arrays.
    if file.read(&mut [0u8; 1]).ok()? != 0 {
        return None;
    }
    acc.samples_done = header.samples_done;
    acc.stats = header.stats;
    Some(acc)
}

/// How old a temporary `.partial` file must be to count as left behind by a
/// killed render. A writer holds one only while encoding a finished frame
/// (seconds), so anything this old belongs to no live process.
pub const STALE_PARTIAL_AGE: std::time::Duration = std::time::Duration::from_secs(600);

/// This machine's name, for temporary-file tags, claims and `status`.
pub fn host_name() -> String {
    // Read once a process: claims ask for it for every frame they look at.
    static NAME: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    NAME.get_or_init(|| {
        std::fs::read_to_string("/proc/sys/kernel/hostname")
            .ok()
            .map(|s| s.trim().to_string())
            .filter(|s| !s.is_empty())
            .or_else(|| std::env::var("HOSTNAME").ok())
            .unwrap_or_else(|| "unknown-host".into())
    })
    .clone()
}

/// `host.pid.`: written into every temporary file's name so a later run on
/// the same machine can tell whether its writer is still alive.
pub fn writer_tag() -> String {
    let host: String = host_name()
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '-'
            }
        })
        .collect();
    format!("{host}.{}.", std::process::id())
}

/// Whether the writer of temporary file `name` is a dead process on this
/// machine (read from its `host.pid.` tag; Linux's /proc says who lives).
fn writer_is_dead_here(name: &str) -> bool {
    let mut parts = name.trim_end_matches(".partial").rsplit('.');
    let (_random, pid, host) = (parts.next(), parts.next(), parts.next());
    let ours = writer_tag();
    let our_host = ours.split('.').next().unwrap_or_default();
    match (host, pid.and_then(|p| p.parse::<u32>().ok())) {
        (Some(h), Some(pid)) if h == our_host => gone_here(pid),
        _ => false,
    }
}

/// Whether process `pid` of this machine is known to have ended: Linux's
/// /proc has no such process (without /proc, nothing is known; nor where
/// /proc hides other users' processes, `hidepid`, which shows as no
/// process 1). A process that reused the pid is taken for alive.
pub fn gone_here(pid: u32) -> bool {
    pid != std::process::id()
        && Path::new("/proc/self").exists()
        && Path::new("/proc/1").exists()
        && !Path::new(&format!("/proc/{pid}")).exists()
}

/// This boot of this machine's kernel and this process's pid namespace
/// (`<boot id>/<namespace>`), where Linux tells: two processes with the same
/// host name see each other's pids only if these match (containers that
/// share a host name, cloned machines that kept one, do not).
pub fn pid_space() -> Option<String> {
    // Fixed for the life of a process: read once.
    static SPACE: std::sync::OnceLock<Option<String>> = std::sync::OnceLock::new();
    SPACE
        .get_or_init(|| {
            let boot = std::fs::read_to_string("/proc/sys/kernel/random/boot_id").ok()?;
            let namespace = std::fs::read_link("/proc/self/ns/pid").ok()?;
            Some(format!("{}/{}", boot.trim(), namespace.display()))
        })
        .clone()
}

/// How long ago `path` was last modified (`None` if that cannot be told).
pub fn file_age(path: &Path) -> Option<std::time::Duration> {
    std::fs::metadata(path)
        .ok()?
        .modified()
        .ok()?
        .elapsed()
        .ok()
}

/// The temporary files in `dir` (any writer's, any version's), each with
/// whether its writer is gone: a dead process on this machine, or older than
/// `STALE_PARTIAL_AGE`.
fn partials(dir: &Path) -> Result<Vec<(PathBuf, String, bool)>> {
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    Ok(entries
        .filter_map(|e| e.ok())
        .filter_map(|entry| {
            let name = entry.file_name().to_string_lossy().into_owned();
            // Every `write_atomic` temporary (frames, job file, checkpoints,
            // claims, sheets), and earlier versions' names too.
            if !(name.starts_with('.') && name.ends_with(".partial")) {
                return None;
            }
            let age = file_age(&entry.path());
            let stale = writer_is_dead_here(&name) || age.is_some_and(|a| a >= STALE_PARTIAL_AGE);
            Some((entry.path(), name, stale))
        })
        .collect())
}

/// Deletes temporary files in `dir` left by writers that are gone. Returns
/// how many went. Fresh ones of live writers may belong to a render running
/// beside this one and are left alone.
pub fn remove_stale_partials(dir: &Path) -> Result<usize> {
    Ok(partials(dir)?
        .into_iter()
        .filter(|(path, _, stale)| *stale && std::fs::remove_file(path).is_ok())
        .count())
}

/// Frames a live writer is working on: those with a temporary file (frame,
/// claim or checkpoint) that is not stale.
pub fn frames_being_written(dir: &Path) -> std::collections::HashSet<u32> {
    partials(dir)
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

/// Up to `count` items spread evenly from the first to the last.
pub fn evenly_spaced<T: Clone>(items: &[T], count: usize) -> Vec<T> {
    if items.len() <= count || count < 2 {
        return items.iter().take(count.max(1)).cloned().collect();
    }
    (0..count)
        .map(|i| items[i * (items.len() - 1) / (count - 1)].clone())
        .collect()
}

/// Tiles the PNG `frames` into a grid `columns` wide, each scaled to `thumb_width`.
pub fn write_contact_sheet(
    frames: &[PathBuf],
    columns: u32,
    thumb_width: u32,
    out: &Path,
) -> Result<()> {
    use image::{imageops, RgbImage};
    let decode = |p: &PathBuf| {
        image::open(p)
            .map(|i| i.to_rgb8())
            .map_err(|e| Error::Image {
                path: p.clone(),
                message: e.to_string(),
            })
    };
    // As large as a frame may be, and no larger.
    const MAX_SIDE: u64 = 32_768;
    if thumb_width as u64 > MAX_SIDE {
        return Err(Error::usage(
            "--thumb-width",
            format!("may be at most {MAX_SIDE}, got {thumb_width}"),
        ));
    }
    let first = decode(&frames[0])?;
    let thumb_height =
        ((thumb_width as u64 * first.height() as u64) / first.width().max(1) as u64).max(1) as u32;
    let columns = columns.min(frames.len() as u32);
    let rows = (frames.len() as u32).div_ceil(columns);
    let gap = 2;
    let (w, h) = (
        columns as u64 * (thumb_width as u64 + gap as u64) - gap as u64,
        rows as u64 * (thumb_height as u64 + gap as u64) - gap as u64,
    );
    if w > MAX_SIDE || h > MAX_SIDE {
        return Err(Error::usage(
            "--thumb-width/--columns/--count",
            format!("the sheet would be {w}x{h} pixels; it may be at most {MAX_SIDE} a side"),
        ));
    }
    let mut sheet = RgbImage::new(w as u32, h as u32);
    for (i, path) in frames.iter().enumerate() {
        let frame = decode(path)?;
        let thumb = imageops::resize(
            &frame,
            thumb_width,
            thumb_height,
            imageops::FilterType::Triangle,
        );
        let (cx, cy) = (i as u32 % columns, i as u32 / columns);
        imageops::replace(
            &mut sheet,
            &thumb,
            (cx * (thumb_width + gap)) as i64,
            (cy * (thumb_height + gap)) as i64,
        );
    }
    write_atomic(out, |w, temp| {
        sheet
            .write_to(w, image::ImageFormat::Png)
            .map_err(|e| Error::Image {
                path: temp.to_path_buf(),
                message: e.to_string(),
            })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;
    use crate::render::FrameStats;

    #[test]
    fn exr_tiles_read_back_as_the_film_across_partial_tiles() {
        // A size of 3×2 of exrs' 64-pixel tiles, cut short at the right and
        // the bottom; every layer and values that differ per pixel and
        // channel (some negative, some past f16's range), with and without
        // the extra layers.
        let (w, h) = (150u32, 70u32);
        let n = (w * h) as usize;
        let v = |i: usize, k: usize| match (i * 7 + k * 3) % 41 {
            40 => 1e5,
            j => j as f32 * 0.37 - 3.0,
        };
        let vectors = |k: usize| {
            (0..n)
                .map(|i| Vec3::new(v(i, k), v(i, k + 1), v(i, k + 2)))
                .collect()
        };
        let full = Film {
            width: w,
            height: h,
            colour: vectors(0),
            alpha: (0..n).map(|i| v(i, 3) / 4.0).collect(),
            depth: (0..n).map(|i| v(i, 4) * 1e5).collect(),
            evaluations: (0..n).map(|i| i as u32 * 97).collect(),
            normal: Some(vectors(5)),
            albedo: Some(vectors(8)),
            traps: Some(
                (0..n)
                    .map(|i| [v(i, 11), v(i, 12), v(i, 13), v(i, 14)])
                    .collect(),
            ),
            stats: FrameStats::default(),
        };
        let plain = Film {
            normal: None,
            albedo: None,
            traps: None,
            ..full.clone()
        };
        let all = [Aov::Normal, Aov::Albedo, Aov::Traps, Aov::Steps];
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("tiles.exr");
        // The film's layers are written wherever it has them; the step
        // count, which every film has, where `Aov::Steps` asks for it.
        let cases = [
            (&full, &all[..], 16),
            (&full, &[Aov::Steps][..], 16),
            (&plain, &[][..], 5),
        ];
        for (film, aovs, channels) in cases {
            write_frame(
                &path,
                Format::Exr,
                film,
                "h",
                aovs,
                &crate::shade::Look::default(),
            )
            .unwrap();
            let image = exr::prelude::read_all_flat_layers_from_file(&path).unwrap();
            let layer = &image.layer_data[0];
            assert_eq!(layer.size, exr::math::Vec2(w as usize, h as usize));
            assert_eq!(layer.channel_data.list.len(), channels);
            if channels == 5 {
                let names = layer.channel_data.list.iter().map(|c| c.name.to_string());
                assert_eq!(names.collect::<Vec<_>>(), ["A", "B", "G", "R", "Z"]);
            }
            for i in 0..n {
                for (name, value) in expected_samples(film, !aovs.is_empty(), i) {
                    assert_eq!(read_sample(layer, name, i), value, "{name} at pixel {i}");
                }
            }
        }
    }

    /// What the EXR of `film` should hold at pixel `i` in each channel it
    /// has, as read back (f16 channels rounded to f16, beyond its range held
    /// at its largest).
    fn expected_samples(film: &Film, steps: bool, i: usize) -> Vec<(&'static str, f32)> {
        let half = |x: f32| {
            let rounded = exr::prelude::f16::from_f32(x).to_f32();
            if rounded.is_infinite() {
                65504.0f32.copysign(x)
            } else {
                rounded
            }
        };
        let mut expected = vec![
            ("R", half(film.colour[i].x)),
            ("G", half(film.colour[i].y)),
            ("B", half(film.colour[i].z)),
            ("A", half(film.alpha[i])),
            ("Z", film.depth[i]),
        ];
        if let Some(normal) = &film.normal {
            expected.extend([
                ("N.X", normal[i].x),
                ("N.Y", normal[i].y),
                ("N.Z", normal[i].z),
            ]);
        }
        if let Some(albedo) = &film.albedo {
            expected.extend([
                ("albedo.R", half(albedo[i].x)),
                ("albedo.G", half(albedo[i].y)),
                ("albedo.B", half(albedo[i].z)),
            ]);
        }
        if let Some(traps) = &film.traps {
            expected.extend([
                ("trap.origin", traps[i][0]),
                ("trap.x", traps[i][1]),
                ("trap.y", traps[i][2]),
                ("trap.z", traps[i][3]),
            ]);
        }
        if steps {
            expected.push(("DE", film.evaluations[i] as f32));
        }
        expected
    }

    /// Sample `i` of the channel `name` of `layer`, as f32.
    fn read_sample(
        layer: &exr::image::Layer<exr::image::AnyChannels<exr::image::FlatSamples>>,
        name: &str,
        i: usize,
    ) -> f32 {
        let c = layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.to_string() == name)
            .unwrap_or_else(|| panic!("channel {name} missing"));
        c.sample_data.value_by_flat_index(i).to_f32()
    }

    /// `write_frame` without layers, shown as by default.
    fn write_plain(path: &Path, format: Format, film: &Film, hash: &str) {
        write_frame(
            path,
            format,
            film,
            hash,
            &[],
            &crate::shade::Look::default(),
        )
        .unwrap();
    }

    fn film() -> Film {
        Film {
            width: 3,
            height: 2,
            colour: vec![Vec3::new(0.0, 0.5, 1.0); 6],
            alpha: vec![1.0; 6],
            depth: vec![2.5; 6],
            evaluations: vec![7; 6],
            normal: None,
            albedo: None,
            traps: None,
            stats: FrameStats::default(),
        }
    }

    #[test]
    fn names_are_zero_padded_and_temporaries_hidden() {
        assert_eq!(frame_file_name(42, Format::Png), "frame_00042.png");
        assert_eq!(frame_file_name(7, Format::Exr), "frame_00007.exr");
        // While it is written, a file is a hidden temporary beside the final one.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("frame_00042.png");
        write_atomic(&path, |_, t| {
            let name = t.file_name().unwrap().to_string_lossy().into_owned();
            assert_eq!(t.parent(), Some(dir.path()));
            assert!(name.starts_with(&format!(".frame_00042.png.{}", writer_tag())));
            assert!(name.ends_with(".partial"));
            Ok(())
        })
        .unwrap();
        assert!(path.exists());
    }

    #[test]
    fn hash_changes_with_any_input() {
        let s = Scene::default();
        let h = frame_hash(std::slice::from_ref(&s), 0, 4, 3);
        assert_eq!(h.len(), 64);
        assert_eq!(h, frame_hash(std::slice::from_ref(&s), 0, 4, 3));
        assert_ne!(h, frame_hash(std::slice::from_ref(&s), 1, 4, 3));
        assert_ne!(h, frame_hash(std::slice::from_ref(&s), 0, 5, 3));
        assert_ne!(h, frame_hash(&[s.clone(), s.clone()], 0, 4, 3));
        let mut t = s.clone();
        t.fractal.power = 8.000001;
        assert_ne!(h, frame_hash(&[t], 0, 4, 3));
        // Extra layers are the EXR's alone: its key names them, in order.
        let layers = [Aov::Normal, Aov::Steps];
        assert_eq!(stored_key(Format::Png, &h, &layers), h);
        assert_eq!(stored_key(Format::Exr, &h, &[]), h);
        assert_eq!(
            stored_key(Format::Exr, &h, &layers),
            format!("{h}+normal,steps")
        );
        // A grade other than the default follows the light's hash in the
        // PNG's key alone: the EXR's and the checkpoint's are the light's.
        let mut g = s.clone();
        g.look.exposure = 2.0;
        g.look.tone_map = crate::shade::ToneMap::Filmic;
        let graded = frame_hash(std::slice::from_ref(&g), 0, 4, 3);
        assert_eq!(graded, format!("{h}~exposure=2,Filmic"));
        assert_eq!(light_hash(&graded), h);
        assert_eq!(stored_key(Format::Exr, &graded, &[]), h);
        assert_eq!(stored_key(Format::Png, &graded, &[]), graded);
    }

    /// An 8×8 PNG job of `zoom.ron` over `frames`.
    fn record(frames: (u32, u32)) -> JobRecord {
        JobRecord {
            renderer: "test".into(),
            timeline_path: "zoom.ron".into(),
            timeline_text: String::new(),
            width: 8,
            height: 8,
            formats: vec!["png".into()],
            frames,
            preview: false,
            aovs: Vec::new(),
            samples: None,
            outputs: Vec::new(),
        }
    }

    #[test]
    fn each_format_keeps_its_own_range_layers_and_samples() {
        let dir = tempfile::tempdir().unwrap();
        // A record written before formats had their own: PNGs of 0..120.
        record((0, 120)).write(dir.path()).unwrap();
        let exr = OutputRecord {
            format: "exr".into(),
            frames: (0, 3),
            aovs: vec![Aov::Normal],
            samples: Some(2),
        };
        let few_exrs = JobRecord {
            formats: vec!["exr".into()],
            frames: (0, 3),
            aovs: vec![Aov::Normal],
            samples: Some(2),
            outputs: vec![exr.clone()],
            ..record((0, 3))
        };
        few_exrs.record_in(dir.path(), |_| Ok(())).unwrap();
        let png = OutputRecord {
            format: "png".into(),
            frames: (0, 120),
            aovs: Vec::new(),
            samples: None,
        };
        let merged = JobRecord::read(dir.path()).unwrap();
        assert_eq!(merged.outputs(), [exr.clone(), png.clone()]);
        assert_eq!((merged.frames, merged.formats.len()), ((0, 120), 2));
        // More EXRs widen the EXRs' span alone, and take the new samples.
        let more = OutputRecord {
            frames: (5, 8),
            samples: None,
            ..exr
        };
        JobRecord {
            outputs: vec![more.clone()],
            ..record((5, 8))
        }
        .record_in(dir.path(), |_| Ok(()))
        .unwrap();
        let merged = JobRecord::read(dir.path()).unwrap();
        let widened = OutputRecord {
            frames: (0, 8),
            ..more
        };
        assert_eq!(merged.outputs(), [widened, png]);
    }

    #[test]
    fn renders_started_together_each_add_their_range_to_the_record() {
        const WORKERS: u32 = 8;
        for _ in 0..20 {
            let dir = tempfile::tempdir().unwrap();
            // Another size is another sequence: its range is not kept.
            JobRecord {
                width: 9,
                ..record((100, 200))
            }
            .write(dir.path())
            .unwrap();
            let start = std::sync::Barrier::new(WORKERS as usize);
            std::thread::scope(|s| {
                for worker in 0..WORKERS {
                    let (start, dir) = (&start, dir.path());
                    s.spawn(move || {
                        start.wait();
                        record((worker * 10 + 5, worker * 10 + 10))
                            .record_in(dir, |_| Ok(()))
                            .unwrap();
                    });
                }
            });
            let merged = JobRecord::read(dir.path()).unwrap();
            assert_eq!(
                merged.frames,
                (5, WORKERS * 10),
                "every worker's range is kept"
            );
            assert_eq!(merged.width, 8);
        }
        // A lock file this render cannot open for writing (another user's,
        // here a folder, which only opens for reading) does not stop it.
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join(JOB_LOCK)).unwrap();
        record((0, 3)).record_in(dir.path(), |_| Ok(())).unwrap();
        assert_eq!(JobRecord::read(dir.path()).unwrap().frames, (0, 3));
    }

    #[test]
    fn the_check_of_the_record_there_runs_under_the_lock_and_can_stop_the_write() {
        let dir = tempfile::tempdir().unwrap();
        record((0, 3)).write(dir.path()).unwrap();
        let refused = JobRecord {
            width: 9,
            ..record((5, 6))
        }
        .record_in(dir.path(), |old| {
            assert_eq!(old.frames, (0, 3), "the check sees the record there");
            // Another render cannot take the lock while the check runs.
            let other = File::open(dir.path().join(JOB_LOCK)).unwrap();
            assert!(
                matches!(other.try_lock(), Err(std::fs::TryLockError::WouldBlock)),
                "the check runs under the folder's lock"
            );
            Err(Error::usage("--out", "another sequence"))
        });
        assert!(refused.is_err());
        let kept = JobRecord::read(dir.path()).unwrap();
        assert_eq!((kept.width, kept.frames), (8, (0, 3)), "nothing written");
    }

    #[test]
    fn written_frames_carry_their_hash_and_leave_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        for format in [Format::Png, Format::Exr] {
            let path = dir.path().join(frame_file_name(0, format));
            write_plain(&path, format, &film(), "abc123");
            assert!(path.exists());
            let leftovers: Vec<_> = std::fs::read_dir(dir.path())
                .unwrap()
                .filter_map(|e| e.ok())
                .filter(|e| e.file_name().to_string_lossy().ends_with(".partial"))
                .collect();
            assert!(leftovers.is_empty(), "temporary files left behind");
            for thorough in [false, true] {
                let state = |path: &Path, key| file_state(path, format, key, thorough);
                assert_eq!(state(&path, "abc123"), FileState::Current);
                assert_eq!(state(&path, "other"), FileState::Stale);
                let missing = dir.path().join(frame_file_name(1, format));
                assert_eq!(state(&missing, "abc123"), FileState::Missing);
            }
        }
    }

    #[test]
    fn temporaries_of_dead_local_writers_go_at_once() {
        let dir = tempfile::tempdir().unwrap();
        let host = writer_tag().split('.').next().unwrap().to_string();
        // pid 4194304 is above Linux's pid_max: never alive.
        let dead = format!(".frame_00003.png.{host}.4194304.Ab12Cd.partial");
        let alive = format!(".frame_00004.png.{}Zz99Yy.partial", writer_tag());
        let elsewhere = ".frame_00005.png.other-host.17.Qq11Ww.partial";
        for name in [dead.as_str(), alive.as_str(), elsewhere] {
            std::fs::write(dir.path().join(name), b"x").unwrap();
        }
        assert_eq!(remove_stale_partials(dir.path()).unwrap(), 1);
        assert!(!dir.path().join(&dead).exists());
        assert!(dir.path().join(&alive).exists());
        assert!(dir.path().join(elsewhere).exists());
    }

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
        let path = checkpoint_path(dir.path(), 0);
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
    fn evenly_spaced_keeps_both_ends() {
        let v: Vec<u32> = (0..10).collect();
        assert_eq!(evenly_spaced(&v, 4), vec![0, 3, 6, 9]);
        assert_eq!(evenly_spaced(&v, 20), v);
    }

    #[test]
    fn frame_files_ignore_temporaries_and_other_names() {
        let dir = tempfile::tempdir().unwrap();
        for name in [
            "frame_00001.png",
            "frame_00000.png",
            ".frame_00002.png.partial",
            "frame_x.png",
            "sheet.png",
        ] {
            std::fs::write(dir.path().join(name), b"").unwrap();
        }
        let names: Vec<_> = frame_files(dir.path(), Format::Png)
            .unwrap()
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["frame_00000.png", "frame_00001.png"]);
    }

    #[test]
    fn an_exr_whose_offset_table_is_damaged_is_not_current() {
        // The file keeps its length, but its last offset points at the chunk
        // before: the end check finds the last chunk short of the end, and
        // --verify checks that too.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("frame_00000.exr");
        // Big enough for several chunks.
        let (w, h) = (200, 100);
        let n = (w * h) as usize;
        let film = Film {
            width: w,
            height: h,
            colour: (0..n).map(|i| Vec3::splat(i as f32 / n as f32)).collect(),
            alpha: vec![1.0; n],
            depth: vec![2.5; n],
            evaluations: vec![7; n],
            ..film()
        };
        write_plain(&path, Format::Exr, &film, "abc");
        assert_eq!(
            file_state(&path, Format::Exr, "abc", true),
            FileState::Current
        );
        let mut bytes = std::fs::read(&path).unwrap();
        let meta = exr::meta::MetaData::read_from_buffered(&bytes[..], false).unwrap();
        let chunks = meta.headers[0].chunk_count;
        assert!(chunks >= 2, "{chunks} chunks");
        let at = |b: &[u8], p: usize| u64::from_le_bytes(b[p..p + 8].try_into().unwrap());
        // The table sits just before the first chunk, which its first entry names.
        let table = (8..bytes.len() - 8)
            .find(|&p| at(&bytes, p) == (p + 8 * chunks) as u64)
            .expect("the offset table");
        let (last, before) = (table + 8 * (chunks - 1), table + 8 * (chunks - 2));
        let previous = at(&bytes, before).to_le_bytes();
        bytes[last..last + 8].copy_from_slice(&previous);
        std::fs::write(&path, &bytes).unwrap();
        for thorough in [false, true] {
            let state = file_state(&path, Format::Exr, "abc", thorough);
            assert_eq!(state, FileState::Damaged, "thorough: {thorough}");
        }
    }

    #[test]
    fn a_scan_line_exr_is_checked_to_its_end_too() {
        // Our writer makes tiled files; another tool re-saving one keeps
        // the hash in scan-line blocks, whose chunks start with a y (4
        // bytes) rather than a tile's four numbers (16).
        use exr::prelude::*;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("frame_00000.exr");
        let mut attributes = LayerAttributes::named("");
        attributes.other.insert(
            Text::from(HASH_KEY),
            exr::meta::attribute::AttributeValue::Text(Text::from("abc")),
        );
        let encoding = Encoding {
            blocks: Blocks::ScanLines,
            compression: Compression::ZIP1,
            line_order: LineOrder::Increasing,
        };
        let channels = SpecificChannels::rgb(|p: Vec2<usize>| (p.x() as f32, p.y() as f32, 0.5f32));
        let layer = Layer::new((64, 40), attributes, encoding, channels);
        Image::from_layer(layer).write().to_file(&path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let meta = exr::meta::MetaData::read_from_buffered(&bytes[..], false).unwrap();
        assert!(matches!(
            meta.headers[0].blocks,
            exr::meta::BlockDescription::ScanLines
        ));
        assert!(meta.headers[0].chunk_count > 2);
        for thorough in [false, true] {
            let state = |p: &Path| file_state(p, Format::Exr, "abc", thorough);
            assert_eq!(state(&path), FileState::Current, "thorough: {thorough}");
            let cut = dir.path().join("cut.exr");
            std::fs::write(&cut, &bytes[..bytes.len() - 3]).unwrap();
            assert_eq!(state(&cut), FileState::Damaged, "thorough: {thorough}");
            let long = dir.path().join("long.exr");
            std::fs::write(&long, [&bytes[..], &[0]].concat()).unwrap();
            assert_eq!(state(&long), FileState::Damaged, "thorough: {thorough}");
        }
    }

    #[test]
    fn a_png_cut_after_its_header_is_not_current() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("frame_00000.png");
        write_plain(&path, Format::Png, &film(), "abc");
        assert_eq!(
            file_state(&path, Format::Png, "abc", false),
            FileState::Current
        );
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() - 20]).unwrap();
        for thorough in [false, true] {
            let state = file_state(&path, Format::Png, "abc", thorough);
            assert_eq!(state, FileState::Damaged);
        }
    }

    #[test]
    fn a_truncated_file_is_not_current() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("frame_00000.png");
        std::fs::write(&path, b"\x89PNG\r\n\x1a\n").unwrap();
        assert_eq!(
            file_state(&path, Format::Png, "abc", false),
            FileState::Damaged
        );
    }
}
