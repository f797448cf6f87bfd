//! What `status` finds in an output folder: each frame's state in each
//! format (complete, in progress, resumable, stale, damaged, missing), the
//! workers on it, and whether the timeline changed since its render.

use crate::error::Error;
use crate::job::frames::parse_frames;
use crate::job::plan::Plan;
use crate::job::request::Sequence;
use crate::output;
use crate::output::names::FrameName;
use crate::output::Format;
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet, HashSet};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Frames by state, in the order `status` lists them.
pub type ByState = BTreeMap<FrameState, Vec<u32>>;

/// What `status` found: the frames of a sequence by state, over all its
/// formats and in each.
pub struct Scan {
    /// One plan per format, each with its own range.
    pub parts: Vec<Plan>,
    /// What the formats share, over the span of their ranges.
    pub plan: Plan,
    /// Every frame by its state over the formats.
    pub by_state: ByState,
    /// Each part's frames by state, counted on their own.
    pub by_format: Vec<ByState>,
    /// Renders running on the folder, and workers holding a claim.
    pub workers: BTreeSet<String>,
    pub total: usize,
    pub complete: usize,
    /// The timeline the folder was last rendered from, where that is
    /// another file (rendered with --force).
    pub other_timeline: Option<PathBuf>,
    /// Formats whose frames the folder's record names otherwise than the
    /// scan does (a timeline's scan without its render's `--frame-name`),
    /// with the names recorded.
    pub other_names: Vec<(String, FrameName)>,
    /// Whether the timeline changed since the folder's last render started.
    pub changed: bool,
}

/// Scans the sequence `target` names: an output folder (using what it
/// records, only its frames narrowed by `sequence`), or a timeline with the
/// `sequence` options of its render. `verify` reads every frame whole.
pub fn scan(
    target: &Path,
    sequence: &Sequence,
    claim_timeout: Duration,
    verify: bool,
) -> anyhow::Result<Scan> {
    // One plan per format, and the folder's record: read once.
    let (parts, job, counted) = if target.is_dir() {
        folder_plans(target, sequence)?
    } else {
        let plan = Plan::new(target, sequence)?;
        let job = crate::job::record::JobRecord::read(&plan.out_dir).ok();
        let counted = vec![true; plan.formats.len()];
        (plan.per_format(), job, counted)
    };
    let parts: Vec<Plan> = parts
        .into_iter()
        .map(|part| Plan { verify, ..part })
        .collect();
    let counted_parts: Vec<&Plan> = (parts.iter().zip(&counted))
        .filter_map(|(p, c)| c.then_some(p))
        .collect();
    let Some(first) = counted_parts.first() else {
        let message = format!("{} records no output format", crate::job::record::JOB_FILE);
        return Err(Error::usage(&target.display().to_string(), message).into());
    };
    let plan = Plan {
        range: counted_parts
            .iter()
            .map(|p| p.range.start)
            .min()
            .unwrap_or(0)
            ..counted_parts.iter().map(|p| p.range.end).max().unwrap_or(0),
        ..(*first).clone()
    };
    let (by_state, by_format, workers) = frame_states(&plan, &parts, &counted, claim_timeout);
    let total: usize = by_state.values().map(Vec::len).sum();
    let complete = by_state.get(&FrameState::Complete).map_or(0, Vec::len);
    // A folder last rendered from another timeline file (with --force).
    let other_timeline = job
        .as_ref()
        .filter(|job| !job.of_timeline(&plan.timeline.source))
        .map(|job| job.timeline_path.clone());
    let other_names = job.as_ref().map_or(Vec::new(), |job| renamed(job, &parts));
    let changed = other_timeline.is_none()
        && crate::timeline::read_text(&plan.timeline.source)
            .ok()
            .zip(job)
            .is_some_and(|(now, job)| now != job.timeline_text);
    Ok(Scan {
        parts,
        plan,
        by_state,
        by_format,
        workers,
        total,
        complete,
        other_timeline,
        other_names,
        changed,
    })
}

/// The formats of `parts` whose frames `job` records under other names,
/// with those names.
fn renamed(job: &crate::job::record::JobRecord, parts: &[Plan]) -> Vec<(String, FrameName)> {
    let outputs = job.outputs();
    let scanned = |o: &&crate::job::record::OutputRecord| {
        let part = parts.iter().find(|p| o.files_like(p.formats[0]));
        part.is_some_and(|p| p.frame_name != o.frame_name)
    };
    let named = |o: &crate::job::record::OutputRecord| (o.format.clone(), o.frame_name.clone());
    outputs.iter().filter(scanned).map(named).collect()
}

