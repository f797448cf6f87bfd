//! Contact sheets: a grid of thumbnails of a sequence's PNG frames, each
//! labelled with its frame number where asked.

use super::atomic::write_atomic;
use super::{font, names::FrameName, Format};
use crate::error::{Error, Result};
use image::{Rgb, RgbImage};
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// A label's box and text: light on dark reads on light and dark frames alike.
pub const LABEL_BOX: Rgb<u8> = Rgb([16, 16, 16]);
pub const LABEL_TEXT: Rgb<u8> = Rgb([240, 240, 240]);

/// Thumbnails lower than this get no label: its box, at least 13 pixels
/// high, would cover most of them.
pub const MIN_LABELLED_HEIGHT: u32 = 30;

/// The most pixels a sheet may have (3 bytes each in memory).
const MAX_PIXELS: u64 = 1 << 27;

/// Up to `count` items spread evenly from the first to the last.
pub fn evenly_spaced<T: Clone>(items: &[T], count: usize) -> Vec<T> {
    if items.len() <= count || count < 2 {
        return items.iter().take(count.max(1)).cloned().collect();
    }
    (0..count)
        .map(|i| items[i * (items.len() - 1) / (count - 1)].clone())
        .collect()
}

/// Tiles the PNG `frames` into a grid `columns` wide, each scaled to
/// `thumb_width` and, given `labels` (how they are named), marked with
/// its frame number.
pub fn write_contact_sheet(
    frames: &[PathBuf],
    columns: u32,
    thumb_width: u32,
    labels: Option<&FrameName>,
    out: &Path,
) -> Result<()> {
    use image::imageops;
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
    if w > MAX_SIDE || h > MAX_SIDE || w * h > MAX_PIXELS {
        return Err(Error::usage(
            "--thumb-width/--columns/--count",
            format!(
                "the sheet would be {w}x{h} pixels; it may be at most {MAX_SIDE} a side \
                 and {MAX_PIXELS} pixels in all"
            ),
        ));
    }
    let mut sheet = RgbImage::new(w as u32, h as u32);
    for (i, path) in frames.iter().enumerate() {
        let frame = decode(path)?;
        let mut thumb = imageops::resize(
            &frame,
            thumb_width,
            thumb_height,
            imageops::FilterType::Triangle,
        );
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or_default();
        let number = labels.and_then(|names| names.frame_of(name, Format::Png));
        if let Some(number) = number.filter(|_| thumb_height >= MIN_LABELLED_HEIGHT) {
            draw_label(&mut thumb, &number.to_string()).map_err(|message| Error::Image {
                path: path.clone(),
                message,
            })?;
        }
        let (cx, cy) = (i as u32 % columns, i as u32 / columns);
        imageops::replace(
            &mut sheet,
            &thumb,
            (cx * (thumb_width + gap)) as i64,
            (cy * (thumb_height + gap)) as i64,
        );
    }
    write_atomic(out, |w, named| {
        sheet
            .write_to(w, image::ImageFormat::Png)
            .map_err(|e| Error::Image {
                path: named.to_path_buf(),
                message: e.to_string(),
            })
    })
}

/// Draws `text` on a dark box in the top-left corner of `thumb`, sized to
/// the thumbnail (a ninth of its height, 9 to 48 px); returns the box's
/// width and height, clipped to the thumbnail.
pub fn draw_label(thumb: &mut RgbImage, text: &str) -> std::result::Result<(u32, u32), String> {
    font::register()?;
    let (w, h) = thumb.dimensions();
    let size = (h / 9).clamp(9, 48);
    let pad = (size / 4).max(1);
    let [r, g, b] = LABEL_TEXT.0;
    let style = (font::FAMILY, size).into_font().color(&RGBColor(r, g, b));
    let root = BitMapBackend::with_buffer(thumb.as_mut(), (w, h)).into_drawing_area();
    let (text_w, text_h) = root.estimate_text_size(text, &style).map_err(message)?;
    let (box_w, box_h) = ((text_w + 2 * pad).min(w), (text_h + 2 * pad).min(h));
    let [r, g, b] = LABEL_BOX.0;
    // A filled rectangle leaves out its far column and row.
    let corner = (box_w as i32, box_h as i32);
    root.draw(&Rectangle::new(
        [(0, 0), corner],
        RGBColor(r, g, b).filled(),
    ))
    .map_err(message)?;
    root.draw_text(text, &style, (pad as i32, pad as i32))
        .map_err(message)?;
    root.present().map_err(message)?;
    Ok((box_w, box_h))
}

fn message<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
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

    #[test]
    fn a_label_is_light_text_on_a_dark_box_in_the_corner_only() {
        // On a light frame and a dark one: the box, and only the box, is
        // drawn on, and it holds text lighter than the frame around it.
        for shade in [20, 128, 250] {
            let plain = RgbImage::from_pixel(240, 135, Rgb([shade; 3]));
            let mut labelled = plain.clone();
            let (box_w, box_h) = draw_label(&mut labelled, "119").unwrap();
            assert!(box_w > 20 && box_w < 120 && box_h > 10 && box_h < 60);
            for (x, y, p) in labelled.enumerate_pixels() {
                let inside = x < box_w && y < box_h;
                assert!(inside || *p == plain[(x, y)], "({x}, {y}) outside the box");
            }
            for (x, y) in [
                (0, 0),
                (box_w - 1, 0),
                (0, box_h - 1),
                (box_w - 1, box_h - 1),
            ] {
                assert_eq!(labelled[(x, y)], LABEL_BOX, "box corner ({x}, {y})");
            }
            let text = (0..box_h)
                .flat_map(|y| (0..box_w).map(move |x| (x, y)))
                .filter(|&(x, y)| labelled[(x, y)].0.iter().all(|&c| c >= 200))
                .count();
            assert!(text >= 20, "{text} text pixels on shade {shade}");
        }
    }
}
