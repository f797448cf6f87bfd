//! The plan of a render: its timeline, size, frames, formats and folder,
//! checked from a `Sequence` or read back from a folder's job record; each
//! frame's scenes, hash, files and state; and the ffmpeg command for a video.

use crate::error::Error;
use crate::job::frames::{frames_text, parse_frames};
use crate::job::request::{check_eyes, parse_size, Sequence};
use crate::output::names::FrameName;
use crate::output::{self, Format};
use crate::timeline::Timeline;
use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// A validated render job: what to render, how big, in which formats, where.
#[derive(Clone)]
pub struct Plan {
    pub timeline: Timeline,
    pub width: u32,
    pub height: u32,
    pub range: std::ops::Range<u32>,
    pub formats: Vec<Format>,
    pub out_dir: PathBuf,
    pub preview: bool,
    pub aovs: Vec<output::Aov>,
    pub exr_compression: output::exr::ExrCompression,
    /// `--samples`, applied to the timeline's scene (and recorded).
    pub samples: Option<u32>,
    /// `--verify`: frame files are read to their last byte before they
    /// count as complete (`output::frames::file_state`).
    pub verify: bool,
    /// `--frame-name`: how the frame files, and the hidden files kept for
    /// each frame (claim, checkpoint), are named.
    pub frame_name: FrameName,
}

impl Plan {
    /// Checks every option; touches nothing on disk.
    pub fn new(timeline_path: &Path, args: &Sequence) -> anyhow::Result<Plan> {
        let timeline = Timeline::load(timeline_path)?;
        let mut aovs = args.aovs.clone();
        aovs.sort();
        aovs.dedup();
        let mut formats = if args.formats.is_empty() {
            vec![Format::Png]
        } else {
            args.formats.clone()
        };
        formats.sort();
        formats.dedup();
        let pngs: Vec<&str> = formats
            .iter()
            .filter(|f| f.is_png())
            .map(|f| f.name())
            .collect();
        if pngs.len() > 1 {
            let names = args.frame_name.clone().unwrap_or_default();
            let message = format!(
                "{} would write the same files, {}.png: choose one of them",
                pngs.join(" and "),
                names.to_string().replace('#', "N")
            );
            return Err(Error::usage("--format", message).into());
        }
        if !aovs.is_empty() && !formats.contains(&Format::Exr) {
            return Err(
                Error::usage("--aov", "extra layers are EXR channels: add --format exr").into(),
            );
        }
        let timeline = timeline.with_samples(args.samples);
        if args.samples.is_some() && timeline.base.effects.motion_blur.is_some() {
            // Under motion blur the samples are instants, each checked.
            timeline
                .check_scene_count()
                .map_err(|(_, message)| Error::usage("--samples", message))?;
            let failing = timeline.first_invalid_frame();
            let failure = failing.and_then(|f| Some((f, timeline.invalid_instant(f)?)));
            if let Some((frame, (time, (field, message)))) = failure {
                let message = format!("frame {frame} (t = {time:.4} s): scene.{field}: {message}");
                return Err(Error::usage("--samples", message).into());
            }
        }
        let (mut width, mut height) = match &args.size {
            Some(s) => parse_size("--size", s)?,
            None => (timeline.width, timeline.height),
        };
        check_eyes(&timeline, (width, height))?;
        let range = match &args.frames {
            Some(f) => parse_frames(f, timeline.frame_count)?,
            None => 0..timeline.frame_count,
        };
        formats.sort_by_key(|f| f.extension());
        let mut out_dir = args
            .out
            .clone()
            .unwrap_or_else(|| Path::new("out").join(&timeline.name));
        let preview = args.preview;
        if preview {
            // Halved, a stereo pair's side stays even.
            let half = [(width / 2).max(1), (height / 2).max(1)];
            [width, height] = timeline.base.camera.even_eyes(half);
            out_dir = out_dir.join("preview");
        }
        Ok(Plan {
            timeline,
            width,
            height,
            range,
            formats,
            out_dir,
            preview,
            aovs,
            exr_compression: args.exr_compression.unwrap_or_default(),
            samples: args.samples,
            verify: false,
            frame_name: args.frame_name.clone().unwrap_or_default(),
        })
    }