/// The plans an output folder records, narrowed to `--frames` where given,
/// and its record. The folder records the rest of the sequence: other
/// options are refused.
fn folder_plans(
    target: &Path,
    s: &Sequence,
) -> anyhow::Result<(Vec<Plan>, Option<crate::job::record::JobRecord>, Vec<bool>)> {
    let given = [
        ("--out", s.out.is_some()),
        ("--size", s.size.is_some()),
        ("--aov", !s.aovs.is_empty()),
        ("--preview", s.preview),
        ("--samples", s.samples.is_some()),
        ("--frame-name", s.frame_name.is_some()),
        ("--exr-compression", s.exr_compression.is_some()),
    ];
    if let Some((option, _)) = given.iter().find(|(_, given)| *given) {
        return Err(Error::usage(
            option,
            format!(
                "{} is an output folder, which records its own size, samples, layers, \
                 frame names and EXR compression: give the timeline instead (status TIMELINE {option} …) or leave {option} out",
                target.display()
            ),
        )
        .into());
    }
    let (parts, job) = Plan::from_folder(target)?;
    let mut parts = formats_asked(target, parts, &s.formats)?;
    // The film is the format its video is made from, and every format
    // rendered over all its frames: these count every frame (a folder
    // holding some of a film's frames is not a finished film) and decide
    // whether it is complete. Other formats (a few EXRs beside the PNGs)
    // keep the span rendered in them and are reported on their own lines.
    let video = parts
        .iter()
        .position(|p| p.formats[0].is_png())
        .unwrap_or(0);
    let mut film = Vec::new();
    for (i, part) in parts.iter_mut().enumerate() {
        let all = 0..part.timeline.frame_count;
        let whole = i == video || part.range == all;
        let asked = match &s.frames {
            Some(frames) => parse_frames(frames, part.timeline.frame_count)?,
            None => all,
        };
        part.range = match whole {
            true => asked,
            false => part.range.start.max(asked.start)..part.range.end.min(asked.end),
        };
        part.range.end = part.range.end.max(part.range.start);
        film.push(whole);
    }
    Ok((parts, Some(job), film))
}

/// The parts of `parts` in the formats `asked` (all where none is), or
/// an error naming a format the folder holds no frames of.
fn formats_asked(target: &Path, parts: Vec<Plan>, asked: &[Format]) -> anyhow::Result<Vec<Plan>> {
    let held: Vec<&str> = parts.iter().map(|p| p.formats[0].name()).collect();
    if let Some(missing) = asked.iter().find(|f| !held.contains(&f.name())) {
        let message = format!(
            "{} holds no {} frames (it holds {})",
            target.display(),
            missing.name(),
            held.join(", ")
        );
        return Err(Error::usage("--format", message).into());
    }
    let wanted = |p: &Plan| asked.is_empty() || asked.contains(&p.formats[0]);
    Ok(parts.into_iter().filter(wanted).collect())
}

/// Every frame of `plan`'s range by state over the formats of `parts`,
/// each part's frames by state, and the workers on the folder: renders
/// running on it (`claim::announce_run`) and any holding a claim.
fn frame_states(
    plan: &Plan,
    parts: &[Plan],
    counted: &[bool],
    claim_timeout: Duration,
) -> (ByState, Vec<ByState>, BTreeSet<String>) {
    // Fresh temporary files, by frame: a writer is finishing that frame
    // (found by each part's frame names).
    let writing: Vec<HashSet<u32>> = parts
        .iter()
        .map(|p| output::frames::frames_being_written(&p.out_dir, &p.frame_name))
        .collect();
    let mut by_state = ByState::new();
    let mut by_format = vec![ByState::new(); parts.len()];
    let mut workers: BTreeSet<String> = crate::job::claim::live_runs(&plan.out_dir, claim_timeout)
        .iter()
        .map(crate::job::claim::ClaimRecord::who)
        .collect();
    let listed = plan.listing();
    for frame in plan.range.clone() {
        let mut states = Vec::new();
        let each = parts.iter().zip(&mut by_format).zip(&writing).zip(counted);
        for (((part, by_state), writing), &counted) in each {
            if part.range.contains(&frame) {
                // Nothing of it on disk: missing, its scene never built.
                let (state, worker) = match part.has_files(frame, listed.as_ref()) {
                    false if !writing.contains(&frame) => (FrameState::Missing, None),
                    _ => frame_state(part, frame, writing, claim_timeout),
                };
                workers.extend(worker);
                by_state.entry(state).or_insert_with(Vec::new).push(frame);
                states.extend(Some(state).filter(|_| counted));
            }
        }
        // A frame in a gap between formats' ranges is no format's to hold.
        if !states.is_empty() {
            by_state
                .entry(FrameState::of_formats(&states))
                .or_default()
                .push(frame);
        }
    }
    (by_state, by_format, workers)
}

