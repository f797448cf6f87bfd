//! `sheet`: tiles rendered PNG frames from a folder into one contact sheet.

use super::SheetArgs;
use crate::error::Error;
use crate::output::{self, Format};

/// Writes the contact sheet and says what it holds.
pub fn sheet(args: SheetArgs) -> anyhow::Result<()> {
    if args.count == 0 || args.columns == 0 || args.thumb_width == 0 {
        return Err(Error::usage("--count/--columns/--thumb-width", "must be at least 1").into());
    }
    let out = args.out.unwrap_or_else(|| args.dir.join("sheet.png"));
    if !out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"))
    {
        let message = format!("the sheet is a PNG: name it .png, not {}", out.display());
        return Err(Error::usage("--out", message).into());
    }
    let frames = output::frames::frame_files(&args.dir, Format::Png)?;
    if frames.is_empty() {
        // A --preview render's frames are a folder further down.
        let preview = args.dir.join("preview");
        let hint =
            if output::frames::frame_files(&preview, Format::Png).is_ok_and(|f| !f.is_empty()) {
                format!(" (a preview's are in {})", preview.display())
            } else {
                String::new()
            };
        return Err(Error::usage(
            &args.dir.display().to_string(),
            format!("no frame_NNNNN.png files in this folder{hint}"),
        )
        .into());
    }
    let shown = output::sheet::evenly_spaced(&frames, args.count);
    output::sheet::write_contact_sheet(&shown, args.columns, args.thumb_width, args.labels, &out)?;
    out!(
        "{} frames of {} tiled into {}",
        shown.len(),
        frames.len(),
        out.display()
    );
    Ok(())
}
