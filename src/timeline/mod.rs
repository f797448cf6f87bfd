//! The RON timeline: a film as a scene per instant. The file is read
//! (`schema`) and checked, every error placed at its line (`parse`,
//! `messages`, `limits`); its tracks become splines (`tracks`), sampled
//! into the scene of any frame (`scene_at`). `parameters` is the one table
//! of what a track can animate; `validate` says whether a scene renders.
//!
//! Every component of every parameter is interpolated by the same scalar
//! spline code; `camera.distance` is interpolated in log space so a zoom
//! keeps a constant apparent speed over many decades of scale.

pub(crate) mod auto;
mod checks;
mod deep_keys;
pub(crate) mod edit;
mod limits;
pub use limits::{MAX_SAMPLES, MAX_SIDE};
mod messages;
pub(crate) mod parameters;
mod parse;
mod relative;
mod scan;
mod schema;
pub(crate) mod spans;
mod spline;
mod tracks;
mod validate;

pub use limits::{
    check_scene_count, TooMany, MAX_FRAMES, MAX_INSTANTS, MAX_KEYS, MAX_SAMPLED_VALUES,
};
pub use parameters::{MIN_FOV_DEGREES, PARAMETERS, ZOOM_TRACK};
pub use schema::{Interpolation, KeyValue};
pub use tracks::Track;
pub use validate::validate_scene;

use crate::error::{Error, Result};
use crate::fractal::AutoIterations;
use crate::math::Real;
use crate::scene::Scene;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// A validated timeline.
#[derive(Clone, Debug)]
pub struct Timeline {
    pub source: PathBuf,
    /// The file stem; names the default output folder.
    pub name: String,
    pub fps: Real,
    pub frame_count: u32,
    pub width: u32,
    pub height: u32,
    /// The scene before any track is applied.
    pub base: Scene,
    pub tracks: Vec<Track>,
    /// `loop: true`: the film is one period of a seamless loop, and frame
    /// `frame_count` would be frame 0 again. The period is `duration_seconds`.
    pub looping: bool,
    /// `fractal.iterations: Auto`'s count at each frame made so far.
    auto_counts: auto::Counts,
    /// The camera's exact position relative to its target at each instant
    /// made so far, where digits give either.
    relatives: relative::Relatives,
    /// The high-precision orbits its deep frames' scenes have followed.
    references: crate::deep::References,
}

/// The longest file read as a timeline: real ones are a few kilobytes, and
/// a file past this (`/dev/zero`) is refused before it fills the memory. At
/// 1 MiB an error's place is found within a second (`spans` reads the text
/// once per level of the field path, and RON reads about 5 MB/s untyped).
pub const MAX_TIMELINE_BYTES: u64 = 1 << 20;

/// A timeline file's text: a regular file (a FIFO is refused, not waited
/// on), at most `MAX_TIMELINE_BYTES`, UTF-8 (a byte that is not is a syntax
/// error at its line and column), a leading byte-order mark dropped.
pub fn read_text(path: &Path) -> Result<String> {
    let syntax = |line, column, message: String| Error::Syntax {
        file: path.to_path_buf(),
        line,
        column,
        message,
    };
    let read = crate::input::open_regular(path)
        .and_then(|file| crate::input::read_at_most(file, MAX_TIMELINE_BYTES));
    let bytes = match read {
        Err(e) if e.kind() == std::io::ErrorKind::FileTooLarge => {
            let mib = MAX_TIMELINE_BYTES >> 20;
            return Err(syntax(
                1,
                1,
                format!("longer than {mib} MiB: not a timeline"),
            ));
        }
        read => read.map_err(|e| Error::io(path, e))?,
    };
    let text = String::from_utf8(bytes).map_err(|e| {
        let before = &e.as_bytes()[..e.utf8_error().valid_up_to()];
        let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
        let line_start = before
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |i| i + 1);
        // Columns count characters, as RON's do.
        let column = String::from_utf8_lossy(&before[line_start..])
            .chars()
            .count()
            + 1;
        syntax(
            line,
            column,
            "not UTF-8 text: save the timeline as UTF-8".into(),
        )
    })?;
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_string(),
        None => text,
    })
}