impl Scan {
    /// Each format's frames, by its name.
    pub fn formats(&self) -> BTreeMap<&str, FormatStatus<'_>> {
        self.parts
            .iter()
            .zip(&self.by_format)
            .map(|(part, by_state)| (part.formats[0].name(), FormatStatus::of(part, by_state)))
            .collect()
    }

    /// Once the video's frames are all there: the command that encodes them.
    pub fn video_command(&self, formats: &BTreeMap<&str, FormatStatus<'_>>) -> Option<String> {
        // The PNGs where there are any (`Plan::video_format`): `plan` has
        // only the first part's format, and EXR sorts first.
        let video = self
            .parts
            .iter()
            .find(|p| p.formats[0].is_png())
            .unwrap_or(&self.parts[0]);
        formats
            .get(video.formats[0].name())
            .filter(|f| f.total > 0 && f.complete == f.total)
            .map(|_| video.video_command(&video.range, video.formats[0]))
    }
}

/// The state of one frame in an output folder.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum FrameState {
    // In the order `status` lists them.
    /// Every format exists and carries the current hash.
    Complete,
    /// A live claim or a fresh temporary file: some worker is on it.
    InProgress,
    /// A checkpoint holds part of its samples: a render will continue it.
    Resumable,
    /// A file exists but was made from other inputs (the timeline changed).
    Stale,
    /// A file exists but cannot be read, or is not whole (cut short by a
    /// copy or a full disk, or damaged): a render writes it again.
    Damaged,
    /// Nothing of it yet.
    Missing,
}

impl FrameState {
    /// A frame's state over the `states` of its formats: complete if each
    /// is, else the one that says most of what is left (a live worker, a
    /// checkpoint, a damaged file, a stale one, in that order).
    pub fn of_formats(states: &[FrameState]) -> FrameState {
        use FrameState::*;
        let order = [InProgress, Resumable, Damaged, Stale, Missing];
        order
            .into_iter()
            .find(|s| states.contains(s))
            .unwrap_or(Complete)
    }

    /// The state's name in `status --json` (`in progress` in the text).
    pub fn name(self) -> &'static str {
        match self {
            FrameState::Complete => "complete",
            FrameState::Stale => "stale",
            FrameState::Damaged => "damaged",
            FrameState::InProgress => "in_progress",
            FrameState::Resumable => "resumable",
            FrameState::Missing => "missing",
        }
    }
}

/// The state of `frame` in the one format of `part`, and the worker
/// holding its claim, if a live one does. `writing` holds the frames with
/// a live writer's temporary file.
pub fn frame_state(
    part: &Plan,
    frame: u32,
    writing: &HashSet<u32>,
    claim_timeout: std::time::Duration,
) -> (FrameState, Option<String>) {
    let (_, hash) = part.frame(frame);
    // Each file's header read once, and a file read whole only where
    // its header records these inputs.
    let files = part.file_states(frame, &hash);
    if files.iter().all(|&s| s == output::FileState::Current) {
        return (FrameState::Complete, None);
    }
    let claim = crate::job::claim::read_claim(&part.claim_path(frame))
        .filter(|c| crate::job::claim::is_live(c, claim_timeout));
    if let Some(claim) = claim {
        return (FrameState::InProgress, Some(claim.who()));
    }
    let state = if writing.contains(&frame) {
        FrameState::InProgress
    } else if crate::job::checkpoint::checkpoint_is_for(
        &part.checkpoint_path(frame),
        output::frames::light_hash(&hash),
        part.width,
        part.height,
        part.layers(),
    ) {
        FrameState::Resumable
    } else if files.contains(&output::FileState::Damaged) {
        FrameState::Damaged
    } else if files.contains(&output::FileState::Stale) {
        FrameState::Stale
    } else {
        FrameState::Missing
    };
    (state, None)
}

/// One format's frames in a `status` report.
#[derive(Serialize)]
pub struct FormatStatus<'a> {
    pub frames: (u32, u32),
    pub total: usize,
    pub complete: usize,
    pub states: BTreeMap<&'a str, &'a Vec<u32>>,
}

impl<'a> FormatStatus<'a> {
    pub fn of(part: &Plan, by_state: &'a ByState) -> Self {
        FormatStatus {
            frames: (part.range.start, part.range.end),
            total: by_state.values().map(Vec::len).sum(),
            complete: by_state.get(&FrameState::Complete).map_or(0, Vec::len),
            states: by_state.iter().map(|(s, f)| (s.name(), f)).collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_with_nothing_on_disk_are_missing_without_their_scenes() {
        let dir = tempfile::tempdir().unwrap();
        let timeline = dir.path().join("t.ron");
        std::fs::write(&timeline, "(fps: 24, frames: 300, size: (8, 6))").unwrap();
        let out = dir.path().join("out");
        std::fs::create_dir(&out).unwrap();
        // Not a PNG: damaged, which its inputs' hash is made to tell.
        std::fs::write(out.join("frame_00007.png"), "not a PNG").unwrap();
        let sequence = Sequence {
            out: Some(out.clone()),
            ..Sequence::default()
        };
        let scan = scan(&timeline, &sequence, Duration::from_secs(60), false).unwrap();
        assert_eq!(scan.by_state[&FrameState::Damaged], [7]);
        assert_eq!(scan.by_state[&FrameState::Missing].len(), 299);
        assert_eq!(crate::job::plan::tally::frames(&out), 1);
    }
}