    pub fn layers(&self) -> crate::render::Layers {
        output::layers_for(&self.aovs)
    }

    /// The plans an output folder records, one per format with its own
    /// range, layers and samples (see `crate::job::record::JobRecord`), and the record.
    pub fn from_folder(dir: &Path) -> anyhow::Result<(Vec<Plan>, crate::job::record::JobRecord)> {
        if !dir.join(crate::job::record::JOB_FILE).exists() {
            let preview = dir.join("preview");
            let hint = if preview.join(crate::job::record::JOB_FILE).exists() {
                format!("; a preview's is in {}", preview.display())
            } else {
                String::new()
            };
            let message = format!(
                "not a mandelreel output folder (no {}){hint}",
                crate::job::record::JOB_FILE
            );
            return Err(Error::usage(&dir.display().to_string(), message).into());
        }
        let job = crate::job::record::JobRecord::read(dir)?;
        let timeline = Timeline::parse(&job.timeline_text, &job.timeline_path)?;
        let plan = |o: crate::job::record::OutputRecord| -> anyhow::Result<Plan> {
            let format = Format::named(&o.format).ok_or_else(|| {
                anyhow::anyhow!("unknown format {:?} in the job record", o.format)
            })?;
            let timeline = timeline.clone().with_samples(o.samples);
            Ok(Plan {
                width: job.width,
                height: job.height,
                range: o.frames.0..o.frames.1.min(timeline.frame_count),
                formats: vec![format],
                out_dir: dir.to_path_buf(),
                preview: job.preview,
                aovs: o.aovs,
                exr_compression: o.exr_compression,
                samples: o.samples,
                verify: false,
                frame_name: o.frame_name,
                timeline,
            })
        };
        let plans = job
            .outputs()
            .into_iter()
            .map(plan)
            .collect::<anyhow::Result<_>>()?;
        Ok((plans, job))
    }

    /// This plan as one plan per format, so each format's frames can be
    /// counted on their own.
    pub fn per_format(&self) -> Vec<Plan> {
        let one = |&format: &Format| Plan {
            formats: vec![format],
            ..self.clone()
        };
        self.formats.iter().map(one).collect()
    }

    pub fn record(&self) -> anyhow::Result<crate::job::record::JobRecord> {
        let text = crate::timeline::read_text(&self.timeline.source)?;
        Ok(crate::job::record::JobRecord {
            renderer: format!("mandelreel {}", env!("CARGO_PKG_VERSION")),
            timeline_path: std::fs::canonicalize(&self.timeline.source)
                .unwrap_or_else(|_| self.timeline.source.clone()),
            timeline_text: text,
            width: self.width,
            height: self.height,
            formats: self.formats.iter().map(|f| f.name().to_string()).collect(),
            frames: (self.range.start, self.range.end),
            preview: self.preview,
            aovs: self.aovs.clone(),
            samples: self.samples,
            outputs: self
                .formats
                .iter()
                .map(|&f| crate::job::record::OutputRecord {
                    format: f.name().to_string(),
                    frames: (self.range.start, self.range.end),
                    // Only EXRs hold extra layers.
                    aovs: if f == Format::Exr {
                        self.aovs.clone()
                    } else {
                        Vec::new()
                    },
                    samples: self.samples,
                    exr_compression: self.exr_compression,
                    frame_name: self.frame_name.clone(),
                })
                .collect(),
        })
    }

    /// The scenes of one frame (one per sample under motion blur) and its content hash.
    pub fn frame(&self, frame: u32) -> (Vec<crate::scene::Scene>, String) {
        #[cfg(test)]
        tally::count(&self.out_dir);
        let scenes = if self.preview {
            // A quick look: one sample, one instant.
            let mut scene = self.timeline.scene_at(frame);
            scene.samples_per_pixel = 1;
            vec![scene]
        } else {
            self.timeline.scenes_for_frame(frame)
        };
        let hash = output::frames::frame_hash(&scenes, frame, self.width, self.height);
        (scenes, hash)
    }

    pub fn path(&self, frame: u32, format: Format) -> PathBuf {
        self.out_dir.join(self.frame_name.file_name(frame, format))
    }

