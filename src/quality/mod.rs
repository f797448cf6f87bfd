//! Image quality of a rendered sequence, frame by frame: PSNR against a
//! reference render of the same frames, speckles in each frame and pops
//! from each frame to the next (the measures are in `metrics`; their
//! definitions are in docs/accuracy.md). It works on 8-bit sRGB images in
//! memory, as written to PNG: `mandelreel quality` reads them from folders,
//! other commands may hand over frames they rendered. `report` prints the
//! result as a table.

pub(crate) mod metrics;
pub(crate) mod report;

pub use metrics::psnr_db;

use crate::error::{Error, Result};
use image::RgbImage;
use metrics::Luma;
use serde::Serialize;

/// One frame of a sequence: its number and its pixels, 8-bit sRGB as
/// written to PNG.
#[derive(Clone, Debug)]
pub struct FrameImage {
    pub frame: u32,
    pub image: RgbImage,
}

/// The measures of one frame.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FrameQuality {
    pub frame: u32,
    /// Against the reference frame of the same number, where there is a
    /// reference; +∞ where the two are identical (`"inf"` in JSON).
    #[serde(serialize_with = "finite_or_inf")]
    pub psnr_db: Option<f64>,
    /// Mean squared error against the reference, in 8-bit units².
    pub mse: Option<f64>,
    pub speckles: u64,
    /// To this frame from the one before it in the sequence; None for the first.
    pub pops: Option<u64>,
}

/// The measures of a whole sequence, and of each frame.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SequenceQuality {
    pub frames: Vec<FrameQuality>,
    /// From the mean of the frames' MSEs (not the mean of their PSNRs,
    /// which one identical frame would make infinite).
    #[serde(serialize_with = "finite_or_inf")]
    pub psnr_db: Option<f64>,
    /// The lowest frame's PSNR.
    #[serde(serialize_with = "finite_or_inf")]
    pub worst_psnr_db: Option<f64>,
    /// Over all frames.
    pub speckles: u64,
    /// Over all pairs of consecutive frames.
    pub pops: u64,
    /// Pixels measured: the frames' width × height × their number (for
    /// rates such as speckles per megapixel).
    pub pixels: u64,
}

/// Measures `frames`, a sequence in order, all of one size; with
/// `reference`, each frame against the reference frame of the same number,
/// which must be there and of the same size. The errors name the frame.
#[cfg(test)]
pub fn measure(frames: &[FrameImage], reference: Option<&[FrameImage]>) -> Result<SequenceQuality> {
    let mut meter = Meter::default();
    for frame in frames {
        let matching = match reference {
            Some(all) => Some(reference_frame(all, frame.frame)?),
            None => None,
        };
        meter.add(frame, matching)?;
    }
    meter.finish()
}

#[cfg(test)]
fn reference_frame(all: &[FrameImage], frame: u32) -> Result<&RgbImage> {
    all.iter()
        .find(|r| r.frame == frame)
        .map(|r| &r.image)
        .ok_or_else(|| mismatch(frame, "the reference has no frame of this number"))
}

/// Measures a sequence one frame at a time, keeping only the previous
/// frame's luma: a long sequence read from disk need not all be in memory.
#[derive(Debug, Default)]
pub struct Meter {
    frames: Vec<FrameQuality>,
    previous: Option<Luma>,
    pixels: u64,
}

impl Meter {
    /// Measures the sequence's next frame, against `reference` if given.
    pub fn add(&mut self, frame: &FrameImage, reference: Option<&RgbImage>) -> Result<()> {
        let number = frame.frame;
        let luma = Luma::of(&frame.image);
        if let Some(previous) = &self.previous {
            let first = (previous.width, previous.height);
            let message = "the sequence's frames before it are";
            check_size(number, frame.image.dimensions(), first, message)?;
        }
        let mse = match reference {
            Some(r) => {
                check_size(
                    number,
                    frame.image.dimensions(),
                    r.dimensions(),
                    "the reference is",
                )?;
                Some(metrics::mse(&frame.image, r))
            }
            None => None,
        };
        let pops = self
            .previous
            .as_ref()
            .map(|p| metrics::pops_between(p, &luma));
        self.frames.push(FrameQuality {
            frame: number,
            psnr_db: mse.map(psnr_db),
            mse,
            speckles: metrics::speckles_in(&luma),
            pops,
        });
        self.pixels += u64::from(luma.width) * u64::from(luma.height);
        self.previous = Some(luma);
        Ok(())
    }

