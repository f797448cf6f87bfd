//! EXR frames: the film's linear light as half floats, its depth and the
//! layers `--aov` asks for, from one table of channels, written in tiles
//! compressed on rayon's pool; and the check that a file ends where its
//! last chunk does.

use super::FileState;
use super::{stats_text, Aov, Encoding, HASH_KEY, STATS_KEY};
use crate::render::Film;
use std::fs::File;
use std::io::{BufReader, Write};
use std::path::Path;

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
        // `depth.Z`, not `Z`: ffmpeg takes a bare Z for the third colour
        // channel; compositors find depth under either name.
        ("depth.Z", F32, Depth),
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

pub(crate) fn encode(
    out: &mut (impl Write + std::io::Seek),
    film: &Film,
    hash: &str,
    aovs: &[Aov],
    encoding: &Encoding,
) -> std::result::Result<(), String> {
    use exr::prelude::*;
    // The film's channels, in name order as the format asks.
    let mut channels: Vec<(&str, SampleType, Plane)> = EXR_CHANNELS
        .iter()
        .filter_map(|&(name, sample, source)| {
            Some((name, sample, Plane::of(film, aovs, source, encoding)?))
        })
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
    // 64-pixel tiles in increasing line order: exrs otherwise orders
    // blocks as its threads finish them, and the bytes would differ run to run.
    .with_encoding(
        encoding.exr_compression.exr(),
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
    /// The same value in every pixel (an opaque frame's alpha).
    Constant(f32),
}

impl<'f> Plane<'f> {
    /// The plane `source` names, if the film has it (the steps layer only
    /// where `aovs` asks for it; alpha the hit coverage where the
    /// background is transparent, else the picture's: 0 beyond a fisheye's
    /// circle, whatever the background).
    fn of(film: &'f Film, aovs: &[Aov], source: Source, encoding: &Encoding) -> Option<Plane<'f>> {
        use Plane::*;
        Some(match source {
            Source::Alpha if !encoding.transparent => match &film.coverage {
                Some(coverage) => Floats(coverage),
                None => Constant(1.0),
            },
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
                Plane::Constant(v) => put_line(line, std::iter::repeat(v), sample),
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

/// `frames::file_state` for an EXR opened as `file`: stale unless its
/// header records `key`; then current if its last chunk ends where the
/// file does and, `thorough`, every chunk reads.
pub(crate) fn file_state(
    mut file: BufReader<File>,
    path: &Path,
    key: &str,
    thorough: bool,
) -> FileState {
    // The header, read once: its hash, then the offset table after it.
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
        let file = BufReader::new(crate::input::open_regular(path).ok()?);
        let chunks = exr::block::read(file, true).ok()?.all_chunks(true).ok()?;
        Some(chunks.into_iter().all(|chunk| chunk.is_ok()))
    };
    let whole = exr_ends_with_its_last_chunk(&mut file, &meta).unwrap_or(false)
        && (!thorough || every_chunk() == Some(true));
    if whole {
        FileState::Current
    } else {
        FileState::Damaged
    }
}

/// Whether a single-part EXR (as `write_frame` writes them) ends exactly
/// where its last chunk does: the header parsed by exr, then the offset
/// table read, and the chunk at the largest offset (its coordinates: a
/// tile's four numbers or a scan-line block's y; its byte count; its
/// bytes) must reach the file's end and not pass it.
/// `file` stands just after the header `meta` (exr reads a header up to
/// the null byte that ends it, and no further): at the offset table.
fn exr_ends_with_its_last_chunk(
    file: &mut BufReader<File>,
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

/// The compressions `--exr-compression` offers: every one exrs writes.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum ExrCompression {
    /// Uncompressed.
    None,
    /// Run-length: lossless, fastest, largest.
    Rle,
    /// Deflate a line at a time: lossless.
    Zips,
    /// Deflate 16 lines at a time: lossless.
    #[default]
    Zip,
    /// Wavelet and Huffman: lossless.
    Piz,
    /// 24-bit floats deflated: lossy for float channels (depth, normals, traps).
    Pxr24,
    /// 4x4 blocks of half floats: lossy.
    B44,
    /// B44 with flat blocks smaller: lossy.
    B44a,
    /// DCT, 32 lines at a time (as in JPEG): lossy.
    Dwaa,
    /// DCT, 256 lines at a time: lossy.
    Dwab,
}

impl ExrCompression {
    pub const ALL: [ExrCompression; 10] = [
        ExrCompression::None,
        ExrCompression::Rle,
        ExrCompression::Zips,
        ExrCompression::Zip,
        ExrCompression::Piz,
        ExrCompression::Pxr24,
        ExrCompression::B44,
        ExrCompression::B44a,
        ExrCompression::Dwaa,
        ExrCompression::Dwab,
    ];

    fn exr(self) -> exr::prelude::Compression {
        use exr::prelude::Compression as C;
        match self {
            ExrCompression::None => C::Uncompressed,
            ExrCompression::Rle => C::RLE,
            ExrCompression::Zips => C::ZIP1,
            ExrCompression::Zip => C::ZIP16,
            ExrCompression::Piz => C::PIZ,
            ExrCompression::Pxr24 => C::PXR24,
            ExrCompression::B44 => C::B44,
            ExrCompression::B44a => C::B44A,
            ExrCompression::Dwaa => C::DWAA(None),
            ExrCompression::Dwab => C::DWAB(None),
        }
    }

    /// Whether a file keeps every sample exactly as rendered.
    pub fn is_lossless(self) -> bool {
        matches!(
            self,
            ExrCompression::None
                | ExrCompression::Rle
                | ExrCompression::Zips
                | ExrCompression::Zip
                | ExrCompression::Piz
        )
    }

    /// The name `--exr-compression` takes.
    pub fn name(self) -> &'static str {
        match self {
            ExrCompression::None => "none",
            ExrCompression::Rle => "rle",
            ExrCompression::Zips => "zips",
            ExrCompression::Zip => "zip",
            ExrCompression::Piz => "piz",
            ExrCompression::Pxr24 => "pxr24",
            ExrCompression::B44 => "b44",
            ExrCompression::B44a => "b44a",
            ExrCompression::Dwaa => "dwaa",
            ExrCompression::Dwab => "dwab",
        }
    }
}