impl Timeline {
    /// This timeline with `samples` per pixel in place of its own, where
    /// given (`--samples`).
    pub fn with_samples(mut self, samples: Option<u32>) -> Timeline {
        if let Some(n) = samples {
            self.base.samples_per_pixel = n;
        }
        self
    }

    /// Whether checking every scene this timeline's frames show stays
    /// within bounds (`check_scene_count`), with `--samples` applied.
    pub fn check_scene_count(&self) -> std::result::Result<(), TooMany> {
        let values = self.tracks.iter().map(Track::components).sum();
        check_scene_count(&self.base, self.frame_count, values)
    }

    /// This timeline with only the tracks `keep` names: its scenes are
    /// quicker to build where only some parameters matter. With
    /// `iterations: Auto` every track is kept: the count depends on them.
    pub fn with_tracks(&self, keep: impl Fn(&str) -> bool) -> Timeline {
        let auto = self.base.fractal.auto.is_some();
        let kept = |t: &&Track| auto || keep(&t.name);
        // Instants whose cameras are placed alike share what was computed.
        let moves = |t: &&Track| ["camera.position", "camera.target"].contains(&t.name.as_str());
        let same_camera = self.tracks.iter().filter(moves).all(|t| kept(&t));
        Timeline {
            source: self.source.clone(),
            name: self.name.clone(),
            base: self.base.clone(),
            tracks: self.tracks.iter().filter(kept).cloned().collect(),
            auto_counts: self.auto_counts.clone(),
            references: self.references.clone(),
            relatives: match same_camera {
                true => self.relatives.clone(),
                false => Default::default(),
            },
            ..*self
        }
    }

    /// The count `iterations: Auto` chose for frame `frame_index`, and
    /// what decided it; `None` where the timeline gives a number.
    pub fn auto_count(&self, frame_index: u32) -> Option<auto::Resolved> {
        let time = self.time_of(frame_index);
        let scene = self.scene_built(time, false).ok()?;
        let auto = scene.fractal.auto?;
        let (size, instant) = (
            [self.width, self.height],
            (time, Some(frame_index as usize)),
        );
        let references = &self.references;
        Some(self.auto_counts.at(instant, &scene, auto, size, references))
    }

    /// `scene` (one of this timeline's) as it renders at the timeline's
    /// size where it is deep (`deep::prepare`), sharing the reference
    /// orbits its other scenes have followed.
    pub fn prepare_deep(&self, scene: &Scene) -> Option<Scene> {
        crate::deep::prepare_with(scene, [self.width, self.height], &self.references)
    }

    /// The error of this timeline's value at `field`, a path into its file,
    /// found by a check made after loading (the memory its frames need): at
    /// the value's line and column, the file read again for them.
    pub fn field_error(&self, field: &str, message: String) -> Error {
        let text = read_text(&self.source).unwrap_or_default();
        messages::invalid_value(&text, &self.source, field, message)
    }

    /// Reads, parses and validates a timeline file.
    pub fn load(path: &Path) -> Result<Timeline> {
        let text = read_text(path)?;
        Timeline::parse(&text, path)
    }

    /// The first frame with an instant whose scene fails `validate_scene`
    /// (`invalid_instant`): every frame checked on every core, nothing kept
    /// per frame.
    pub fn first_invalid_frame(&self) -> Option<u32> {
        (0..self.frame_count)
            .into_par_iter()
            .find_first(|&frame| self.invalid_instant(frame).is_some())
    }

    /// The first instant of frame `frame_index` whose scene fails
    /// `validate_scene`, with the field and the problem: the frame's own
    /// instant (what previews, `info`, `pick` and `accuracy` show of it),
    /// then with motion blur each sample's between it and the next frame.
    pub fn invalid_instant(&self, frame_index: u32) -> Option<(Real, (String, String))> {
        let blurred = self.base.effects.motion_blur.is_some();
        let own = blurred.then(|| self.time_of(frame_index));
        let mut times = own.into_iter().chain(self.sample_times(frame_index));
        times.find_map(|time| {
            self.scene_built(time, true)
                .and_then(|scene| validate_scene(&scene))
                .err()
                .map(|e| (time, e))
        })
    }

    /// Time in seconds of frame `frame_index`.
    pub fn time_of(&self, frame_index: u32) -> Real {
        frame_index as Real / self.fps
    }

