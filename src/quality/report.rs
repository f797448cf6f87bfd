//! A sequence's measures as text: a markdown table, one row per frame and
//! a row for them all, and a one-line summary.

use super::{FrameQuality, SequenceQuality};
use std::fmt::Write as _;

/// The table: frame | PSNR dB | speckles | pops, then `all`.
pub fn markdown(q: &SequenceQuality) -> String {
    let mut text =
        String::from("| frame | PSNR dB | speckles | pops |\n| ---: | ---: | ---: | ---: |\n");
    for f in &q.frames {
        let pops = f.pops.map_or("-".into(), |p| p.to_string());
        let row = format!(
            "| {} | {} | {} | {pops} |",
            f.frame,
            db(f.psnr_db),
            f.speckles
        );
        text.push_str(&row);
        text.push('\n');
    }
    let all = format!("| all | {} | {} | {} |", db(q.psnr_db), q.speckles, q.pops);
    text.push_str(&all);
    text.push('\n');
    text
}

/// `3 frames: PSNR 31.20 dB (worst 29.10 dB, frame 2), 4 speckles, 1 pop`.
pub fn summary(q: &SequenceQuality) -> String {
    let n = q.frames.len();
    let mut text = format!("{n} frame{}", plural(n as u64));
    if q.psnr_db.is_some() {
        let _ = write!(text, ": PSNR {} dB", db(q.psnr_db));
        if let Some(worst) = worst(&q.frames) {
            let _ = write!(
                text,
                " (worst {} dB, frame {})",
                db(worst.psnr_db),
                worst.frame
            );
        }
        text.push(',');
    } else {
        text.push_str(": no reference,");
    }
    let (s, p) = (q.speckles, q.pops);
    let _ = write!(text, " {s} speckle{}, {p} pop{}", plural(s), plural(p));
    text
}

/// The frame of lowest PSNR, the first such.
fn worst(frames: &[FrameQuality]) -> Option<&FrameQuality> {
    frames
        .iter()
        .filter(|f| f.psnr_db.is_some())
        .reduce(|a, b| if b.psnr_db < a.psnr_db { b } else { a })
}

/// `31.20`, `inf` for identical images, `-` without a reference.
fn db(psnr: Option<f64>) -> String {
    match psnr {
        Some(v) if v.is_infinite() => "inf".into(),
        Some(v) => format!("{v:.2}"),
        None => "-".into(),
    }
}

fn plural(n: u64) -> &'static str {
    if n == 1 {
        ""
    } else {
        "s"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(frame: u32, psnr_db: Option<f64>, pops: Option<u64>) -> FrameQuality {
        FrameQuality {
            frame,
            psnr_db,
            mse: None,
            speckles: 1,
            pops,
        }
    }

    #[test]
    fn the_table_has_a_row_per_frame_and_one_for_all() {
        let q = SequenceQuality {
            frames: vec![
                frame(4, Some(f64::INFINITY), None),
                frame(5, Some(30.0), Some(1)),
            ],
            psnr_db: Some(33.0),
            worst_psnr_db: Some(30.0),
            speckles: 2,
            pops: 1,
            pixels: 10,
        };
        let table = markdown(&q);
        assert!(table.contains("| 4 | inf | 1 | - |"), "{table}");
        assert!(table.contains("| 5 | 30.00 | 1 | 1 |"), "{table}");
        assert!(table.ends_with("| all | 33.00 | 2 | 1 |\n"), "{table}");
        let line = summary(&q);
        assert_eq!(
            line,
            "2 frames: PSNR 33.00 dB (worst 30.00 dB, frame 5), 2 speckles, 1 pop"
        );
    }
}