    /// The sequence's measures; an error if no frame was added.
    pub fn finish(self) -> Result<SequenceQuality> {
        if self.frames.is_empty() {
            return Err(Error::usage("quality", "no frames to measure"));
        }
        let frames = self.frames;
        // None unless every frame has a reference.
        let mses: Option<Vec<f64>> = frames.iter().map(|f| f.mse).collect();
        let mean_mse = mses.map(|m| m.iter().sum::<f64>() / m.len() as f64);
        let worst_psnr_db = frames
            .iter()
            .filter_map(|f| f.psnr_db)
            .min_by(f64::total_cmp);
        Ok(SequenceQuality {
            psnr_db: mean_mse.map(psnr_db),
            worst_psnr_db: mean_mse.and(worst_psnr_db),
            speckles: frames.iter().map(|f| f.speckles).sum(),
            pops: frames.iter().filter_map(|f| f.pops).sum(),
            pixels: self.pixels,
            frames,
        })
    }
}

/// An error unless frame `frame`, of size `own`, matches `other`, the size
/// of what `what` names ("the reference is").
fn check_size(frame: u32, own: (u32, u32), other: (u32, u32), what: &str) -> Result<()> {
    if own == other {
        return Ok(());
    }
    let (w, h, rw, rh) = (own.0, own.1, other.0, other.1);
    Err(mismatch(
        frame,
        format!("it is {w}×{h} but {what} {rw}×{rh}"),
    ))
}

fn mismatch(frame: u32, message: impl Into<String>) -> Error {
    Error::Frame {
        frame,
        message: message.into(),
    }
}

/// A PSNR as a JSON number, or the string "inf" where it is infinite
/// (identical images), which JSON has no number for.
fn finite_or_inf<S: serde::Serializer>(value: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
    match value {
        Some(v) if v.is_infinite() => s.serialize_str("inf"),
        Some(v) => s.serialize_some(v),
        None => s.serialize_none(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgb;

    fn frame(frame: u32, v: u8) -> FrameImage {
        FrameImage {
            frame,
            image: RgbImage::from_pixel(6, 5, Rgb([v, v, v])),
        }
    }

    #[test]
    fn a_sequence_sums_its_frames_and_averages_their_errors() {
        let frames = [frame(3, 100), frame(4, 102)];
        let reference = [frame(4, 100), frame(3, 101)];
        let q = measure(&frames, Some(&reference)).unwrap();
        assert_eq!(q.frames[0].mse, Some(1.0));
        assert_eq!(q.frames[1].mse, Some(4.0));
        assert_eq!(q.frames[0].pops, None);
        assert_eq!(q.frames[1].pops, Some(0));
        // Mean mse 2.5; the worst frame is 4 (mse 4).
        assert_eq!(q.psnr_db, Some(psnr_db(2.5)));
        assert_eq!(q.worst_psnr_db, Some(psnr_db(4.0)));
        assert_eq!(q.pixels, 60);
    }

    #[test]
    fn without_a_reference_there_is_no_psnr() {
        let q = measure(&[frame(0, 1)], None).unwrap();
        assert_eq!(
            (q.psnr_db, q.worst_psnr_db, q.frames[0].mse),
            (None, None, None)
        );
    }

    #[test]
    fn a_missing_or_other_sized_frame_is_an_error_naming_it() {
        let missing = measure(&[frame(7, 1)], Some(&[frame(6, 1)])).unwrap_err();
        assert!(missing.to_string().starts_with("frame 7: "), "{missing}");
        let mut small = frame(7, 1);
        small.image = RgbImage::new(4, 5);
        let sized = measure(&[small.clone()], Some(&[frame(7, 1)])).unwrap_err();
        assert!(
            sized.to_string().contains("4×5 but the reference is 6×5"),
            "{sized}"
        );
        let within = measure(&[frame(6, 1), small], None).unwrap_err();
        assert!(
            within.to_string().starts_with("frame 7: it is 4×5"),
            "{within}"
        );
    }

    #[test]
    fn an_identical_frame_is_inf_in_json() {
        let q = measure(&[frame(0, 9)], Some(&[frame(0, 9)])).unwrap();
        let json = serde_json::to_value(&q).unwrap();
        assert_eq!(json["psnr_db"], "inf");
        assert_eq!(json["frames"][0]["psnr_db"], "inf");
        assert_eq!(json["frames"][0]["pops"], serde_json::Value::Null);
    }
}
