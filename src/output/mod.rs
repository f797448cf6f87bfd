//! Frames on disk: one module per file format (`png`: sRGB, 8-bit dithered
//! or 16-bit, with or without alpha; `exr`: linear half-float premultiplied
//! RGBA, a float depth and the layers `--aov` asks for), frame
//! files and the content hash each carries in its own metadata so resume can
//! tell a current frame from a stale one (`frames`), their names (`names`:
//! the `--frame-name` pattern), write-to-temporary-then-rename (`atomic`),
//! contact sheets (`sheet`), CSV tables (`csv`) and the font drawn text
//! uses (`font`).

pub(crate) mod atomic;
pub(crate) mod csv;
pub mod exr;
pub(crate) mod font;
pub(crate) mod frames;
pub(crate) mod names;
pub(crate) mod png;
pub(crate) mod sheet;

#[cfg(test)]
mod tests;

use crate::render::Film;
pub use frames::write_frame;
use serde::Serialize;

/// Metadata key under which every frame stores the hash of what made it.
pub const HASH_KEY: &str = "mandelreel-hash";
/// Metadata key for the frame's render statistics.
pub const STATS_KEY: &str = "mandelreel-stats";

/// An output file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Format {
    /// 8-bit sRGB PNG, dithered (no banding in smooth gradients).
    Png,
    /// 16-bit sRGB PNG.
    Png16,
    /// 16-bit sRGB PNG with straight (unpremultiplied) alpha.
    Png16Alpha,
    /// OpenEXR: linear half-float premultiplied R, G, B, A and a float
    /// depth.Z (camera distance), plus the layers --aov asks for.
    Exr,
}

impl Format {
    pub const ALL: [Format; 4] = [Format::Png, Format::Png16, Format::Png16Alpha, Format::Exr];

    pub fn extension(self) -> &'static str {
        match self {
            Format::Png | Format::Png16 | Format::Png16Alpha => "png",
            Format::Exr => "exr",
        }
    }

    /// The name `--format` takes and the job record keeps.
    pub fn name(self) -> &'static str {
        match self {
            Format::Png => "png",
            Format::Png16 => "png16",
            Format::Png16Alpha => "png16alpha",
            Format::Exr => "exr",
        }
    }

    /// The format `--format` calls `name`.
    pub fn named(name: &str) -> Option<Format> {
        Format::ALL
            .into_iter()
            .find(|f| f.name().eq_ignore_ascii_case(name))
    }

    pub fn is_png(self) -> bool {
        matches!(self.codec(), Codec::Png(_))
    }

    /// The encoder that writes this format, and what it writes.
    pub fn codec(self) -> Codec {
        match self {
            Format::Png => Codec::Png(PngKind::Rgb8),
            Format::Png16 => Codec::Png(PngKind::Rgb16),
            Format::Png16Alpha => Codec::Png(PngKind::Rgba16),
            Format::Exr => Codec::Exr,
        }
    }
}

/// The encoder of a frame file (`png.rs` or `exr.rs`): every match on a
/// format's file goes through this, so a new format must name its encoder.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Codec {
    Png(PngKind),
    Exr,
}

/// The PNG a PNG format writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PngKind {
    /// 8-bit RGB, dithered.
    Rgb8,
    /// 16-bit RGB.
    Rgb16,
    /// 16-bit RGBA with straight alpha.
    Rgba16,
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

/// How a finished film is written: shown through `display` (PNG), with
/// the background kept or made transparent, and the EXR compression.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Encoding {
    pub display: crate::color::Display,
    /// The film leaves the background out (its misses hold no sky): alpha
    /// is the fractal's coverage. Otherwise every pixel is opaque.
    pub transparent: bool,
    pub exr_compression: exr::ExrCompression,
}

/// Extra EXR layers (arbitrary output variables) a render can write.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, serde::Deserialize,
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
    pub const ALL: [Aov; 4] = [Aov::Normal, Aov::Albedo, Aov::Traps, Aov::Steps];

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

/// The frame's render statistics, as its file's `STATS_KEY` records them.
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