    /// `frame`'s claim (`job::claim`): `.frame_00042.claim`.
    pub fn claim_path(&self, frame: u32) -> PathBuf {
        self.out_dir.join(self.frame_name.hidden(frame, "claim"))
    }

    /// `frame`'s checkpoint (`job::checkpoint`): `.frame_00042.ckpt`.
    pub fn checkpoint_path(&self, frame: u32) -> PathBuf {
        self.out_dir.join(self.frame_name.hidden(frame, "ckpt"))
    }

    /// The format a video is encoded from: the PNGs, where rendered.
    pub fn video_format(&self) -> Format {
        let png = self.formats.iter().find(|f| f.is_png());
        png.copied().unwrap_or(Format::Exr)
    }

    /// The names in the output folder, read once, so that a long film's
    /// frames with nothing on disk are told apart without a look-up each;
    /// `None` where the folder cannot be listed (each is then looked for).
    pub fn listing(&self) -> Option<HashSet<String>> {
        let entries = match std::fs::read_dir(&self.out_dir) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Some(HashSet::new()),
            entries => entries.ok()?,
        };
        let names = entries.map(|e| e.map(|e| e.file_name().into_string().ok()));
        names
            .filter_map(Result::transpose)
            .collect::<Result<_, _>>()
            .ok()
    }

    /// Whether `frame` may have a file, a claim or a checkpoint in `listed`
    /// (`listing`): where nothing was listed, it may.
    pub fn has_files(&self, frame: u32, listed: Option<&HashSet<String>>) -> bool {
        let Some(names) = listed else {
            return true;
        };
        let hidden = ["claim", "ckpt"].map(|kind| self.frame_name.hidden(frame, kind));
        let files = self
            .formats
            .iter()
            .map(|&f| self.frame_name.file_name(frame, f));
        files.chain(hidden).any(|name| names.contains(&name))
    }

    /// Whether `frame`'s file in `format` is whole and current (no hash
    /// is computed where there is no file): looked for in `listed`
    /// (`listing`) where given, else on disk.
    pub fn is_current_in(
        &self,
        frame: u32,
        format: Format,
        listed: Option<&HashSet<String>>,
    ) -> bool {
        let path = self.path(frame, format);
        let there = match listed {
            Some(names) => names.contains(&self.frame_name.file_name(frame, format)),
            None => path.exists(),
        };
        if !there {
            return false;
        }
        let (_, hash) = self.frame(frame);
        let key = output::frames::stored_key(format, &hash, &self.aovs, self.exr_compression);
        output::frames::file_state(&path, format, &key, self.verify) == output::FileState::Current
    }

    /// The ffmpeg command encoding `range` from its `format` files: into
    /// `<name>.mp4` for the whole film, else `<name>_frames_<A>-<B>.mp4`
    /// (`<name>_frame_<A>.mp4` for one).
    pub fn video_command(&self, range: &std::ops::Range<u32>, format: Format) -> String {
        let name = &self.timeline.name;
        let movie = if *range == (0..self.timeline.frame_count) {
            name.clone()
        } else {
            format!("{name}_{}", frames_text(range).replace(' ', "_"))
        };
        let fps = self.timeline.fps;
        let input = self.frame_name.ffmpeg_input(format);
        ffmpeg_command(&self.out_dir, &movie, fps, range, format, &input)
    }

    /// The state of each format's file of `frame` against these inputs
    /// (read whole with `--verify`).
    pub fn file_states(&self, frame: u32, hash: &str) -> Vec<output::FileState> {
        self.formats
            .iter()
            .map(|&f| {
                let key = output::frames::stored_key(f, hash, &self.aovs, self.exr_compression);
                output::frames::file_state(&self.path(frame, f), f, &key, self.verify)
            })
            .collect()
    }

    /// Whether every format of `frame` exists, whole, and was made from
    /// these inputs.
    pub fn is_complete(&self, frame: u32, hash: &str) -> bool {
        let states = self.file_states(frame, hash);
        states.iter().all(|&s| s == output::FileState::Current)
    }
}

