//! `status`: which frames of a sequence are complete, stale, missing or in
//! progress (`job::status::scan`), printed as text or JSON, with exit status
//! 4 until the sequence is complete.

use super::{unless_output_closed, Incomplete, StatusArgs};
use crate::job::frames::ranges;
use crate::job::status::{scan, FormatStatus, FrameState, Scan};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

/// Scans the sequence, prints the report, and fails with `Incomplete`
/// unless every frame is complete and current.
pub fn status(args: StatusArgs) -> anyhow::Result<()> {
    let sequence = args.sequence.request();
    let s = scan(&args.target, &sequence, args.claim_timeout, args.verify)?;
    let formats = s.formats();
    let video_command = s.video_command(&formats);
    // The exit status says whether the sequence is complete even when the
    // report's reader has gone (`status out/zoom | head -1`).
    let report = if args.json {
        print_json(&s, &formats, video_command.as_deref())
    } else {
        print_text(&s, &formats, video_command.as_deref())
    };
    unless_output_closed(report)?;
    let (complete, total) = (s.complete, s.total);
    if complete == total {
        Ok(())
    } else {
        Err(Incomplete { complete, total }.into())
    }
}

/// The report as one JSON object.
fn print_json(
    s: &Scan,
    formats: &BTreeMap<&str, FormatStatus<'_>>,
    video_command: Option<&str>,
) -> anyhow::Result<()> {
    #[derive(Serialize)]
    struct StatusReport<'a> {
        folder: &'a Path,
        timeline: &'a Path,
        frames: (u32, u32),
        /// The timeline's own frame count (`frames` may be fewer).
        timeline_frames: u32,
        total: usize,
        complete: usize,
        states: BTreeMap<&'a str, &'a Vec<u32>>,
        workers: Vec<String>,
        timeline_changed_since_render: bool,
        /// The timeline the folder was last rendered from, where that
        /// is another file.
        folder_rendered_from: Option<&'a Path>,
        /// Formats whose frames the folder names otherwise than asked,
        /// with the names it records.
        folder_frame_names: BTreeMap<&'a str, String>,
        /// Each format's frames, counted on their own.
        formats: &'a BTreeMap<&'a str, FormatStatus<'a>>,
        /// The ffmpeg command for the frames counted, once they
        /// are complete in the format a video is made from.
        video_command: Option<&'a str>,
    }
    out!(
        "{}",
        serde_json::to_string(&StatusReport {
            folder: &s.plan.out_dir,
            timeline: &s.plan.timeline.source,
            frames: (s.plan.range.start, s.plan.range.end),
            timeline_frames: s.plan.timeline.frame_count,
            total: s.total,
            complete: s.complete,
            states: s.by_state.iter().map(|(s, f)| (s.name(), f)).collect(),
            workers: s.workers.iter().cloned().collect(),
            timeline_changed_since_render: s.changed,
            folder_rendered_from: s.other_timeline.as_deref(),
            folder_frame_names: s
                .other_names
                .iter()
                .map(|(f, n)| (f.as_str(), n.to_string()))
                .collect(),
            formats,
            video_command,
        })?
    );
    Ok(())
}

/// The report as text: a line per state, per format where there are
/// several, and notes.
fn print_text(
    s: &Scan,
    formats: &BTreeMap<&str, FormatStatus<'_>>,
    video_command: Option<&str>,
) -> anyhow::Result<()> {
    let plan = &s.plan;
    out!(
        "{}: {} of {} frames complete and current (frames {}..{} of {}, {}x{})",
        plan.out_dir.display(),
        s.complete,
        s.total,
        plan.range.start,
        plan.range.end,
        plan.timeline.source.display(),
        plan.width,
        plan.height
    );
    for (state, frames) in &s.by_state {
        out!(
            "  {:<12} {:>6}  {}",
            state.name().replace('_', " "),
            frames.len(),
            ranges(frames)
        );
    }
    // Several formats: each on its own line, with what it lacks.
    for (name, f) in formats.iter().filter(|_| formats.len() > 1) {
        let lacking: Vec<String> = (f.states.iter())
            .filter(|(state, _)| **state != FrameState::Complete.name())
            .map(|(state, frames)| format!("; {} {}", state.replace('_', " "), ranges(frames)))
            .collect();
        out!(
            "  {name}: {} of {} complete and current (frames {}..{}){}",
            f.complete,
            f.total,
            f.frames.0,
            f.frames.1,
            lacking.concat()
        );
    }
    if !s.workers.is_empty() {
        out!(
            "  running: {}",
            s.workers.iter().cloned().collect::<Vec<_>>().join(", ")
        );
    }
    let all = plan.timeline.frame_count;
    if plan.range != (0..all) {
        out!(
            "  note: {} has {all} frames; --frames counts only these (status is 0 when they are complete)",
            plan.timeline.source.display(),
        );
    }
    if s.changed {
        out!(
            "  note: {} has changed since this folder's last render started",
            plan.timeline.source.display()
        );
    }
    for (format, names) in &s.other_names {
        out!("  note: the folder's {format} frames are named {names}: add --frame-name {names}");
    }
    if let Some(other) = &s.other_timeline {
        out!(
            "  note: this folder was last rendered from {}, not {}",
            other.display(),
            plan.timeline.source.display()
        );
    }
    if let Some(command) = video_command {
        out!("  encode: {command}");
    }
    Ok(())
}