    /// Length of the sequence in seconds.
    pub fn duration_seconds(&self) -> Real {
        self.frame_count as Real / self.fps
    }

    /// The scene of frame `frame_index`: the base scene with every track applied.
    pub fn scene_at(&self, frame_index: u32) -> Scene {
        self.scene_at_time(self.time_of(frame_index))
    }

    /// The scene at any time in seconds, between frames too.
    pub fn scene_at_time(&self, time_seconds: Real) -> Scene {
        self.scene_built(time_seconds, false)
            .unwrap_or_else(|_| unreachable!("only the check fails"))
    }

    /// The base scene with every track applied at a time, the zoom last.
    /// With `check`, a zoom track where the camera's position and target
    /// before it coincide is refused: `camera.distance` places the camera
    /// along the line between them, and there is none.
    fn scene_built(
        &self,
        time_seconds: Real,
        check: bool,
    ) -> std::result::Result<Scene, (String, String)> {
        let mut scene = self.base.clone();
        self.apply_tracks(&mut scene, time_seconds, check)?;
        // Validation needs no count (Auto's are in range by construction),
        // so a scene about to be refused is never marched for one.
        if let Some(auto) = scene.fractal.auto.filter(|_| !check) {
            scene.fractal.iterations = self.auto_at(time_seconds, &scene, auto).count;
        }
        Ok(scene)
    }

    /// Applies every track to `scene` at `time_seconds`, the zoom last,
    /// which starts from the camera's exact relative position (`relatives`).
    /// With `check`, refuses a zoom with no direction (`scene_built`).
    fn apply_tracks(
        &self,
        scene: &mut Scene,
        time_seconds: Real,
        check: bool,
    ) -> std::result::Result<(), (String, String)> {
        for track in &self.tracks {
            if track.name == ZOOM_TRACK {
                let c = &scene.camera;
                let away = c.position - c.target;
                let scale = c.target.abs().max_element().max(1.0);
                if check && away.length() <= 8.0 * Real::EPSILON * scale {
                    return Err((
                        "camera.target".into(),
                        "the camera position and target coincide, so camera.distance has no direction to place the camera along".into(),
                    ));
                }
                self.relatives.carry(time_seconds, &mut scene.camera);
            }
            track.apply(scene, time_seconds);
        }
        Ok(())
    }

    /// `Auto`'s count at `time_seconds`, whose scene is `scene`: the count
    /// of the frame the instant belongs to, at the frame's own time, so a
    /// frame's motion-blur samples share one count (and one reference).
    fn auto_at(&self, time_seconds: Real, scene: &Scene, auto: AutoIterations) -> auto::Resolved {
        let (size, references) = ([self.width, self.height], &self.references);
        let frame = (time_seconds * self.fps + 1e-9).floor();
        let frame_time = frame / self.fps;
        if frame_time < 0.0 {
            return self
                .auto_counts
                .at((time_seconds, None), scene, auto, size, references);
        }
        let instant = (frame_time, Some(frame as usize));
        if frame_time == time_seconds {
            return self.auto_counts.at(instant, scene, auto, size, references);
        }
        let mut own = self.base.clone();
        self.apply_tracks(&mut own, frame_time, false)
            .unwrap_or_else(|_| unreachable!("only the check fails"));
        self.auto_counts.at(instant, &own, auto, size, references)
    }

    /// The instants a frame's samples see: the frame's own, or with motion
    /// blur one per sample spread evenly over the open shutter (sample s at
    /// (s + ½)/n of it), so everything animated blurs as a camera would see it.
    pub fn sample_times(&self, frame_index: u32) -> Vec<Real> {
        let time = self.time_of(frame_index);
        // No track animates the shutter or the sample count: the base has them.
        let Some(blur) = &self.base.effects.motion_blur else {
            return vec![time];
        };
        let n = self.base.samples_per_pixel.max(1);
        let open = blur.shutter / self.fps;
        (0..n)
            .map(|s| time + open * (s as Real + 0.5) / n as Real)
            .collect()
    }

    /// The scenes a frame's samples see, one per `sample_times` instant.
    pub fn scenes_for_frame(&self, frame_index: u32) -> Vec<Scene> {
        self.sample_times(frame_index)
            .into_iter()
            .map(|t| self.scene_at_time(t))
            .collect()
    }
}

#[cfg(test)]
mod tests;
