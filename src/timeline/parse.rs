//! From a timeline's text to a `Timeline`: read as RON, the film's fields,
//! scene and tracks validated in turn, every error placed at the line and
//! column of what it blames.

use super::limits::{check_scene_count, TooMany, FRAMES_HINT, MAX_FRAMES, MAX_KEYS, MAX_SIDE};
use super::messages::{invalid_value, syntax_message, Shown};
use super::parameters::{self, PARAMETERS, ZOOM_TRACK};
use super::schema::TimelineFile;
use super::spans;
use super::tracks::{Track, TrackError};
use super::validate::validate_scene;
use super::Timeline;
use crate::error::Place;
use crate::error::{Error, Result};
use crate::math::Real;
use crate::scene::Scene;
use std::path::Path;

/// Past a thousand frames a second no player or encoder keeps up (ffmpeg's
/// -framerate among them).
const MAX_FPS: Real = 1000.0;

/// The timeline's text and file, which errors point into.
struct Source<'a> {
    text: &'a str,
    path: &'a Path,
}

impl Timeline {
    /// Parses and validates timeline `text`; `path` is used in messages.
    pub fn parse(text: &str, path: &Path) -> Result<Timeline> {
        let source = Source { text, path };
        let mut file = source.read()?;
        let (width, height) = source.size(&file)?;
        let frame_count = source.frame_count(&file)?;
        source.environment_map(&mut file.scene)?;
        source.auto_iterations(&file)?;
        if let Err((field, message)) = validate_scene(&file.scene) {
            return Err(source.value(&format!("scene.{field}"), message));
        }
        if let Some(message) = file.scene.camera.uneven_eyes([width, height]) {
            return Err(source.top("size", message));
        }
        // Too many instants to check, or too many track values at them.
        let too_many = |(field, message): TooMany| source.value(field, message);
        check_scene_count(&file.scene, frame_count, 0).map_err(too_many)?;
        let tracks = source.tracks(&file, frame_count)?;
        let values = tracks.iter().map(Track::components).sum();
        check_scene_count(&file.scene, frame_count, values).map_err(too_many)?;

        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "timeline".into());
        let auto_counts = match file.scene.fractal.auto {
            Some(_) => super::auto::Counts::new(frame_count),
            None => Default::default(),
        };
        let timeline = Timeline {
            source: path.to_path_buf(),
            name,
            fps: file.fps,
            frame_count,
            width,
            height,
            base: file.scene,
            tracks,
            looping: file.looping,
            auto_counts,
            relatives: Default::default(),
            references: Default::default(),
        };
        // Splines can overshoot their keys: check every scene the frames
        // render; the first frame that fails is told.
        if let Some(frame) = timeline.first_invalid_frame() {
            if let Some(failure) = timeline.invalid_instant(frame) {
                return Err(source.invalid_frame(&timeline, frame, failure));
            }
        }
        Ok(timeline)
    }
}

