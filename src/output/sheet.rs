//! Contact sheets: a grid of thumbnails of a sequence's PNG frames.

use super::atomic::write_atomic;
use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

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

    #[test]
    fn evenly_spaced_keeps_both_ends() {
        let v: Vec<u32> = (0..10).collect();
        assert_eq!(evenly_spaced(&v, 4), vec![0, 3, 6, 9]);
        assert_eq!(evenly_spaced(&v, 20), v);
    }
}
