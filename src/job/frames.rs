//! Frame numbers as text: the `--frames` range a user writes, and the runs
//! (`0-3, 7`) that messages name frames by.

use crate::error::{Error, Result};

/// Parses a frame range (`A..B`, `A..=B`, `A..`, `..B`, `..=B` or `N`) against `count` frames.
pub fn parse_frames(text: &str, count: u32) -> Result<std::ops::Range<u32>> {
    let bad = |why: String| Error::usage("--frames", why);
    let number = |s: &str, default: u32| -> Result<u32> {
        if s.trim().is_empty() {
            Ok(default)
        } else {
            s.trim().parse().map_err(|_| {
                let hint = if s.contains('-') && !s.trim().starts_with('-') {
                    format!(
                        " (a range is written with two dots: {})",
                        s.replacen('-', "..", 1)
                    )
                } else {
                    String::new()
                };
                bad(format!("{s:?} is not a frame number{hint}"))
            })
        }
    };
    let range = match text.split_once("..") {
        // A..=B, as Rust writes an inclusive range: frames A to B.
        Some((a, b)) if b.starts_with('=') => {
            let last = b[1..].trim();
            if last.is_empty() {
                return Err(bad(format!("{text:?} needs a last frame after ..=")));
            }
            number(a, 0)?..number(last, 0)?.saturating_add(1)
        }
        Some((a, b)) => number(a, 0)?..number(b, count)?,
        None => {
            let n = number(text, 0)?;
            n..n.saturating_add(1)
        }
    };
    if range.start >= range.end {
        return Err(bad(format!(
            "{text:?} is empty (0..4 is frames 0 to 3, 0..=4 frames 0 to 4)"
        )));
    }
    if range.end > count {
        return Err(bad(format!(
            "{text:?} goes past the last frame: the timeline has {count} frames, 0..{count}"
        )));
    }
    Ok(range)
}

/// `frame 5`, or `frames 0-2`, for a range of frames.
pub fn frames_text(range: &std::ops::Range<u32>) -> String {
    match range.len() {
        1 => format!("frame {}", range.start),
        _ => format!("frames {}-{}", range.start, range.end.saturating_sub(1)),
    }
}

/// `ranges` of `frames`, its first few runs only for a long list:
/// `1-7, 9-15, 17-23, 25-31, 33-39, … (1110 frames)`.
pub fn frame_summary(frames: &[u32]) -> String {
    let all = ranges(frames);
    let runs: Vec<&str> = all.split(", ").collect();
    if runs.len() <= 6 {
        return all;
    }
    format!("{}, … ({} frames)", runs[..5].join(", "), frames.len())
}

/// `0-3, 7, 9-12` for sorted frame numbers.
pub fn ranges(frames: &[u32]) -> String {
    let mut parts = Vec::new();
    let mut i = 0;
    while i < frames.len() {
        let mut j = i;
        while j + 1 < frames.len() && frames[j + 1] == frames[j] + 1 {
            j += 1;
        }
        parts.push(if i == j {
            frames[i].to_string()
        } else {
            format!("{}-{}", frames[i], frames[j])
        });
        i = j + 1;
    }
    parts.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_ranges_are_read_as_rust_writes_them() {
        assert_eq!(parse_frames("0..4", 10).unwrap(), 0..4);
        assert_eq!(parse_frames("0..=3", 10).unwrap(), 0..4);
        assert_eq!(parse_frames("..=9", 10).unwrap(), 0..10);
        assert!(parse_frames("0..=10", 10).is_err());
        assert!(parse_frames("3..=", 10).is_err());
        assert!(parse_frames("4..=3", 10).is_err());
        assert_eq!(parse_frames("3..", 10).unwrap(), 3..10);
        assert_eq!(parse_frames("..2", 10).unwrap(), 0..2);
        assert_eq!(parse_frames("7", 10).unwrap(), 7..8);
        assert!(parse_frames("4..4", 10).is_err());
        assert!(parse_frames("5..11", 10)
            .unwrap_err()
            .to_string()
            .contains("10 frames"));
        assert!(parse_frames("a..b", 10).is_err());
        // A dash, as other tools write ranges: the two-dot form is suggested.
        let e = parse_frames("0-3", 10).unwrap_err().to_string();
        assert!(e.contains("written with two dots: 0..3"), "{e}");
        let e = parse_frames("-3", 10).unwrap_err().to_string();
        assert!(!e.contains("two dots"), "{e}");
    }

    #[test]
    fn a_long_list_of_missing_frames_is_cut_short() {
        assert_eq!(frame_summary(&[1, 2, 3, 7]), "1-3, 7");
        let every_other: Vec<u32> = (0..100).step_by(2).collect();
        assert_eq!(frame_summary(&every_other), "0, 2, 4, 6, 8, … (50 frames)");
        assert_eq!(frames_text(&(5..6)), "frame 5");
        assert_eq!(frames_text(&(0..3)), "frames 0-2");
    }
}