impl Source<'_> {
    /// `iterations: Auto` as written: the word RON leaves out of what it
    /// hands over (`fractal::form`) is `Auto`, and no track sets the count
    /// `Auto` chooses.
    fn auto_iterations(&self, file: &TimelineFile) -> Result<()> {
        if file.scene.fractal.auto.is_none() {
            return Ok(());
        }
        let field = "scene.fractal.iterations";
        let written = spans::range_at(self.text, &spans::steps(field))
            .map(|r| self.text[r].trim().to_string())
            .unwrap_or_default();
        let word: String = written
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        if word != "Auto" {
            let shown = written.lines().next().unwrap_or_default();
            let message = format!(
                "expected a whole number of iterations, `Auto` or `Auto(margin: 2)`, got `{shown}`"
            );
            return Err(self.value(field, message));
        }
        let track = "fractal.iterations";
        if file.tracks.contains_key(track) {
            let message = format!(
                "`scene.{track}` is `Auto`, which chooses the count per frame: remove this track, or write a number in the scene"
            );
            return Err(self.value(&format!("tracks[\"{track}\"]"), message));
        }
        Ok(())
    }

    /// The file as written, or where its RON goes wrong.
    fn read(&self) -> Result<TimelineFile> {
        let options = ron::Options::default()
            .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME);
        options.from_str(self.text).map_err(|e| {
            let ((line, column), message) = syntax_message(self.text, &e);
            Error::Syntax {
                file: self.path.to_path_buf(),
                line,
                column,
                message,
            }
        })
    }

    fn invalid(&self, place: Option<Place>, field: String, message: String) -> Error {
        Error::Invalid {
            file: self.path.to_path_buf(),
            place,
            path: field,
            message,
        }
    }

    /// A top-level field where it is written, else the timeline's `(`.
    fn top(&self, field: &str, message: String) -> Error {
        let place = spans::nearest(self.text, field).map(|(_, place)| place);
        self.invalid(place, field.to_string(), message)
    }

    /// The value at `field`, a path into the file (`invalid_value`).
    fn value(&self, field: &str, message: String) -> Error {
        invalid_value(self.text, self.path, field, message)
    }

    /// The frame's width and height, after checking the frame rate.
    fn size(&self, file: &TimelineFile) -> Result<(u32, u32)> {
        if !(file.fps > 0.0 && file.fps <= MAX_FPS) {
            let fps = file.fps.shown();
            let message = format!("must be a number in (0, {MAX_FPS}], got {fps}");
            return Err(self.top("fps", message));
        }
        let (width, height) = file.size;
        if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
            return Err(self.top(
                "size",
                format!("width and height must be 1..={MAX_SIDE}, got ({width}, {height})"),
            ));
        }
        Ok((width, height))
    }

    /// The film's frames, given as a count or a duration.
    fn frame_count(&self, file: &TimelineFile) -> Result<u32> {
        let frames = |message: &str| Err(self.top("frames", message.into()));
        let n = match (file.frames, file.duration_seconds) {
            (Some(_), Some(_)) => return frames("give frames or duration_seconds, not both"),
            (None, None) => return frames("give frames or duration_seconds"),
            (Some(0), None) => return frames("must be at least 1"),
            (Some(n), None) if n > MAX_FRAMES => {
                return frames(&format!("at most {MAX_FRAMES}, got {n}: {FRAMES_HINT}"))
            }
            (Some(n), None) => return Ok(n),
            (None, Some(d)) => {
                let n = d * file.fps;
                if !(d.is_finite() && d > 0.0 && n >= 0.5) {
                    return Err(self.top(
                        "duration_seconds",
                        format!(
                            "must give at least one frame at {} fps, got {}",
                            file.fps,
                            d.shown()
                        ),
                    ));
                }
                n.round()
            }
        };
        if n > MAX_FRAMES as Real {
            return Err(self.top(
                "duration_seconds",
                format!(
                    "gives {} frames at {} fps, more than the {MAX_FRAMES} a timeline \
                     may have: {FRAMES_HINT}",
                    n.shown(),
                    file.fps,
                ),
            ));
        }
        Ok(n as u32)
    }

    /// An environment map: found relative to the timeline, loaded once to
    /// check it, and fingerprinted so frames re-render if it changes.
    fn environment_map(&self, scene: &mut Scene) -> Result<()> {
        let sky = scene.effects.path_tracing.as_mut().map(|pt| &mut pt.sky);
        let Some(crate::shade::Sky::Environment {
            path: map_path,
            digest,
            ..
        }) = sky
        else {
            return Ok(());
        };
        let resolved = if map_path.is_relative() {
            let folder = self.path.parent().unwrap_or(Path::new("."));
            folder.join(&*map_path)
        } else {
            map_path.clone()
        };
        let field = "scene.effects.path_tracing.sky.path";
        let (fingerprint, _) = crate::environment::load_fingerprinted(&resolved).map_err(|e| {
            let message = match e {
                Error::Io { .. } => format!("cannot read {e}"),
                e => format!("not a usable environment map: {e}"),
            };
            self.value(field, message)
        })?;
        *digest = fingerprint;
        *map_path = resolved;
        Ok(())
    }

    /// The file's tracks, each of a parameter there is (of an effect the
    /// scene enables), with keys, and no more keys in all than `MAX_KEYS`;
    /// the zoom last.
    fn tracks(&self, file: &TimelineFile, frame_count: u32) -> Result<Vec<Track>> {
        let all_keys: usize = file.tracks.values().map(|t| t.keys.len()).sum();
        let mut keys_so_far = 0;
        let period = file.looping.then_some(frame_count as Real / file.fps);
        let mut tracks = Vec::new();
        for (name, spec) in &file.tracks {
            let at = |(what, message): TrackError| {
                self.value(&format!("tracks[{name:?}]{what}"), message)
            };
            let Some(parameter) = parameters::find(name) else {
                let known: Vec<&str> = PARAMETERS.iter().map(|(p, _)| *p).collect();
                let known = known.join(", ");
                let message = format!("no such parameter; tracks can animate: {known}");
                return Err(at((String::new(), message)));
            };
            if let Some(effect) = name
                .strip_prefix("effects.")
                .and_then(|r| r.split('.').next())
            {
                if !file.scene.effects.enabled().contains(&effect) {
                    return Err(at((
                        String::new(),
                        format!("animates the {effect} effect, which the scene does not enable: add `{effect}: ()` to scene.effects"),
                    )));
                }
            }
            if let Some(missing) = palette_missing(&file.scene, name) {
                return Err(at((String::new(), missing)));
            }
            if let Some(lacking) = parameters::camera_lacks(&file.scene, name) {
                let message =
                    format!("animates a field the scene's camera lacks; it needs {lacking}");
                return Err(at((String::new(), message)));
            }
            if spec.keys.is_empty() {
                return Err(at((
                    ".keys".into(),
                    "a track needs at least one key".into(),
                )));
            }
            keys_so_far += spec.keys.len();
            if keys_so_far > MAX_KEYS {
                return Err(at((
                    ".keys".into(),
                    format!(
                        "the tracks have {all_keys} keys in all, more than the {MAX_KEYS} a \
                         timeline may have"
                    ),
                )));
            }
            tracks.push(Track::build(parameter, spec, period, file.fps).map_err(at)?);
        }
        // The zoom distance acts on the animated position and target, so it goes last.
        tracks.sort_by_key(|t| t.name == ZOOM_TRACK);
        Ok(tracks)
    }

    /// The error for `timeline`'s first invalid frame, `frame`, whose scene
    /// at `time` fails at `field`: at a key of the field's own track that is
    /// itself out of range, else at the tracks that set the field.
    fn invalid_frame(
        &self,
        timeline: &Timeline,
        frame: u32,
        (time, (field, message)): (Real, (String, String)),
    ) -> Error {
        // The tracks that set the field; else those of its group
        // (a camera.position track can make the target coincide).
        let group = field.split('.').next().unwrap_or("");
        let setting = |t: &&Track| {
            field.starts_with(t.name.as_str())
                // The zoom places the camera.
                || (t.name == ZOOM_TRACK && matches!(field.as_str(), "camera.position" | "camera.target"))
                // The target coincides with the position.
                || (field == "camera.target" && t.name == "camera.position")
        };
        let in_group = |t: &&Track| t.name.split('.').next() == Some(group);
        let mut culprits: Vec<&Track> = timeline.tracks.iter().filter(setting).collect();
        if culprits.is_empty() {
            culprits = timeline.tracks.iter().filter(in_group).collect();
        }
        // A key of the field's own track that is itself out of
        // range: point at it, not at the first frame its curve
        // crosses the limit. (Where the field's check involves
        // others, a camera position and its target, a key's time
        // says nothing of which key is wrong.)
        let own = culprits.iter().filter(|track| track.name == field);
        let bad_key = own.into_iter().find_map(|track| {
            track.key_times.iter().enumerate().find_map(|(k, &time)| {
                let checked = timeline.scene_built(time, true);
                match checked.and_then(|scene| validate_scene(&scene)) {
                    Err((f, message)) if f == field => Some((track, k, message)),
                    _ => None,
                }
            })
        });
        if let Some((track, k, message)) = bad_key {
            let key = format!("tracks[{:?}].keys[{k}].value", track.name);
            return self.value(&key, as_written(message, track, k));
        }
        let animated: Vec<String> = culprits.iter().map(|t| format!("{:?}", t.name)).collect();
        let track_place = |name: &String| spans::place_of(self.text, &format!("tracks[{name}]"));
        self.invalid(
            animated.first().and_then(track_place),
            format!("frame {frame} (t = {time:.4} s): scene.{field}"),
            format!(
                "{message}{}",
                if animated.is_empty() {
                    String::new()
                } else {
                    format!(" (set by track {})", animated.join(", "))
                }
            ),
        )
    }
}