/// Quotes a path for a POSIX shell when it needs it.
pub fn shell_quote(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "/._-+%:=,".contains(c))
    {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// Makes odd sizes even (yuv420p needs it), then converts to YUV by the
/// BT.709 matrix into limited range: ffmpeg's default matrix is BT.601,
/// which players of HD video, taking it for 709, show with shifted greens.
const VIDEO_FILTER: &str =
    "pad=ceil(iw/2)*2:ceil(ih/2)*2,scale=out_color_matrix=bt709:out_range=tv,format=yuv420p";

/// The stream's colour tags, saying what `VIDEO_FILTER` made. The transfer
/// is sRGB's (iec61966-2-1), not bt709: the frames hold sRGB-coded values,
/// and colour-managed players decode a bt709 tag with its camera curve.
const VIDEO_TAGS: &str =
    "-colorspace bt709 -color_primaries bt709 -color_trc iec61966-2-1 -color_range tv";

/// The ffmpeg command that encodes frames `range` in `dir`, `format`
/// files named by the ffmpeg pattern `input` (`frame_%05d.png`), as an MP4.
pub fn ffmpeg_command(
    dir: &Path,
    name: &str,
    fps: f64,
    range: &std::ops::Range<u32>,
    format: Format,
    input: &str,
) -> String {
    // ffmpeg reads `%` in an image sequence's name as a pattern: a folder's
    // own `%` is written `%%`.
    let input = Path::new(&dir.to_string_lossy().replace('%', "%%")).join(input);
    let movie = dir.join(format!("{name}.mp4"));
    // EXR frames are linear light; ask ffmpeg to apply the sRGB curve.
    let trc = if format == Format::Exr {
        "-apply_trc iec61966_2_1 "
    } else {
        ""
    };
    format!(
        "ffmpeg -y -framerate {fps} -start_number {start} {trc}-i {input} -frames:v {count} \
         -vf '{VIDEO_FILTER}' -c:v libx264 -crf 18 {VIDEO_TAGS} {movie}",
        start = range.start,
        count = range.end - range.start,
        input = shell_quote(&input.to_string_lossy()),
        movie = shell_quote(&movie.to_string_lossy()),
    )
}

/// How many frames' scenes and hashes were made for each output folder:
/// each test's folder is its own, so tests running at once do not mix.
#[cfg(test)]
pub(crate) mod tally {
    use std::collections::BTreeMap;
    use std::path::{Path, PathBuf};
    use std::sync::Mutex;

    static FRAMES: Mutex<BTreeMap<PathBuf, usize>> = Mutex::new(BTreeMap::new());

    pub(super) fn count(out_dir: &Path) {
        let mut frames = FRAMES.lock().unwrap_or_else(|e| e.into_inner());
        *frames.entry(out_dir.to_path_buf()).or_default() += 1;
    }

    /// Frames made for `out_dir` so far.
    pub fn frames(out_dir: &Path) -> usize {
        let frames = FRAMES.lock().unwrap_or_else(|e| e.into_inner());
        frames.get(out_dir).copied().unwrap_or(0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ffmpeg_command_has_rate_start_and_count() {
        // Frames 10..20 at 24 fps, named by default.
        let command = |dir: &str, name: &str, format| {
            let input = FrameName::default().ffmpeg_input(format);
            ffmpeg_command(Path::new(dir), name, 24.0, &(10..20), format, &input)
        };
        let c = command("out/zoom", "zoom", Format::Png);
        assert!(
            c.contains("-framerate 24 -start_number 10 -i out/zoom/frame_%05d.png -frames:v 10"),
            "{c}"
        );
        assert!(c.ends_with("out/zoom/zoom.mp4"));
        // Converted by the BT.709 matrix into limited range, and tagged so.
        assert!(
            c.contains(",scale=out_color_matrix=bt709:out_range=tv,format=yuv420p' ")
                && c.contains(" -colorspace bt709 -color_primaries bt709 ")
                && c.contains(" -color_trc iec61966-2-1 -color_range tv "),
            "{c}"
        );
        let spaced = command("my out", "z", Format::Exr);
        assert!(
            spaced.contains("-apply_trc iec61966_2_1 -i 'my out/frame_%05d.exr'"),
            "{spaced}"
        );
        let percent = command("take 100%", "z", Format::Png);
        assert!(
            percent.contains("-i 'take 100%%/frame_%05d.png'")
                && percent.ends_with("'take 100%/z.mp4'"),
            "{percent}"
        );
    }
}
