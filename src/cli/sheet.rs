//! `sheet`: tiles rendered PNG frames from a folder into one contact sheet,
//! finding them by the names the folder records (or `--frame-name`).

use super::SheetArgs;
use crate::error::Error;
use crate::output::names::FrameName;
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
    let names = (args.frame_name.clone()).unwrap_or_else(|| recorded_names(&args.dir));
    let frames = output::frames::frame_files(&args.dir, Format::Png, &names)?;
    if frames.is_empty() {
        // A --preview render's frames are a folder further down.
        let preview = args.dir.join("preview");
        // The preview's own record names its frames, unless --frame-name did.
        let preview_names = match &args.frame_name {
            Some(names) => names.clone(),
            None => recorded_names(&preview),
        };
        let in_preview = output::frames::frame_files(&preview, Format::Png, &preview_names);
        let hint = if in_preview.is_ok_and(|f| !f.is_empty()) {
            format!(" (a preview's are in {})", preview.display())
        } else {
            String::new()
        };
        let message = format!("no PNG frames named {names} in this folder{hint}");
        return Err(Error::usage(&args.dir.display().to_string(), message).into());
    }
    let shown = output::sheet::evenly_spaced(&frames, args.count);
    output::sheet::write_contact_sheet(
        &shown,
        args.columns,
        args.thumb_width,
        args.labels.then_some(&names),
        &out,
    )?;
    let plural = if frames.len() == 1 { "" } else { "s" };
    out!(
        "{} of {} frame{plural} tiled into {}",
        shown.len(),
        frames.len(),
        out.display()
    );
    Ok(())
}

/// How the PNG frames in `dir` are named, by its job record: the default
/// where it has none, or records none (it predates `--frame-name`).
pub(super) fn recorded_names(dir: &std::path::Path) -> FrameName {
    let record = crate::job::record::JobRecord::read(dir).ok();
    let outputs = record.map(|r| r.outputs()).unwrap_or_default();
    outputs
        .into_iter()
        .find(|o| o.files_like(Format::Png))
        .map(|o| o.frame_name)
        .unwrap_or_default()
}