/// What a track named `name` of the look's palette lacks in `scene`:
/// the palette itself, or the stop it animates.
fn palette_missing(scene: &Scene, name: &str) -> Option<String> {
    let rest = name.strip_prefix("look.palette.")?;
    let Some(palette) = &scene.look.palette else {
        return Some(
            "animates the look's palette, which the scene does not have: add `palette: ()` \
             (or its stops) to scene.look"
                .into(),
        );
    };
    let stop: usize = rest
        .strip_prefix("stops[")?
        .split(']')
        .next()?
        .parse()
        .ok()?;
    let count = palette.stops.len();
    (stop >= count).then(|| {
        format!(
            "animates stop {stop} of the palette, which has {count} (stops[0] to stops[{}])",
            count - 1
        )
    })
}

/// `message` about key `k` of `track`, with the key's value as written
/// where a count field could not hold it: a key of 1e11 iterations is
/// held as 4294967295 and a negative one as 0, the u32's range, which the
/// message would otherwise show.
fn as_written(message: String, track: &Track, k: usize) -> String {
    let value = match track.sample(track.key_times[k])[..] {
        [v] => v,
        _ => return message,
    };
    let held = value.round().clamp(0.0, u32::MAX as Real);
    if held == value.round() {
        return message;
    }
    let field = format!("scene.{}", track.name);
    super::limits::count_message(&field, &value.shown()).unwrap_or(message)
}
