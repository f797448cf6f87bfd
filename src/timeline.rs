//! The RON timeline: its schema, validation with locations, keyframe tracks on
//! the `splines` crate, and `scene_at(frame)`.
//!
//! A track animates one scene parameter by name (`camera.position`,
//! `fractal.julia`, …). Every component of every parameter is interpolated by
//! the same scalar spline code; `camera.distance` is interpolated in log space
//! so a zoom keeps a constant apparent speed over many decades of scale.

use crate::error::{Error, Result};
use crate::math::{DVec3, Real, Vec3};
use crate::scene::Scene;
use crate::spans::{self, Place};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use splines::{Key, Spline};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// How a track moves between its keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Interpolation {
    /// Hold each key's value until the next key.
    Step,
    /// Straight lines between keys.
    Linear,
    /// Catmull–Rom cubic through the keys (the default): smooth paths.
    CatmullRom,
    /// Ease in and out of every key (cosine), stopping at each.
    Smooth,
}

impl Interpolation {
    fn spline_mode(self) -> splines::Interpolation<Real, Real> {
        match self {
            Interpolation::Step => splines::Interpolation::Step(1.0),
            Interpolation::Linear => splines::Interpolation::Linear,
            Interpolation::CatmullRom => splines::Interpolation::CatmullRom,
            Interpolation::Smooth => splines::Interpolation::Cosine,
        }
    }
}

/// A key's value: a number or a triple such as a position or colour.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum KeyValue {
    Number(Real),
    Triple(Real, Real, Real),
}

/// A number, or a triple written `(x, y, z)` (or `[x, y, z]`, or inside
/// `Some(…)` as `julia` is in a scene). Written by hand rather than derived
/// as an untagged enum, whose one message for every mistake ("did not
/// match any variant") names neither shape.
impl<'de> Deserialize<'de> for KeyValue {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct Shape;
        impl<'de> serde::de::Visitor<'de> for Shape {
            type Value = KeyValue;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number or a triple (x, y, z)")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> std::result::Result<KeyValue, E> {
                Ok(KeyValue::Number(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> std::result::Result<KeyValue, E> {
                Ok(KeyValue::Number(v as Real))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> std::result::Result<KeyValue, E> {
                Ok(KeyValue::Number(v as Real))
            }
            fn visit_some<D: serde::Deserializer<'de>>(
                self,
                d: D,
            ) -> std::result::Result<KeyValue, D::Error> {
                d.deserialize_any(Shape)
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> std::result::Result<KeyValue, A::Error> {
                let mut values = Vec::new();
                while let Some(v) = seq.next_element::<Real>()? {
                    values.push(v);
                }
                match values[..] {
                    [x, y, z] => Ok(KeyValue::Triple(x, y, z)),
                    [v] => Ok(KeyValue::Number(v)),
                    _ => Err(serde::de::Error::custom(format!(
                        "expected a number or a triple (x, y, z), got {} numbers",
                        values.len()
                    ))),
                }
            }
        }
        d.deserialize_any(Shape)
    }
}

impl KeyValue {
    fn components(&self) -> Vec<Real> {
        match *self {
            KeyValue::Number(v) => vec![v],
            KeyValue::Triple(x, y, z) => vec![x, y, z],
        }
    }
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct KeySpec {
    time: Real,
    value: KeyValue,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TrackSpec {
    #[serde(default)]
    interpolation: Option<Interpolation>,
    keys: Vec<KeySpec>,
}

/// The file as written, before validation.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TimelineFile {
    fps: Real,
    #[serde(default)]
    frames: Option<u32>,
    #[serde(default)]
    duration_seconds: Option<Real>,
    size: (u32, u32),
    /// The film is one period of a seamless loop (`Timeline::looping`).
    #[serde(default, rename = "loop")]
    looping: bool,
    #[serde(default)]
    scene: Scene,
    #[serde(default, deserialize_with = "tracks_once_each")]
    tracks: BTreeMap<String, TrackSpec>,
}

/// The tracks by parameter name, refusing a name given twice (a map would
/// keep the last and drop the other without a word).
fn tracks_once_each<'de, D: serde::Deserializer<'de>>(
    deserializer: D,
) -> std::result::Result<BTreeMap<String, TrackSpec>, D::Error> {
    struct Tracks;
    impl<'de> serde::de::Visitor<'de> for Tracks {
        type Value = BTreeMap<String, TrackSpec>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("a map of tracks by parameter name")
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(
            self,
            mut map: A,
        ) -> std::result::Result<Self::Value, A::Error> {
            let mut tracks = BTreeMap::new();
            while let Some(name) = map.next_key::<String>()? {
                if tracks.contains_key(&name) {
                    return Err(serde::de::Error::custom(format!(
                        "the track \"{name}\" is given twice; one track per parameter"
                    )));
                }
                tracks.insert(name, map.next_value()?);
            }
            Ok(tracks)
        }
    }
    deserializer.deserialize_map(Tracks)
}

/// The number written at `line`:`column` (1-based), where a parse error
/// stopped, if it stopped at the fraction of a number: a field that counts
/// (iterations, frames, a size) given `10.5`, which RON reports as a
/// missing comma. (`1e3` there gets RON's own "Invalid digit 'e'", at the
/// number's start.)
fn fraction_at(text: &str, line: usize, column: usize) -> Option<String> {
    let row = text.lines().nth(line.checked_sub(1)?)?;
    let at = row.char_indices().nth(column.checked_sub(1)?)?.0;
    let (before, after) = row.split_at(at);
    let number = |c: char| c.is_ascii_digit() || "+-.eE_".contains(c);
    let digits = before.trim_end_matches(|c: char| c.is_ascii_digit() || c == '_');
    let whole = &before[digits.len()..];
    if whole.is_empty() || !after.starts_with(['.', 'e', 'E']) {
        return None;
    }
    let sign = if digits.ends_with('-') { "-" } else { "" };
    let rest: String = after.chars().take_while(|&c| number(c)).collect();
    Some(format!("{sign}{whole}{rest}"))
}

/// For each line of `text`, the columns (1-based, in characters) of its
/// code: every character that is not white space and not in a comment
/// (`// …` to the end of the line, `/* … */` across lines; a string's
/// characters, `//` included, are code).
fn code_columns(text: &str) -> Vec<Vec<usize>> {
    let (mut in_string, mut in_block) = (false, false);
    text.lines()
        .map(|row| {
            let chars: Vec<char> = row.chars().collect();
            let mut code = Vec::new();
            let mut i = 0;
            while i < chars.len() {
                let (c, next) = (chars[i], chars.get(i + 1).copied());
                if in_block {
                    if c == '*' && next == Some('/') {
                        in_block = false;
                        i += 1;
                    }
                } else if in_string {
                    code.push(i + 1);
                    match c {
                        '\\' => {
                            code.extend(next.map(|_| i + 2));
                            i += 1;
                        }
                        '"' => in_string = false,
                        _ => {}
                    }
                } else if c == '/' && next == Some('/') {
                    break;
                } else if c == '/' && next == Some('*') {
                    in_block = true;
                    i += 1;
                } else {
                    in_string = c == '"';
                    if !c.is_whitespace() {
                        code.push(i + 1);
                    }
                }
                i += 1;
            }
            code
        })
        .collect()
}

/// Where RON's parse error `e` points and what it says, told for a timeline
/// (`line`, `column`, 1-based): the field a wrong value was given to, a
/// missing comma at the end of the line that lacks it, trailing text where
/// it starts, and our own types by what they are rather than their names.
fn syntax_message(text: &str, e: &ron::error::SpannedError) -> ((usize, usize), String) {
    use ron::error::Error as Ron;
    let (line, column) = (e.span.start.line, e.span.start.col);
    let row = |line: usize| text.lines().nth(line.wrapping_sub(1)).unwrap_or("");
    let before = |line: usize, column: usize| -> String {
        row(line).chars().take(column.saturating_sub(1)).collect()
    };
    // Where the text is RON (a value of the wrong shape, a field too many or
    // missing), the field the error is in and the value at fault.
    let typed = spans::path_at(text, line, column);
    let shown = typed
        .as_ref()
        .map_or((line, column), |(_, at)| (at.line, at.column));
    let field = typed
        .map(|(path, _)| path)
        .filter(|path| !path.is_empty())
        .map(|path| format!("`{path}`: "));
    let in_field = field.clone().unwrap_or_default();
    let named = |message: String| {
        // Our types as a timeline's author knows them.
        [
            ("struct `DVec3`", "a triple (x, y, z)"),
            ("struct `Vec3`", "a triple (x, y, z)"),
            ("`DVec3`", "a triple (x, y, z)"),
            ("`Vec3`", "a triple (x, y, z)"),
            ("struct `TimelineFile`", "the timeline"),
            ("`TimelineFile`", "the timeline"),
            ("struct `TrackSpec`", "a track"),
            ("`TrackSpec`", "a track"),
            ("struct `KeySpec`", "a key"),
            ("`KeySpec`", "a key"),
        ]
        .iter()
        .fold(message, |m, (ours, theirs)| m.replace(ours, theirs))
    };
    if let Some(number) = fraction_at(text, line, column) {
        let whole = number.parse::<Real>().ok().filter(|v| v.fract() == 0.0);
        let message = match whole {
            Some(v) if v.abs() < 1e15 => format!(
                "{in_field}expected a whole number, written without a decimal point: {v}, not {number}"
            ),
            _ => format!("{in_field}expected a whole number here, got {number}"),
        };
        return ((line, column), message);
    }
    let code = code_columns(text);
    match &e.code {
        // RON stops at the next field; the comma belongs after the value
        // before it, at the end of the last line with anything on it.
        Ron::ExpectedComma
            if code
                .get(line - 1)
                .is_some_and(|columns| columns.iter().all(|&c| c >= column)) =>
        {
            let previous = (1..line)
                .rev()
                .find_map(|l| code[l - 1].last().map(|&c| (l, c + 1)));
            match previous {
                Some(at) => (at, "expected a comma after this value".into()),
                None => ((line, column), "expected a comma".into()),
            }
        }
        // RON points at the end of the timeline; show where the extra text starts.
        Ron::TrailingCharacters => {
            let at = (line..=code.len())
                .find_map(|l| {
                    let first = code[l - 1].iter().find(|&&c| l > line || c >= column);
                    first.map(|&c| (l, c))
                })
                .unwrap_or((line, column));
            (
                at,
                "text after the timeline's closing `)`: a timeline is one `( … )`".into(),
            )
        }
        Ron::IntegerOutOfBounds => {
            let head = before(line, column + 1);
            let most = if in_field.ends_with("seed`: ") {
                u64::MAX.to_string()
            } else {
                u32::MAX.to_string()
            };
            let message = if head
                .trim_end_matches(|c: char| c.is_ascii_digit())
                .ends_with('-')
            {
                format!("{in_field}must be 0 or more: counts, sizes and seeds are never negative")
            } else {
                format!("{in_field}too large: at most {most}")
            };
            ((line, column), message)
        }
        Ron::SuggestRawIdentifier(found) => (
            (line, column),
            format!("{in_field}expected a field name here (`name: value`), got `{found}`"),
        ),
        code => (shown, named(format!("{in_field}{code}"))),
    }
}

/// A value as messages show it: numbers as written at ordinary
/// magnitudes, in e-notation from a million up and below 1e-4 (not 309
/// digits of 1e308), and an infinity said to be what a number too large
/// for its field became when read (an f32 field given 1e300).
trait Shown {
    fn shown(&self) -> String;
}

macro_rules! shown_number {
    ($t:ty) => {
        impl Shown for $t {
            fn shown(&self) -> String {
                let x = *self;
                if x.is_infinite() {
                    format!("{x} (or a number too large to hold)")
                } else if x != 0.0 && (x.abs() >= 1e6 || x.abs() < 1e-4) {
                    format!("{x:e}")
                } else {
                    format!("{x}")
                }
            }
        }
    };
}
shown_number!(f64);
shown_number!(f32);

macro_rules! shown_vector {
    ($t:ty) => {
        impl Shown for $t {
            fn shown(&self) -> String {
                let [x, y, z] = [self.x.shown(), self.y.shown(), self.z.shown()];
                format!("({x}, {y}, {z})")
            }
        }
    };
}
shown_vector!(DVec3);
shown_vector!(Vec3);

impl Shown for KeyValue {
    fn shown(&self) -> String {
        match *self {
            KeyValue::Number(v) => v.shown(),
            KeyValue::Triple(x, y, z) => DVec3::new(x, y, z).shown(),
        }
    }
}

/// The largest camera position or target component a scene may have.
const MAX_COORDINATE: Real = 1e15;

/// The largest Julia constant component a scene may have (see `validate`).
const MAX_JULIA: Real = 1e15;

/// The largest bounding sphere a scene may have (see `validate`).
const MAX_BOUNDING_RADIUS: Real = 1e6;
/// Membership steps longer than this many footprints would step over
/// whole features: the setting is a fraction of a pixel, or a few.
const MAX_MEMBERSHIP_STEP: Real = 16.0;
/// Shorter steps would spend a ray's `max_steps` creeping along the
/// surface, and then stop it anywhere.
const MIN_MEMBERSHIP_STEP: Real = 0.01;

/// Every parameter a track can animate, with its number of components.
pub const PARAMETERS: &[(&str, usize)] = &[
    ("camera.position", 3),
    ("camera.target", 3),
    ("camera.up", 3),
    ("camera.roll_degrees", 1),
    ("camera.fov_degrees", 1),
    ("camera.distance", 1),
    ("camera.aperture_radius", 1),
    ("camera.focus_distance", 1),
    ("fractal.power", 1),
    ("fractal.iterations", 1),
    ("fractal.bailout", 1),
    ("fractal.julia", 3),
    ("quality.hit_threshold", 1),
    ("quality.membership_step", 1),
    ("quality.fudge", 1),
    ("quality.max_steps", 1),
    ("quality.normal_step", 1),
    ("quality.bounding_radius", 1),
    ("quality.over_relaxation", 1),
    ("look.light_direction", 3),
    ("look.light_colour", 3),
    ("look.ambient", 3),
    ("look.base_colour", 3),
    ("look.trap_x_colour", 3),
    ("look.trap_y_colour", 3),
    ("look.trap_z_colour", 3),
    ("look.trap_occlusion", 1),
    ("look.exposure", 1),
    ("look.background_top", 3),
    ("look.background_bottom", 3),
    ("effects.shadows.softness", 1),
    ("effects.ambient_occlusion.radius", 1),
    ("effects.ambient_occlusion.strength", 1),
    ("effects.specular.strength", 1),
    ("effects.specular.shininess", 1),
    ("effects.fog.density", 1),
    ("effects.fog.colour", 3),
    ("effects.glow.strength", 1),
    ("effects.glow.width", 1),
    ("effects.glow.colour", 3),
];

/// The track that sets the camera–target distance, interpolated in log space.
pub const ZOOM_TRACK: &str = "camera.distance";

/// Writes the sampled `values` of parameter `name` into `scene`.
fn apply(scene: &mut Scene, name: &str, v: &[Real]) {
    let triple = || DVec3::new(v[0], v[1], v[2]);
    let colour = || Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32);
    let count = || v[0].round().clamp(0.0, u32::MAX as Real) as u32;
    let (c, f, q, l) = (
        &mut scene.camera,
        &mut scene.fractal,
        &mut scene.quality,
        &mut scene.look,
    );
    match name {
        "camera.position" => c.position = triple(),
        "camera.target" => c.target = triple(),
        "camera.up" => c.up = triple(),
        "camera.roll_degrees" => c.roll_degrees = v[0],
        "camera.fov_degrees" => c.fov_degrees = v[0],
        "camera.aperture_radius" => c.aperture_radius = v[0],
        "camera.focus_distance" => c.focus_distance = Some(v[0]),
        ZOOM_TRACK => {
            let away = crate::math::normalize_or(c.position - c.target, DVec3::Z);
            c.position = c.target + away * v[0];
        }
        "fractal.power" => f.power = v[0],
        "fractal.iterations" => f.iterations = count(),
        "fractal.bailout" => f.bailout = v[0],
        "fractal.julia" => f.julia = Some(triple()),
        "quality.hit_threshold" => q.hit_threshold = v[0],
        "quality.membership_step" => q.membership_step = v[0],
        "quality.fudge" => q.fudge = v[0],
        "quality.max_steps" => q.max_steps = count(),
        "quality.normal_step" => q.normal_step = v[0],
        "quality.bounding_radius" => q.bounding_radius = v[0],
        "quality.over_relaxation" => q.over_relaxation = v[0],
        "look.light_direction" => l.light_direction = triple(),
        "look.light_colour" => l.light_colour = colour(),
        "look.ambient" => l.ambient = colour(),
        "look.base_colour" => l.base_colour = colour(),
        "look.trap_x_colour" => l.trap_x_colour = colour(),
        "look.trap_y_colour" => l.trap_y_colour = colour(),
        "look.trap_z_colour" => l.trap_z_colour = colour(),
        "look.trap_occlusion" => l.trap_occlusion = v[0] as f32,
        "look.exposure" => l.exposure = v[0] as f32,
        "look.background_top" => l.background_top = colour(),
        "look.background_bottom" => l.background_bottom = colour(),
        effect if effect.starts_with("effects.") => {
            // Validation guarantees the effect is enabled in the base scene.
            let e = &mut scene.effects;
            match effect {
                "effects.shadows.softness" => e.shadows.iter_mut().for_each(|x| x.softness = v[0]),
                "effects.ambient_occlusion.radius" => {
                    e.ambient_occlusion.iter_mut().for_each(|x| x.radius = v[0])
                }
                "effects.ambient_occlusion.strength" => e
                    .ambient_occlusion
                    .iter_mut()
                    .for_each(|x| x.strength = v[0] as f32),
                "effects.specular.strength" => {
                    e.specular.iter_mut().for_each(|x| x.strength = v[0] as f32)
                }
                "effects.specular.shininess" => e
                    .specular
                    .iter_mut()
                    .for_each(|x| x.shininess = v[0] as f32),
                "effects.fog.density" => e.fog.iter_mut().for_each(|x| x.density = v[0]),
                "effects.fog.colour" => e.fog.iter_mut().for_each(|x| x.colour = colour()),
                "effects.glow.strength" => e.glow.iter_mut().for_each(|x| x.strength = v[0] as f32),
                "effects.glow.width" => e.glow.iter_mut().for_each(|x| x.width = v[0]),
                "effects.glow.colour" => e.glow.iter_mut().for_each(|x| x.colour = colour()),
                other => unreachable!("track {other:?} passed validation but has no parameter"),
            }
        }
        other => unreachable!("track {other:?} passed validation but has no parameter"),
    }
}

/// One validated, ready-to-sample track.
#[derive(Clone, Debug)]
pub struct Track {
    pub name: String,
    pub interpolation: Interpolation,
    pub key_times: Vec<Real>,
    /// One spline per component, over padded keys (see `build_spline`).
    splines: Vec<Spline<Real, Real>>,
    /// First and last key values per component, for sampling outside the keys.
    ends: (Vec<Real>, Vec<Real>),
    /// Values are stored as logarithms and exponentiated when sampled.
    log_space: bool,
    /// In a looping film, its period: the track repeats with it, and its
    /// splines hold the keys of three periods (`build_spline`).
    period: Option<Real>,
}

impl Track {
    /// The parameter's value at `time_seconds`; held constant outside the
    /// keys, or in a looping film the same every period.
    pub fn sample(&self, time_seconds: Real) -> Vec<Real> {
        self.sample_components(time_seconds)[..self.splines.len()].to_vec()
    }

    /// `sample` without allocating (every scene of every frame is checked):
    /// the value's components first, at most three.
    fn sample_components(&self, time_seconds: Real) -> [Real; 3] {
        let first = self.key_times[0];
        let last = self.key_times[self.key_times.len() - 1];
        let mut raw = [0.0; 3];
        let values = raw.iter_mut().zip(&self.splines).zip(&self.ends.0);
        if let Some(period) = self.period {
            // Into [0, period): a tiny negative time's remainder can round
            // up to the period itself.
            let t = time_seconds.rem_euclid(period);
            let t = if t < period { t } else { 0.0 };
            for ((v, s), &fallback) in values {
                *v = s.sample(t).unwrap_or(fallback);
            }
        } else if time_seconds <= first {
            raw[..self.ends.0.len()].copy_from_slice(&self.ends.0);
        } else if time_seconds >= last {
            raw[..self.ends.1.len()].copy_from_slice(&self.ends.1);
        } else {
            for ((v, s), &fallback) in values {
                *v = s.sample(time_seconds).unwrap_or(fallback);
            }
        }
        if self.log_space {
            raw = raw.map(Real::exp);
        }
        raw
    }
}

/// A key's problem: its index, the field (`time` or `value`), the message.
type KeyError = (usize, &'static str, String);

/// The keys of a looping film's track (`times`, one column of values per
/// component, written as `keys`) laid out over one period, [0, `period`).
/// A key at the period's end is the start's again: within half a frame of
/// it, since `duration_seconds` is rounded to whole frames (4 s at 29.97 fps
/// is 120 frames, a period of 4.004 s), and no frame lies between. It must
/// equal a key at the start (within half a frame of 0), which then stands
/// for both; without one it moves to 0 s. A key outside the period is an
/// error.
fn one_period(
    times: &[Real],
    mut columns: Vec<Vec<Real>>,
    keys: &[KeySpec],
    period: Real,
    fps: Real,
) -> std::result::Result<(Vec<Real>, Vec<Vec<Real>>), KeyError> {
    let half_frame = 0.5 / fps;
    let at_end = |t: Real| (t - period).abs() < half_frame;
    if let Some(k) = times
        .iter()
        .position(|&t| t < 0.0 || (t > period && !at_end(t)))
    {
        let period = (period * 1e6).round() / 1e6;
        let message = format!(
            "a looping film's keys lie within its one period, 0 s to {period} s (frames / fps), \
             got {}; the loop repeats them every {period} s",
            times[k]
        );
        return Err((k, "time", message));
    }
    let mut times = times.to_vec();
    let last = times.len() - 1;
    if !at_end(times[last]) {
        return Ok((times, columns));
    }
    times.pop();
    let end_values: Vec<Real> = columns.iter_mut().filter_map(|c| c.pop()).collect();
    if last > 0 && times[0] < half_frame {
        let (end, start) = (&keys[last].value, &keys[0].value);
        let same = start
            .components()
            .iter()
            .zip(end.components())
            .all(|(a, b)| (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0));
        if !same {
            let message = format!(
                "in a looping film the key at its end ({} s) is the key at 0 s again, so it \
                 must have the same value: {} here, {} at 0 s (or leave one of them out)",
                keys[last].time,
                end.shown(),
                start.shown()
            );
            return Err((last, "value", message));
        }
    } else {
        times.insert(0, 0.0);
        for (c, v) in columns.iter_mut().zip(end_values) {
            c.insert(0, v);
        }
    }
    Ok((times, columns))
}

/// Builds the spline of one component. Phantom keys are mirrored beyond both
/// ends so Catmull–Rom, which needs a neighbour on each side, covers the first
/// and last segments too. With a `period` (a looping film; `times` in
/// [0, period)), the keys are laid out over the period before, this one and
/// the next instead, so every segment in [0, period) has its true
/// neighbours: the last key leads into the first as any key into the next.
fn build_spline(
    times: &[Real],
    values: &[Real],
    mode: Interpolation,
    period: Option<Real>,
) -> Spline<Real, Real> {
    let m = mode.spline_mode();
    if let Some(period) = period {
        let keys = [-period, 0.0, period].into_iter().flat_map(|shift| {
            let key = move |(&t, &v): (&Real, &Real)| Key::new(t + shift, v, m);
            times.iter().zip(values).map(key)
        });
        return Spline::from_vec(keys.collect());
    }
    let mut keys: Vec<Key<Real, Real>> = times
        .iter()
        .zip(values)
        .map(|(&t, &v)| Key::new(t, v, m))
        .collect();
    let n = times.len();
    if n >= 2 {
        let before = Key::new(2.0 * times[0] - times[1], 2.0 * values[0] - values[1], m);
        let after = Key::new(
            2.0 * times[n - 1] - times[n - 2],
            2.0 * values[n - 1] - values[n - 2],
            m,
        );
        keys.insert(0, before);
        keys.push(after);
    }
    Spline::from_vec(keys)
}

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
}

/// The most frames a timeline may have: 11.6 hours at 24 fps, longer than
/// any film.
pub const MAX_FRAMES: u32 = 1_000_000;

/// What the frame limit's messages suggest.
const FRAMES_HINT: &str = "split a longer film into timelines of its parts";

/// The most instants a timeline's frames may show: with motion blur each
/// sample of a frame sees the timeline at its own instant. Every one's scene
/// is checked before a frame renders (`Timeline::invalid_instant`), a
/// quarter of a second a million on two cores.
pub const MAX_INSTANTS: u64 = 2_000_000;

/// The most track values sampled in checking every instant (each animated
/// value, a component of a track's parameter, at every instant): from 0.2
/// to 1 s a ten million on two cores, as the tracks' keys grow.
pub const MAX_SAMPLED_VALUES: u64 = 10_000_000;

/// The most keys a timeline's tracks may have in all: a key a frame for
/// an hour at 24 fps, on one track or spread over several.
pub const MAX_KEYS: usize = 100_000;

/// Too many scenes to check: the field to blame (`scene.samples_per_pixel`
/// or `tracks`) and why.
pub type TooMany = (&'static str, String);

/// Whether the instants `frame_count` frames of `scene` show (one each, or
/// one per sample with motion blur), and the `values` a timeline's tracks
/// animate sampled at each, stay within `MAX_INSTANTS` and
/// `MAX_SAMPLED_VALUES`.
pub fn check_scene_count(
    scene: &Scene,
    frame_count: u32,
    values: usize,
) -> std::result::Result<(), TooMany> {
    let samples = scene.samples_per_pixel as u64;
    let (instants, shown) = match scene.effects.motion_blur {
        Some(_) => (
            frame_count as u64 * samples,
            format!("{frame_count} frames × {samples} motion-blurred samples"),
        ),
        None => (frame_count as u64, format!("{frame_count} frames")),
    };
    if instants > MAX_INSTANTS {
        return Err((
            "scene.samples_per_pixel",
            format!(
                "with motion blur each of a frame's samples sees the timeline at its own \
                 instant: {shown} = {instants} instants, more than the {MAX_INSTANTS} a \
                 timeline may have; take fewer frames or samples"
            ),
        ));
    }
    let sampled = instants * values as u64;
    if sampled > MAX_SAMPLED_VALUES {
        return Err((
            "tracks",
            format!(
                "every instant's scene is checked before rendering: {values} animated values \
                 (the tracks' components) × {shown} = {sampled} track samples, more than the \
                 {MAX_SAMPLED_VALUES} checked at most; take fewer frames, samples or tracks"
            ),
        ));
    }
    Ok(())
}

/// The longest file read as a timeline: real ones are a few kilobytes, and
/// a file past this (`/dev/zero`) is refused before it fills the memory. At
/// 1 MiB an error's place is found within a second (`spans` reads the text
/// once per level of the field path, and RON reads about 5 MB/s untyped).
const MAX_TIMELINE_BYTES: u64 = 1 << 20;

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
        let values = self.tracks.iter().map(|t| t.splines.len()).sum();
        check_scene_count(&self.base, self.frame_count, values)
    }

    /// This timeline with only the tracks `keep` names: its scenes are
    /// quicker to build where only some parameters matter.
    pub fn with_tracks(&self, keep: impl Fn(&str) -> bool) -> Timeline {
        Timeline {
            source: self.source.clone(),
            name: self.name.clone(),
            base: self.base.clone(),
            tracks: self
                .tracks
                .iter()
                .filter(|t| keep(&t.name))
                .cloned()
                .collect(),
            ..*self
        }
    }

    /// Reads, parses and validates a timeline file.
    pub fn load(path: &Path) -> Result<Timeline> {
        let text = read_text(path)?;
        Timeline::parse(&text, path)
    }

    /// Parses and validates timeline `text`; `path` is used in messages.
    pub fn parse(text: &str, path: &Path) -> Result<Timeline> {
        let options = ron::Options::default()
            .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME);
        let mut file: TimelineFile = options.from_str(text).map_err(|e| {
            let ((line, column), message) = syntax_message(text, &e);
            Error::Syntax {
                file: path.to_path_buf(),
                line,
                column,
                message,
            }
        })?;
        let invalid = |place: Option<Place>, field: String, message: String| Error::Invalid {
            file: path.to_path_buf(),
            place,
            path: field,
            message,
        };
        // A top-level field where it is written, else the timeline's `(`.
        let top = |field: &str, message: String| {
            let place = spans::nearest(text, field).map(|(_, place)| place);
            invalid(place, field.to_string(), message)
        };
        let value = |field: &str, message: String| invalid_value(text, path, field, message);

        // Past a thousand frames a second no player or encoder keeps up
        // (ffmpeg's -framerate among them).
        const MAX_FPS: Real = 1000.0;
        if !(file.fps > 0.0 && file.fps <= MAX_FPS) {
            return Err(top(
                "fps",
                format!(
                    "must be a number in (0, {MAX_FPS}], got {}",
                    file.fps.shown()
                ),
            ));
        }
        let (width, height) = file.size;
        const MAX_SIDE: u32 = 32_768;
        if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
            return Err(top(
                "size",
                format!("width and height must be 1..={MAX_SIDE}, got ({width}, {height})"),
            ));
        }
        let frame_count = match (file.frames, file.duration_seconds) {
            (Some(_), Some(_)) => {
                return Err(top(
                    "frames",
                    "give frames or duration_seconds, not both".into(),
                ))
            }
            (None, None) => return Err(top("frames", "give frames or duration_seconds".into())),
            (Some(0), None) => return Err(top("frames", "must be at least 1".into())),
            (Some(n), None) if n > MAX_FRAMES => {
                return Err(top(
                    "frames",
                    format!("at most {MAX_FRAMES}, got {n}: {FRAMES_HINT}"),
                ))
            }
            (Some(n), None) => n,
            (None, Some(d)) => {
                let n = d * file.fps;
                if !(d.is_finite() && d > 0.0 && n >= 0.5) {
                    return Err(top(
                        "duration_seconds",
                        format!(
                            "must give at least one frame at {} fps, got {}",
                            file.fps,
                            d.shown()
                        ),
                    ));
                }
                if n.round() > MAX_FRAMES as Real {
                    return Err(top(
                        "duration_seconds",
                        format!(
                            "gives {} frames at {} fps, more than the {MAX_FRAMES} a timeline \
                             may have: {FRAMES_HINT}",
                            n.round().shown(),
                            file.fps,
                        ),
                    ));
                }
                n.round() as u32
            }
        };
        // An environment map: found relative to the timeline, loaded once to
        // check it, and fingerprinted so frames re-render if it changes.
        if let Some(crate::shade::Sky::Environment {
            path: map_path,
            digest,
            ..
        }) = file
            .scene
            .effects
            .path_tracing
            .as_mut()
            .map(|pt| &mut pt.sky)
        {
            let resolved = if map_path.is_relative() {
                path.parent().unwrap_or(Path::new(".")).join(&*map_path)
            } else {
                map_path.clone()
            };
            let field = "scene.effects.path_tracing.sky.path";
            let (fingerprint, _) =
                crate::environment::load_fingerprinted(&resolved).map_err(|e| {
                    let message = match e {
                        Error::Io { .. } => format!("cannot read {e}"),
                        e => format!("not a usable environment map: {e}"),
                    };
                    value(field, message)
                })?;
            *digest = fingerprint;
            *map_path = resolved;
        }
        if let Err((field, message)) = validate_scene(&file.scene) {
            return Err(value(&format!("scene.{field}"), message));
        }
        // Too many instants to check, or too many track values at them.
        let too_many = |(field, message): TooMany| value(field, message);
        check_scene_count(&file.scene, frame_count, 0).map_err(too_many)?;
        let all_keys: usize = file.tracks.values().map(|t| t.keys.len()).sum();
        let mut keys_so_far = 0;

        let mut tracks = Vec::new();
        for (name, spec) in &file.tracks {
            let at =
                |what: String, message: String| value(&format!("tracks[{name:?}]{what}"), message);
            let Some(&(_, arity)) = PARAMETERS.iter().find(|(p, _)| p == name) else {
                let known: Vec<&str> = PARAMETERS.iter().map(|(p, _)| *p).collect();
                return Err(at(
                    String::new(),
                    format!(
                        "no such parameter; tracks can animate: {}",
                        known.join(", ")
                    ),
                ));
            };
            if let Some(effect) = name
                .strip_prefix("effects.")
                .and_then(|r| r.split('.').next())
            {
                if !file.scene.effects.enabled().contains(&effect) {
                    return Err(at(
                        String::new(),
                        format!("animates the {effect} effect, which the scene does not enable: add `{effect}: ()` to scene.effects"),
                    ));
                }
            }
            if spec.keys.is_empty() {
                return Err(at(".keys".into(), "a track needs at least one key".into()));
            }
            keys_so_far += spec.keys.len();
            if keys_so_far > MAX_KEYS {
                return Err(at(
                    ".keys".into(),
                    format!(
                        "the tracks have {all_keys} keys in all, more than the {MAX_KEYS} a \
                         timeline may have"
                    ),
                ));
            }
            let log_space = name == ZOOM_TRACK;
            let mut times = Vec::with_capacity(spec.keys.len());
            let mut columns = vec![Vec::with_capacity(spec.keys.len()); arity];
            for (k, key) in spec.keys.iter().enumerate() {
                if !key.time.is_finite() {
                    return Err(at(
                        format!(".keys[{k}].time"),
                        format!(
                            "must be a finite number of seconds, got {}",
                            key.time.shown()
                        ),
                    ));
                }
                if let Some(&prev) = times.last() {
                    if key.time <= prev {
                        return Err(at(
                            format!(".keys[{k}].time"),
                            format!("key times must increase: {} follows {prev}", key.time),
                        ));
                    }
                }
                times.push(key.time);
                let values = key.value.components();
                let shape = |n: usize| {
                    if n == 1 {
                        "a number".to_string()
                    } else {
                        "a triple (x, y, z)".to_string()
                    }
                };
                if values.len() != arity {
                    return Err(at(
                        format!(".keys[{k}].value"),
                        format!("{name} takes {}, got {}", shape(arity), shape(values.len())),
                    ));
                }
                if let Some(bad) = values.iter().find(|v| !v.is_finite()) {
                    return Err(at(
                        format!(".keys[{k}].value"),
                        format!("values must be finite, got {}", bad.shown()),
                    ));
                }
                if log_space && values[0] <= 0.0 {
                    return Err(at(
                        format!(".keys[{k}].value"),
                        format!(
                            "a camera distance must be positive, got {}",
                            values[0].shown()
                        ),
                    ));
                }
                for (column, v) in columns.iter_mut().zip(values) {
                    column.push(if log_space { v.ln() } else { v });
                }
            }
            let interpolation = spec.interpolation.unwrap_or(Interpolation::CatmullRom);
            let ends = (
                columns.iter().map(|c| c[0]).collect(),
                columns.iter().map(|c| c[c.len() - 1]).collect(),
            );
            let period = file.looping.then_some(frame_count as Real / file.fps);
            // The keys the splines go through: in a looping film, those of
            // one period, in [0, period).
            let (loop_times, loop_columns) = match period {
                Some(period) => one_period(&times, columns, &spec.keys, period, file.fps)
                    .map_err(|(k, what, message)| at(format!(".keys[{k}].{what}"), message))?,
                None => (times.clone(), columns),
            };
            let splines = loop_columns
                .iter()
                .map(|c| build_spline(&loop_times, c, interpolation, period))
                .collect();
            tracks.push(Track {
                name: name.clone(),
                interpolation,
                splines,
                key_times: times,
                ends,
                log_space,
                period,
            });
        }
        // The zoom distance acts on the animated position and target, so it goes last.
        tracks.sort_by_key(|t| t.name == ZOOM_TRACK);
        let values = tracks.iter().map(|t| t.splines.len()).sum();
        check_scene_count(&file.scene, frame_count, values).map_err(too_many)?;

        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "timeline".into());
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
        };
        // Splines can overshoot their keys: check every scene the frames
        // render; the first frame that fails is told.
        if let Some(frame) = timeline.first_invalid_frame() {
            let failure = timeline.invalid_instant(frame);
            if let Some((time, (field, message))) = failure {
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
                    return Err(value(&key, message));
                }
                let animated: Vec<String> =
                    culprits.iter().map(|t| format!("{:?}", t.name)).collect();
                let track_place = |name: &String| spans::place_of(text, &format!("tracks[{name}]"));
                return Err(invalid(
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
                ));
            }
        }
        Ok(timeline)
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
        for track in &self.tracks {
            if check && track.name == ZOOM_TRACK {
                let c = &scene.camera;
                let away = c.position - c.target;
                if away.length() <= 8.0 * Real::EPSILON * c.target.abs().max_element().max(1.0) {
                    return Err((
                        "camera.target".into(),
                        "the camera position and target coincide, so camera.distance has no direction to place the camera along".into(),
                    ));
                }
            }
            let values = track.sample_components(time_seconds);
            apply(&mut scene, &track.name, &values[..track.splines.len()]);
        }
        Ok(scene)
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

/// The narrowest field of view. A ray's points are its origin plus a
/// distance along it, so they are placed no finer than 2⁻⁵² of the camera's
/// distance, while a pixel is as wide as its angle times that distance: a
/// pixel's angle must stay well above 2⁻⁵² (64 times, 1.4e-14 radians) for
/// marching to resolve it. 1e-7° over 32 768 rows is 5.3e-14 radians a
/// pixel. (A camera a billion units away frames the bulb at 1.03e-7°.)
pub const MIN_FOV_DEGREES: Real = 1e-7;

/// Checks one frame's scene; on failure returns the field path and the problem.
pub fn validate_scene(s: &Scene) -> Result<(), (String, String)> {
    // The message is built only when the check fails: every rendered
    // scene is checked, thousands per frame under motion blur.
    fn check(
        ok: bool,
        field: &str,
        message: impl FnOnce() -> String,
    ) -> Result<(), (String, String)> {
        if ok {
            Ok(())
        } else {
            Err((field.to_string(), message()))
        }
    }
    // The three checks most fields need, each with one wording.
    fn positive<T: Into<f64> + Copy + Shown>(v: T, field: &str) -> Result<(), (String, String)> {
        let x: f64 = v.into();
        check(x.is_finite() && x > 0.0, field, || {
            format!("must be positive, got {}", v.shown())
        })
    }
    fn non_negative<T: Into<f64> + Copy + Shown>(
        v: T,
        field: &str,
    ) -> Result<(), (String, String)> {
        let x: f64 = v.into();
        check(x.is_finite() && x >= 0.0, field, || {
            format!("must be non-negative, got {}", v.shown())
        })
    }
    fn colour(c: Vec3, field: &str) -> Result<(), (String, String)> {
        check(c.is_finite() && c.min_element() >= 0.0, field, || {
            format!("colours must be finite and non-negative, got {}", c.shown())
        })
    }
    let finite3 = |v: DVec3| v.is_finite();
    let c = &s.camera;
    for (field, v) in [("camera.position", c.position), ("camera.target", c.target)] {
        // The bulb is a unit across: from farther than this it is below a
        // pixel of any field of view, and the view's length would overflow.
        check(
            finite3(v) && v.abs().max_element() <= MAX_COORDINATE,
            field,
            || {
                format!(
                    "each component must be finite and within ±{MAX_COORDINATE:e}, got {}",
                    v.shown()
                )
            },
        )?;
    }
    check(finite3(c.up), "camera.up", || {
        format!("must be finite, got {}", c.up.shown())
    })?;
    check(c.roll_degrees.is_finite(), "camera.roll_degrees", || {
        format!("must be finite, got {}", c.roll_degrees.shown())
    })?;
    check(
        c.fov_degrees.is_finite() && c.fov_degrees >= MIN_FOV_DEGREES && c.fov_degrees < 179.0,
        "camera.fov_degrees",
        || {
            format!(
                "must be from {MIN_FOV_DEGREES:e} to below 179 degrees, got {}{}",
                c.fov_degrees.shown(),
                if c.fov_degrees > 0.0 && c.fov_degrees < MIN_FOV_DEGREES {
                    " (narrower, a pixel would span less than f64 can tell apart along a \
                     ray; move the camera closer instead)"
                } else {
                    ""
                }
            )
        },
    )?;
    check(
        c.aperture_radius.is_finite() && c.aperture_radius >= 0.0,
        "camera.aperture_radius",
        || {
            format!(
                "must be 0 (a pinhole) or positive, got {}",
                c.aperture_radius.shown()
            )
        },
    )?;
    if let Some(f) = c.focus_distance {
        positive(f, "camera.focus_distance")?;
    }
    let view = c.target - c.position;
    // Below a few ulps of the coordinates the view direction is noise.
    let scale = c
        .position
        .abs()
        .max_element()
        .max(c.target.abs().max_element())
        .max(1.0);
    check(
        view.length() > 8.0 * Real::EPSILON * scale,
        "camera.target",
        || {
            format!(
            "the camera position and target coincide (closer than {:.1e}, the limit of f64 at this scale)",
            8.0 * Real::EPSILON * scale
        )
        },
    )?;
    check(
        view.normalize().cross(c.up).length() > 1e-9,
        "camera.up",
        || {
            format!(
                "must not be zero or parallel to the view direction, got {}",
                c.up.shown()
            )
        },
    )?;
    let f = &s.fractal;
    check(
        f.power.is_finite() && f.power >= 1.0 && f.power <= 64.0,
        "fractal.power",
        || format!("must be between 1 and 64, got {}", f.power.shown()),
    )?;
    check(
        (1..=10_000).contains(&f.iterations),
        "fractal.iterations",
        || format!("must be 1..=10000, got {}", f.iterations),
    )?;
    check(
        f.bailout.is_finite() && f.bailout > 1.0,
        "fractal.bailout",
        || format!("must be a finite number above 1, got {}", f.bailout.shown()),
    )?;
    // An orbit at the bailout is raised to the power once more: keep that finite.
    check(f.power * f.bailout.ln() < 600.0, "fractal.bailout", || {
        format!(
            "bailout^power must stay below e^600 (f64 overflows near e^709), got {}^{}",
            f.bailout.shown(),
            f.power.shown()
        )
    })?;
    if let Some(k) = f.julia {
        // Past a bailout plus its power every point escapes at the first
        // step and the set is empty; far past it |z|² overflows (f32 near
        // 1e19, f64 near 1e154), which would read as a surface.
        check(
            finite3(k) && k.abs().max_element() <= MAX_JULIA,
            "fractal.julia",
            || {
                format!(
                    "each component must be finite and within ±{MAX_JULIA:e}, got {}",
                    k.shown()
                )
            },
        )?;
    }
    let q = &s.quality;
    for (field, v) in [
        ("quality.hit_threshold", q.hit_threshold),
        ("quality.normal_step", q.normal_step),
        ("quality.bounding_radius", q.bounding_radius),
    ] {
        positive(v, field)?;
    }
    // The set lies within the bailout, a few units across; a sphere far
    // larger leaves rays to run out of steps in empty space.
    check(
        q.bounding_radius <= MAX_BOUNDING_RADIUS,
        "quality.bounding_radius",
        || {
            format!(
                "must be at most {MAX_BOUNDING_RADIUS:e}, got {}",
                q.bounding_radius.shown()
            )
        },
    )?;
    check(
        q.membership_step == 0.0
            || (MIN_MEMBERSHIP_STEP..=MAX_MEMBERSHIP_STEP).contains(&q.membership_step),
        "quality.membership_step",
        || {
            format!(
                "must be 0 (trust the estimate) or from {MIN_MEMBERSHIP_STEP} to {MAX_MEMBERSHIP_STEP} footprints, got {}",
                q.membership_step.shown()
            )
        },
    )?;
    check(
        q.fudge.is_finite() && q.fudge > 0.0 && q.fudge <= 1.0,
        "quality.fudge",
        || format!("must be in (0, 1], got {}", q.fudge.shown()),
    )?;
    check(
        q.over_relaxation.is_finite() && (1.0..2.0).contains(&q.over_relaxation),
        "quality.over_relaxation",
        || format!("must be in [1, 2), got {}", q.over_relaxation.shown()),
    )?;
    check(
        (1..=1_000_000).contains(&q.max_steps),
        "quality.max_steps",
        || format!("must be 1..=1000000, got {}", q.max_steps),
    )?;
    check(
        (1..=4096).contains(&q.cone_rays),
        "quality.cone_rays",
        || format!("must be 1..=4096, got {}", q.cone_rays),
    )?;
    check(
        (1..=4096).contains(&s.samples_per_pixel),
        "samples_per_pixel",
        || format!("must be 1..=4096, got {}", s.samples_per_pixel),
    )?;
    let l = &s.look;
    check(
        finite3(l.light_direction) && l.light_direction.length() > 0.0,
        "look.light_direction",
        || {
            format!(
                "must be a finite non-zero vector, got {}",
                l.light_direction.shown()
            )
        },
    )?;
    for (field, v) in [
        ("look.light_colour", l.light_colour),
        ("look.ambient", l.ambient),
        ("look.base_colour", l.base_colour),
        ("look.trap_x_colour", l.trap_x_colour),
        ("look.trap_y_colour", l.trap_y_colour),
        ("look.trap_z_colour", l.trap_z_colour),
        ("look.background_top", l.background_top),
        ("look.background_bottom", l.background_bottom),
    ] {
        colour(v, field)?;
    }
    check(
        l.trap_occlusion.is_finite() && (0.0..=1.0).contains(&l.trap_occlusion),
        "look.trap_occlusion",
        || format!("must be in [0, 1], got {}", l.trap_occlusion.shown()),
    )?;
    non_negative(l.exposure, "look.exposure")?;
    check(
        l.extra_lights.len() < crate::shade::MAX_LIGHTS,
        "look.extra_lights",
        || {
            format!(
                "at most {} extra lights, got {}",
                crate::shade::MAX_LIGHTS - 1,
                l.extra_lights.len()
            )
        },
    )?;
    for (i, light) in l.extra_lights.iter().enumerate() {
        check(
            light.direction.is_finite() && light.direction.length() > 0.0,
            &format!("look.extra_lights[{i}].direction"),
            || {
                format!(
                    "must be a finite non-zero vector, got {}",
                    light.direction.shown()
                )
            },
        )?;
        colour(light.colour, &format!("look.extra_lights[{i}].colour"))?;
        non_negative(
            light.intensity,
            &format!("look.extra_lights[{i}].intensity"),
        )?;
    }
    let e = &s.effects;
    if let Some(sh) = &e.shadows {
        check(
            sh.softness.is_finite() && sh.softness >= 0.0,
            "effects.shadows.softness",
            || format!("must be 0 (hard) or positive, got {}", sh.softness.shown()),
        )?;
        check(
            (1..=100_000).contains(&sh.max_steps),
            "effects.shadows.max_steps",
            || format!("must be 1..=100000, got {}", sh.max_steps),
        )?;
    }
    if let Some(ao) = &e.ambient_occlusion {
        check(
            (1..=64).contains(&ao.samples),
            "effects.ambient_occlusion.samples",
            || format!("must be 1..=64, got {}", ao.samples),
        )?;
        positive(ao.radius, "effects.ambient_occlusion.radius")?;
        check(
            ao.strength.is_finite() && (0.0..=1.0).contains(&ao.strength),
            "effects.ambient_occlusion.strength",
            || format!("must be in [0, 1], got {}", ao.strength.shown()),
        )?;
    }
    if let Some(sp) = &e.specular {
        non_negative(sp.strength, "effects.specular.strength")?;
        positive(sp.shininess, "effects.specular.shininess")?;
    }
    if let Some(fog) = &e.fog {
        non_negative(fog.density, "effects.fog.density")?;
        colour(fog.colour, "effects.fog.colour")?;
    }
    if let Some(pt) = &e.path_tracing {
        check(
            e.shadows.is_none() && e.ambient_occlusion.is_none() && e.specular.is_none(),
            "effects.path_tracing",
            || {
                "path tracing computes shadows and occlusion itself: remove shadows, ambient_occlusion and specular".into()
            },
        )?;
        check(
            (1..=1024).contains(&pt.max_bounces),
            "effects.path_tracing.max_bounces",
            || format!("must be 1..=1024, got {}", pt.max_bounces),
        )?;
        check(
            pt.sun_angle_degrees.is_finite() && (0.0..=30.0).contains(&pt.sun_angle_degrees),
            "effects.path_tracing.sun_angle_degrees",
            || format!("must be 0..=30, got {}", pt.sun_angle_degrees.shown()),
        )?;
        non_negative(pt.sky_intensity, "effects.path_tracing.sky_intensity")?;
        match pt.sky {
            crate::shade::Sky::Constant(c) => colour(c, "effects.path_tracing.sky")?,
            crate::shade::Sky::Preetham { turbidity } => check(
                turbidity.is_finite() && (1.7..=12.0).contains(&turbidity),
                "effects.path_tracing.sky.turbidity",
                || {
                    format!(
                        "Preetham turbidity must be 1.7..=12, got {}",
                        turbidity.shown()
                    )
                },
            )?,
            crate::shade::Sky::Environment {
                rotation_degrees, ..
            } => check(
                rotation_degrees.is_finite(),
                "effects.path_tracing.sky.rotation_degrees",
                || {
                    format!(
                        "Environment rotation_degrees must be finite, got {}",
                        rotation_degrees.shown()
                    )
                },
            )?,
            crate::shade::Sky::Gradient => {}
        }
    }
    if let Some(m) = &e.motion_blur {
        check(
            m.shutter.is_finite() && m.shutter > 0.0 && m.shutter <= 1.0,
            "effects.motion_blur.shutter",
            || {
                format!(
                    "must be in (0, 1] of the frame interval, got {}",
                    m.shutter.shown()
                )
            },
        )?;
    }
    if let Some(g) = &e.glow {
        non_negative(g.strength, "effects.glow.strength")?;
        positive(g.width, "effects.glow.width")?;
        colour(g.colour, "effects.glow.colour")?;
    }
    Ok(())
}

/// The error for the value at `field`, a path into the file: at the
/// value's line and column, or, where the file leaves the field to its
/// default, at the block that would hold it, saying so.
fn invalid_value(text: &str, file: &Path, field: &str, message: String) -> Error {
    let steps = spans::steps(field);
    let (place, message) = match spans::nearest(text, field) {
        // A missing key or item is not a default: only a field has one.
        Some((found, place)) if matches!(steps.get(found), Some(spans::Step::Field(_))) => {
            let name = spans::path_of(&steps[found..]);
            let note = format!(" (`{name}` is not given here, so it takes its default)");
            (Some(place), message + &note)
        }
        found => (found.map(|(_, place)| place), message),
    };
    Error::Invalid {
        file: file.to_path_buf(),
        place,
        path: field.to_string(),
        message,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Timeline> {
        Timeline::parse(text, Path::new("test.ron"))
    }

    const MINIMAL: &str = "(fps: 10, frames: 11, size: (8, 6))";

    fn with_track(track: &str) -> String {
        format!("(fps: 10, frames: 11, size: (8, 6), tracks: {{ {track} }})")
    }

    #[test]
    fn minimal_timeline_uses_defaults() {
        let t = parse(MINIMAL).unwrap();
        assert_eq!(t.frame_count, 11);
        assert_eq!((t.width, t.height), (8, 6));
        assert_eq!(t.scene_at(5), Scene::default());
    }

    #[test]
    fn duration_gives_frame_count() {
        let t = parse("(fps: 24, duration_seconds: 2.5, size: (8, 6))").unwrap();
        assert_eq!(t.frame_count, 60);
    }

    #[test]
    fn frames_instants_and_keys_past_their_limits_are_refused_by_name() {
        // Just past each limit. Before, each was taken, and every frame's
        // scene checked: 4e9 frames would have taken hours.
        let e = error_of("(fps: 24, frames: 1000001, size: (8, 6))");
        assert_eq!(
            e,
            "test.ron:1:19: frames: at most 1000000, got 1000001: split a longer film into \
             timelines of its parts"
        );
        let e = error_of("(fps: 24,\n duration_seconds: 41667, size: (8, 6))");
        assert!(
            e.starts_with(
                "test.ron:2:20: duration_seconds: gives 1.000008e6 frames at 24 fps, \
                 more than the 1000000 a timeline may have"
            ),
            "{e}"
        );
        // Motion blur: every sample of every frame is an instant of its own.
        let blur = "(fps: 24, frames: 1000, size: (8, 6),\n scene: (samples_per_pixel: 4096, \
                    effects: (motion_blur: ())))";
        let e = error_of(blur);
        assert!(
            e.starts_with("test.ron:2:29: scene.samples_per_pixel: ")
                && e.contains(
                    "1000 frames × 4096 motion-blurred samples = 4096000 instants, \
                     more than the 2000000"
                ),
            "{e}"
        );
        // Twelve animated values at each of a million frames.
        let text = "(fps: 24, frames: 1000000, size: (8, 6),\n tracks: {
            \"camera.position\": (keys: [(time: 0, value: (0, 0, 3)), (time: 1, value: (0, 1, 3))]),
            \"camera.target\": (keys: [(time: 0, value: (0, 0, 0))]),
            \"look.ambient\": (keys: [(time: 0, value: (0.1, 0.1, 0.1))]),
            \"look.light_colour\": (keys: [(time: 0, value: (1, 1, 1))]),
        })";
        let e = error_of(text);
        assert!(
            e.starts_with("test.ron:2:10: tracks: every instant's scene is checked")
                && e.contains(
                    "12 animated values (the tracks' components) × 1000000 frames \
                     = 12000000 track samples, more than the 10000000"
                ),
            "{e}"
        );
        let keys: Vec<String> = (0..=MAX_KEYS)
            .map(|k| format!("(time: {k}, value: 8)"))
            .collect();
        let many = with_track(&format!("\"fractal.power\": (keys: [{}])", keys.join(", ")));
        let e = error_of(&many);
        assert!(
            e.contains(
                "tracks[\"fractal.power\"].keys: the tracks have 100001 keys in all, \
                 more than the 100000"
            ),
            "{e}"
        );
    }

    fn sample(track: &str, time: Real) -> Vec<Real> {
        let t = parse(&with_track(track)).unwrap();
        t.tracks[0].sample(time)
    }

    const KEYS: &str = "keys: [(time: 0, value: 1), (time: 0.5, value: 3), (time: 1, value: 2)]";

    #[test]
    fn every_mode_passes_through_its_keys() {
        for mode in ["Step", "Linear", "CatmullRom", "Smooth"] {
            let track = format!("\"fractal.power\": (interpolation: {mode}, {KEYS})");
            for (time, value) in [(0.0, 1.0), (0.5, 3.0), (1.0, 2.0)] {
                assert_eq!(sample(&track, time), vec![value], "{mode} at {time}");
            }
            // Held constant outside the keys.
            assert_eq!(sample(&track, -1.0), vec![1.0]);
            assert_eq!(sample(&track, 9.0), vec![2.0]);
        }
    }

    #[test]
    fn modes_between_keys() {
        let at = |mode: &str, time: Real| {
            sample(
                &format!("\"fractal.power\": (interpolation: {mode}, {KEYS})"),
                time,
            )[0]
        };
        assert_eq!(at("Step", 0.25), 1.0);
        assert_eq!(at("Step", 0.75), 3.0);
        assert!((at("Linear", 0.25) - 2.0).abs() < 1e-12);
        assert!((at("Linear", 0.75) - 2.5).abs() < 1e-12);
        // Smooth: the cosine ease is at the midpoint halfway, and slow near keys.
        assert!((at("Smooth", 0.25) - 2.0).abs() < 1e-12);
        assert!(at("Smooth", 0.05) - 1.0 < 0.3 * (at("Linear", 0.05) - 1.0));
        // Catmull–Rom overshoots the peak at 3 between 0.5 and 1 before settling to 2.
        let c = at("CatmullRom", 0.55);
        assert!(c > 3.0 && c < 3.5, "{c}");
        // With two keys, Catmull–Rom over mirrored end keys is a straight line.
        let two = "\"fractal.power\": (keys: [(time: 0, value: 2), (time: 2, value: 6)])";
        assert!((sample(two, 0.5)[0] - 3.0).abs() < 1e-12);
    }

    #[test]
    fn triples_interpolate_per_component() {
        let track = "\"camera.position\": (interpolation: Linear, keys: [(time: 0, value: (0, 0, 4)), (time: 1, value: (2, -2, 2))])";
        assert_eq!(sample(track, 0.5), vec![1.0, -1.0, 3.0]);
    }

    #[test]
    fn zoom_distance_interpolates_in_log_space() {
        let track = "\"camera.distance\": (interpolation: Linear, keys: [(time: 0, value: 1), (time: 1, value: 0.0001)])";
        // Linear in log space: every tenth of the time divides distance by the same factor.
        for i in 0..=10 {
            let t = i as Real / 10.0;
            let expect = 10f64.powf(-4.0 * t);
            let got = sample(track, t)[0];
            assert!(
                (got / expect - 1.0).abs() < 1e-9,
                "t={t}: {got} vs {expect}"
            );
        }
        // And it moves the camera towards the target along the current view line.
        let t = parse(&with_track(track)).unwrap();
        let s = t.scene_at(5);
        let d = (s.camera.position - s.camera.target).length();
        assert!((d - 1e-2).abs() < 1e-12);
        let dir = (s.camera.position - s.camera.target).normalize();
        let base = (t.base.camera.position - t.base.camera.target).normalize();
        assert!((dir - base).length() < 1e-12);
    }

    #[test]
    fn julia_track_switches_to_julia_mode() {
        let t = parse(&with_track(
            "\"fractal.julia\": (keys: [(time: 0, value: (0.1, 0.2, 0.3)), (time: 1, value: (0.3, 0.2, 0.1))])",
        ))
        .unwrap();
        assert_eq!(t.scene_at(0).fractal.julia, Some(DVec3::new(0.1, 0.2, 0.3)));
        assert_eq!(
            t.scene_at(10).fractal.julia,
            Some(DVec3::new(0.3, 0.2, 0.1))
        );
    }

    fn error_of(text: &str) -> String {
        parse(text)
            .expect_err("timeline should be rejected")
            .to_string()
    }

    #[test]
    fn syntax_error_names_line_and_column() {
        let e = error_of("(\n  fps: 24,\n  frames: 3,\n  size: (8; 6),\n)");
        assert!(e.starts_with("test.ron:4:11:"), "{e}");
    }

    #[test]
    fn syntax_errors_point_where_the_mistake_is_and_say_it_plainly() {
        // A missing comma: at the end of the line that lacks it, not at the next field.
        let e = error_of("(\n  fps: 24,\n  frames: 3 // three\n\n  size: (8, 6),\n)");
        assert_eq!(e, "test.ron:3:12: expected a comma after this value");
        // Not fooled by `//` in a string, nor by block comments.
        let e = error_of(
            "(\n  fps: 24, frames: 3, scene: (fractal: (formula: Quilez)), size: (8, 6) // \"x\"\n  /* one */ /* and\n two */\n  tracks: {}, // y\n)",
        );
        assert_eq!(e, "test.ron:2:72: expected a comma after this value");
        let e = error_of(
            "(fps: 24, frames: 3, size: (8, 6), scene: (effects: (path_tracing: (sky: Environment(path: \"//x/\\\"sky.exr\"))))\n  tracks: {},\n)",
        );
        assert!(e.starts_with("test.ron:1:111: expected a comma"), "{e}");
        // A track name with characters of several bytes.
        let e = error_of("(fps: 24, frames: 3, size: (8, 6), tracks: { \"é→power\": 1.5 })");
        assert!(e.contains("for a track"), "{e}");
        // Text after the timeline: where it starts.
        let e = error_of("(fps: 24, frames: 3, size: (8, 6))\n// done\n  (fps: 12)");
        assert!(
            e.starts_with("test.ron:3:3: text after the timeline"),
            "{e}"
        );
        let e = error_of("(fps: 24, frames: 3, size: (8, 6)) /* done */ x");
        assert!(
            e.starts_with("test.ron:1:47: text after the timeline"),
            "{e}"
        );
        // A whole number written with a point, a negative and a huge count: the field named.
        let e = error_of("(fps: 24, frames: 3.0, size: (8, 6))");
        assert!(
            e.ends_with(
                "`frames`: expected a whole number, written without a decimal point: 3, not 3.0"
            ),
            "{e}"
        );
        let e = error_of("(fps: 24, frames: 3, size: (8, -6))");
        assert!(e.contains("`size[1]`: must be 0 or more"), "{e}");
        let e = error_of("(fps: 24, frames: 99999999999, size: (8, 6))");
        assert!(
            e.ends_with("`frames`: too large: at most 4294967295"),
            "{e}"
        );
        let e = error_of("(fps: 24, frames: 3, size: (8, 6), scene: (fractal: (power: \"8\")))");
        assert!(e.contains("`scene.fractal.power`: Expected float"), "{e}");
        // Keys written as tuples, and our own type names.
        let e = error_of(&with_track("\"fractal.power\": (keys: [(0, 8)])"));
        assert!(
            e.contains("expected a field name here (`name: value`), got `0`"),
            "{e}"
        );
        let e = error_of(&with_track(
            "\"fractal.power\": (keys: [(tme: 0, value: 8)])",
        ));
        assert!(e.contains("in a key,"), "{e}");
        let e = error_of("(fps: 24, frames: 3, size: (8, 6), scene: (camera: (up: [0, 1, 0])))");
        assert!(
            e.contains("a triple (x, y, z)") && !e.contains("DVec3"),
            "{e}"
        );
        assert!(error_of("").contains("for the timeline"));
    }

    #[test]
    fn a_key_of_the_wrong_shape_says_what_shapes_there_are() {
        for (value, says) in [
            (
                "(0.5, 0.5)",
                "expected a number or a triple (x, y, z), got 2 numbers",
            ),
            (
                "(1, 2, 3, 4)",
                "expected a number or a triple (x, y, z), got 4 numbers",
            ),
            (
                "\"8\"",
                "Expected a number or a triple (x, y, z) but found the string \"8\"",
            ),
        ] {
            let e = error_of(&with_track(&format!(
                "\"fractal.julia\": (keys: [(time: 0, value: {value})])"
            )));
            assert!(e.contains(says), "{value}: {e}");
        }
        // A julia constant as a scene writes it, and a list, are triples too.
        for value in ["Some((0.1, 0.2, 0.3))", "[0.1, 0.2, 0.3]"] {
            let t = parse(&with_track(&format!(
                "\"fractal.julia\": (keys: [(time: 0, value: {value})])"
            )))
            .unwrap();
            assert_eq!(t.scene_at(0).fractal.julia, Some(DVec3::new(0.1, 0.2, 0.3)));
        }
    }

    #[test]
    fn unknown_field_is_rejected_with_its_name() {
        let e = error_of("(fps: 24, frames: 3, size: (8, 6), scene: (camra: ()))");
        assert!(e.contains("camra") && e.starts_with("test.ron:1:"), "{e}");
        // Inside an enum's variant too.
        let e = error_of(
            "(fps: 24, frames: 3, size: (8, 6), scene: (effects: (path_tracing: (sky: Preetham(turbidty: 3)))))",
        );
        assert!(e.contains("turbidty"), "{e}");
    }

    #[test]
    fn wrong_type_is_rejected() {
        let e = error_of("(fps: \"fast\", frames: 3, size: (8, 6))");
        assert!(e.starts_with("test.ron:1:"), "{e}");
    }

    #[test]
    fn nan_and_inf_are_rejected() {
        let e = error_of("(fps: 24, frames: 3, size: (8, 6), scene: (fractal: (power: NaN)))");
        assert!(e.contains("scene.fractal.power"), "{e}");
        let e = error_of(&with_track(
            "\"fractal.power\": (keys: [(time: 0, value: inf)])",
        ));
        assert!(
            e.contains("tracks[\"fractal.power\"].keys[0].value") && e.contains("finite"),
            "{e}"
        );
        let e = error_of("(fps: inf, frames: 3, size: (8, 6))");
        assert!(e.contains("fps"), "{e}");
    }

    #[test]
    fn out_of_range_values_name_their_field_and_the_rule() {
        for (scene, field, rule) in [
            (
                "quality: (hit_threshold: 0)",
                "quality.hit_threshold",
                "must be positive",
            ),
            (
                "quality: (membership_step: -0.5)",
                "quality.membership_step",
                "must be 0 (trust the estimate) or from 0.01 to 16 footprints",
            ),
            (
                "quality: (membership_step: 1e-300)",
                "quality.membership_step",
                "must be 0 (trust the estimate) or from 0.01 to 16 footprints",
            ),
            (
                "quality: (membership_step: 17)",
                "quality.membership_step",
                "must be 0 (trust the estimate) or from 0.01 to 16 footprints",
            ),
            (
                "camera: (focus_distance: Some(-2))",
                "camera.focus_distance",
                "must be positive",
            ),
            (
                "effects: (fog: (density: -1))",
                "effects.fog.density",
                "must be non-negative",
            ),
            (
                "effects: (specular: (shininess: 0))",
                "effects.specular.shininess",
                "must be positive",
            ),
            (
                "effects: (glow: (width: inf))",
                "effects.glow.width",
                "must be positive",
            ),
            (
                "effects: (glow: (colour: (1, -0.5, 0)))",
                "effects.glow.colour",
                "colours must be finite and non-negative",
            ),
            (
                "look: (ambient: (0, NaN, 0))",
                "look.ambient",
                "colours must be finite",
            ),
        ] {
            let e = error_of(&format!(
                "(fps: 24, frames: 3, size: (8, 6), scene: ({scene}))"
            ));
            assert!(
                e.contains(&format!("scene.{field}")) && e.contains(rule),
                "{scene}: {e}"
            );
        }
    }

    #[test]
    fn non_increasing_key_times_name_the_key_and_line() {
        let text = "(fps: 10, frames: 3, size: (8, 6), tracks: {\n  \"fractal.power\": (keys: [\n    (time: 0, value: 8),\n    (time: 1, value: 7),\n    (time: 1, value: 6),\n  ]),\n})";
        let e = error_of(text);
        assert!(
            e.starts_with("test.ron:5:12: tracks[\"fractal.power\"].keys[2].time"),
            "{e}"
        );
    }

    /// A looping film of 24 frames at 4 fps (a 6 s period) and `tracks`.
    fn looping(tracks: &str) -> String {
        format!("(fps: 4, frames: 24, size: (8, 6), loop: true, tracks: {{ {tracks} }})")
    }

    /// julia_morph.ron's camera orbit: four keys around the y axis and back
    /// to the first at 6 s.
    const ORBIT: &str = "\"camera.position\": (keys: [
        (time: 0.0, value: (3.1, 0.8, 0.0)),
        (time: 1.5, value: (0.0, 0.8, 3.1)),
        (time: 3.0, value: (-3.1, 0.8, 0.0)),
        (time: 4.5, value: (0.0, 0.8, -3.1)),
        (time: 6.0, value: (3.1, 0.8, 0.0)),
    ])";

    #[test]
    fn a_looping_film_comes_back_to_its_start_without_a_kink() {
        let velocity = |track: &Track, from: Real, to: Real| -> DVec3 {
            let at = |t| DVec3::from_slice(&track.sample(t));
            (at(to) - at(from)) / (to - from)
        };
        let h = 1e-5;
        for mode in ["Step", "Linear", "CatmullRom", "Smooth"] {
            let text = looping(&ORBIT.replace("(keys", &format!("(interpolation: {mode}, keys")));
            let t = parse(&text).unwrap();
            let orbit = &t.tracks[0];
            // One period on, the same value: frame 24 would be frame 0.
            for time in [0.0, 0.3, 1.5, 2.2, 5.9] {
                let (now, later) = (orbit.sample(time), orbit.sample(time + 6.0));
                let close = now.iter().zip(&later).all(|(a, b)| (a - b).abs() < 1e-12);
                assert!(close, "{mode} at {time}: {now:?} then {later:?}");
            }
            assert_eq!(orbit.sample(0.0), vec![3.1, 0.8, 0.0], "{mode}");
            assert_eq!(orbit.sample(-1.5), vec![0.0, 0.8, -3.1], "{mode}");
            // Between the last key and the period's end the track leads into
            // the first key as between any two keys: no value is held.
            if mode != "Step" {
                let p = orbit.sample(5.25);
                assert!(p[0] > 0.5 && p[0] < 3.1 && p[2] < -0.5, "{mode}: {p:?}");
            }
        }
        // Catmull-Rom's velocity runs on through the wrap; without the loop
        // the mirrored end keys turn it by a right angle there.
        let smooth = parse(&looping(ORBIT)).unwrap();
        let plain = parse(&looping(ORBIT).replace("loop: true", "loop: false")).unwrap();
        let (orbit, open) = (&smooth.tracks[0], &plain.tracks[0]);
        let leaving = velocity(orbit, 0.0, h);
        let arriving = velocity(orbit, 6.0 - h, 6.0);
        assert!(
            (leaving - arriving).length() < 1e-3,
            "{leaving} vs {arriving}"
        );
        let (leaving, arriving) = (velocity(open, 0.0, h), velocity(open, 6.0 - h, 6.0));
        assert!(
            (leaving - arriving).length() > 2.0,
            "{leaving} vs {arriving}"
        );
        assert!(smooth.looping && !plain.looping);
    }

    #[test]
    fn a_looping_films_keys_lie_within_its_period() {
        // The end key may be left out: the start key closes the loop.
        let open = ORBIT.replace("\n        (time: 6.0, value: (3.1, 0.8, 0.0)),", "");
        assert_ne!(open, ORBIT);
        let (a, b) = (
            parse(&looping(ORBIT)).unwrap(),
            parse(&looping(&open)).unwrap(),
        );
        for time in [0.0, 0.7, 4.9, 5.6] {
            assert_eq!(a.tracks[0].sample(time), b.tracks[0].sample(time), "{time}");
        }
        // A key at the end alone is the start's.
        let end_only = "\"fractal.power\": (interpolation: Linear, keys: [(time: 3, value: 4), (time: 6, value: 8)])";
        let t = parse(&looping(end_only)).unwrap();
        assert_eq!(t.tracks[0].sample(0.0), vec![8.0]);
        assert_eq!(t.tracks[0].sample(1.5), vec![6.0]);
        assert_eq!(t.tracks[0].sample(4.5), vec![6.0]);
        // A key past the end, or before the start, names its line.
        let past = looping(&ORBIT.replace("time: 6.0", "time: 6.5"));
        let e = error_of(&past);
        assert!(
            e.starts_with("test.ron:6:16: tracks[\"camera.position\"].keys[4].time: a looping film's keys lie within its one period, 0 s to 6 s (frames / fps), got 6.5; the loop repeats them every 6 s"),
            "{e}"
        );
        let before = looping(&ORBIT.replace("time: 0.0", "time: -0.5"));
        assert!(
            error_of(&before).contains("keys[0].time: a looping film"),
            "{}",
            error_of(&before)
        );
        // The end key is the start key again: another value is refused.
        let torn = looping(&ORBIT.replace(
            "(time: 6.0, value: (3.1, 0.8, 0.0))",
            "(time: 6.0, value: (3.0, 0.8, 0.0))",
        ));
        let e = error_of(&torn);
        assert!(
            e.starts_with("test.ron:6:28: tracks[\"camera.position\"].keys[4].value: in a looping film the key at its end (6 s) is the key at 0 s again, so it must have the same value: (3, 0.8, 0) here, (3.1, 0.8, 0) at 0 s (or leave one of them out)"),
            "{e}"
        );
        // Without the loop, the same keys are fine.
        let unlooped = |text: String| text.replace("loop: true", "loop: false");
        assert!(parse(&unlooped(past)).is_ok() && parse(&unlooped(torn)).is_ok());
        // 4 s at 29.97 fps is 120 frames, a period of 4.004 s: a key written
        // at 4 s is within half a frame of its end, so it is the start key
        // again, not a key of its own 4 ms before it.
        let ntsc = format!(
            "(fps: 29.97, duration_seconds: 4.0, size: (8, 6), loop: true, tracks: {{ {} }})",
            "\"fractal.power\": (interpolation: Linear, keys: [(time: 0, value: 8), (time: 2, value: 4), (time: 4, value: 8)])"
        );
        let t = parse(&ntsc).unwrap();
        let period = 120.0 / 29.97;
        let power = |time: Real| t.tracks[0].sample(time)[0];
        assert!(
            (power(period - 0.002) - 8.0).abs() < 0.01,
            "{}",
            power(period - 0.002)
        );
        assert!((power(3.0) - 6.0).abs() < 0.01, "{}", power(3.0));
        let torn = ntsc.replace("(time: 4, value: 8)", "(time: 4, value: 7)");
        assert!(error_of(&torn).contains("the key at its end (4 s) is the key at 0 s again"));
        // So is a first key within half a frame of 0 the start key.
        let late_start = ntsc.replace("(time: 0, value: 8)", "(time: 0.001, value: 8)");
        assert!(parse(&late_start).is_ok());
        let torn = late_start.replace("(time: 4, value: 8)", "(time: 4, value: 7)");
        assert!(error_of(&torn).contains("the key at its end (4 s) is the key at 0 s again"));
    }

    #[test]
    fn a_word_in_a_comment_does_not_move_a_keys_line() {
        let text = "(fps: 10, frames: 3, size: (8, 6), tracks: {\n  \"fractal.power\": (keys: [\n    (time: 0, value: 8),\n    // at this time the bulb swells\n    (time: 1, value: 7),\n    (time: 1, value: 6),\n  ]),\n})";
        let e = error_of(text);
        assert!(
            e.starts_with("test.ron:6:12: tracks[\"fractal.power\"].keys[2].time"),
            "{e}"
        );
    }

    #[test]
    fn non_positive_fps_size_fov_are_rejected() {
        assert!(error_of("(fps: 0, frames: 3, size: (8, 6))").contains("fps"));
        assert!(error_of("(fps: -24, frames: 3, size: (8, 6))").contains("fps"));
        assert!(error_of("(fps: 24, frames: 3, size: (0, 6))").contains("size"));
        assert!(error_of("(fps: 24, frames: 0, size: (8, 6))").contains("frames"));
        let e = error_of("(fps: 24, frames: 3, size: (8, 6), scene: (camera: (fov_degrees: 0)))");
        assert!(e.contains("scene.camera.fov_degrees"), "{e}");
        let e = error_of("(fps: 24, frames: 3, size: (8, 6), scene: (quality: (cone_rays: 0)))");
        assert!(
            e.contains("quality.cone_rays") && e.contains("1..=4096"),
            "{e}"
        );
        let e = error_of(&with_track(
            "\"camera.fov_degrees\": (keys: [(time: 0, value: 40), (time: 0.5, value: -3)])",
        ));
        assert!(
            e.contains(
                "tracks[\"camera.fov_degrees\"].keys[1].value: must be from 1e-7 to below 179"
            ),
            "{e}"
        );
    }

    #[test]
    fn empty_and_unknown_tracks_are_rejected() {
        let e = error_of(&with_track("\"fractal.power\": (keys: [])"));
        assert!(
            e.contains("tracks[\"fractal.power\"].keys") && e.contains("at least one"),
            "{e}"
        );
        let e = error_of(&with_track(
            "\"fractal.pwer\": (keys: [(time: 0, value: 1)])",
        ));
        assert!(
            e.contains("fractal.pwer") && e.contains("fractal.power"),
            "{e}"
        );
    }

    #[test]
    fn wrong_arity_and_bad_zoom_distance_are_rejected() {
        let e = error_of(&with_track(
            "\"camera.position\": (keys: [(time: 0, value: 2)])",
        ));
        assert!(e.contains("triple"), "{e}");
        let e = error_of(&with_track(
            "\"camera.distance\": (keys: [(time: 0, value: 0)])",
        ));
        assert!(e.contains("positive"), "{e}");
    }

    #[test]
    fn only_a_key_of_the_failing_parameter_is_blamed() {
        // The fov curve overshoots past 179 between its keys at t = 0.6,
        // where the zoom has a key: no key is wrong, so the frame and the
        // fov track are named.
        let e = error_of(&with_track(
            "\"camera.fov_degrees\": (keys: [(time: 0, value: 40), (time: 0.5, value: 175), (time: 0.7, value: 178), (time: 1, value: 60)]),\n\"camera.distance\": (keys: [(time: 0, value: 4), (time: 0.6, value: 3)])",
        ));
        let frame = "test.ron:1:69: frame 6 (t = 0.6000 s): scene.camera.fov_degrees: must be from 1e-7 to below 179 degrees, got 187.1";
        assert!(e.starts_with(frame), "{e}");
        assert!(e.ends_with("(set by track \"camera.fov_degrees\")"), "{e}");
    }

    #[test]
    fn a_key_out_of_range_is_named_on_its_own_line() {
        // Reached only by interpolation at frame 21; the key itself is the mistake.
        let text = "(fps: 24, frames: 24, size: (8, 6), tracks: {\n  \"fractal.power\": (interpolation: Linear, keys: [\n    (time: 0, value: 8),\n    (time: 0.5, value: 4),\n    (time: 1, value: 90),\n  ]),\n})";
        assert_eq!(
            error_of(text),
            "test.ron:5:22: tracks[\"fractal.power\"].keys[2].value: must be between 1 and 64, got 90"
        );
    }

    #[test]
    fn overshoot_caught_per_frame() {
        // Catmull–Rom overshoots below 1 between these keys; the bailout must stay above 1.
        let e = error_of(&with_track(
            "\"fractal.bailout\": (keys: [(time: 0, value: 4), (time: 0.5, value: 1.01), (time: 0.6, value: 50)])",
        ));
        assert!(
            e.contains("fractal.bailout") && e.contains("set by track"),
            "{e}"
        );
    }

    #[test]
    fn every_parameter_name_applies() {
        let all_effects = Scene {
            effects: crate::shade::Effects {
                shadows: Some(Default::default()),
                ambient_occlusion: Some(Default::default()),
                specular: Some(Default::default()),
                fog: Some(Default::default()),
                glow: Some(Default::default()),
                motion_blur: None,
                path_tracing: None,
            },
            ..Scene::default()
        };
        for &(name, arity) in PARAMETERS {
            let mut scene = all_effects.clone();
            let before = scene.clone();
            let v = vec![0.25; arity];
            apply(&mut scene, name, &v);
            assert_ne!(scene, before, "{name} changed nothing");
        }
    }

    #[test]
    fn effect_tracks_need_the_effect_enabled() {
        let e = error_of(&with_track(
            "\"effects.fog.density\": (keys: [(time: 0, value: 0.5)])",
        ));
        assert!(e.contains("fog") && e.contains("does not enable"), "{e}");
        let t = parse(
            "(fps: 10, frames: 11, size: (8, 6), scene: (effects: (fog: (density: 0.1))), tracks: { \"effects.fog.density\": (interpolation: Linear, keys: [(time: 0, value: 0.1), (time: 1, value: 0.9)]) })",
        )
        .unwrap();
        assert_eq!(t.scene_at(5).effects.fog.unwrap().density, 0.5);
        let e = error_of("(fps: 10, frames: 1, size: (8, 6), scene: (effects: (ambient_occlusion: (samples: 0))))");
        assert!(e.contains("effects.ambient_occlusion.samples"), "{e}");
    }

    #[test]
    fn motion_blur_spreads_samples_over_the_shutter() {
        let text = "(fps: 10, frames: 3, size: (8, 6), scene: (samples_per_pixel: 4, effects: (motion_blur: (shutter: 0.5))), tracks: { \"fractal.power\": (interpolation: Linear, keys: [(time: 0, value: 8), (time: 1, value: 9)]) })";
        let t = parse(text).unwrap();
        let scenes = t.scenes_for_frame(1);
        assert_eq!(scenes.len(), 4);
        // Frame 1 is at 0.1 s; the shutter is open 0.05 s; samples at 1/8, 3/8, 5/8, 7/8 of it.
        for (s, scene) in scenes.iter().enumerate() {
            let time = 0.1 + 0.05 * (s as f64 + 0.5) / 4.0;
            assert!(
                (scene.fractal.power - (8.0 + time)).abs() < 1e-12,
                "sample {s}"
            );
        }
        // Without motion blur a frame is one scene.
        let still = parse(&text.replace("effects: (motion_blur: (shutter: 0.5))", "")).unwrap();
        assert_eq!(still.scenes_for_frame(1), vec![still.scene_at(1)]);
        assert!(error_of(&text.replace("shutter: 0.5", "shutter: 1.5")).contains("shutter"));
    }

    #[test]
    fn extra_lights_are_checked() {
        let ok = parse("(fps: 10, frames: 1, size: (8, 6), scene: (look: (extra_lights: [(direction: (0, 1, 0), colour: (1, 1, 1), intensity: 0.5)])))").unwrap();
        assert_eq!(ok.base.look.extra_lights.len(), 1);
        let e = error_of("(fps: 10, frames: 1, size: (8, 6), scene: (look: (extra_lights: [(), (direction: (0, 0, 0))])))");
        assert!(e.contains("look.extra_lights[1].direction"), "{e}");
    }

    #[test]
    fn single_key_holds_its_value_everywhere() {
        let track = "\"fractal.power\": (keys: [(time: 0.4, value: 5)])";
        for time in [-1.0, 0.0, 0.4, 0.5, 100.0] {
            assert_eq!(sample(track, time), vec![5.0]);
        }
    }

    #[test]
    fn log_zoom_reaches_1e_minus_12_without_nan() {
        // Naive: interpolating the distance linearly undershoots zero for
        // Catmull–Rom between 1 and 1e-12; in log space it cannot.
        let text = "(fps: 10, frames: 41, size: (8, 6), tracks: { \"camera.distance\": (keys: [(time: 0, value: 1), (time: 2, value: 1e-6), (time: 4, value: 1e-12)]) })";
        let t = parse(text).unwrap();
        let mut previous = Real::INFINITY;
        for frame in 0..41 {
            let s = t.scene_at(frame);
            let d = (s.camera.position - s.camera.target).length();
            assert!(
                d.is_finite() && d > 0.0 && d <= previous * (1.0 + 1e-12),
                "frame {frame}: {d}"
            );
            previous = d;
        }
        assert!((previous / 1e-12 - 1.0).abs() < 1e-3, "{previous}");
    }

    #[test]
    fn iterations_interpolating_below_one_are_rejected() {
        // Catmull–Rom from 1 through 1 to 30 dips below 0.5 between the first
        // keys: the frame where iterations would round to 0 is named.
        let e = error_of(&with_track(
            "\"fractal.iterations\": (keys: [(time: 0, value: 1), (time: 0.5, value: 1), (time: 0.6, value: 30)])",
        ));
        assert!(
            e.contains("fractal.iterations") && e.contains("frame"),
            "{e}"
        );
    }

    #[test]
    fn the_readme_lists_every_parameter_a_track_can_animate() {
        // The README's table of track parameters, as far as the blank line
        // after its header.
        let readme = include_str!("../docs/timeline.md");
        let start = readme.find("| parameter | value |").expect("the table");
        let table = &readme[start..][..readme[start..].find("\n\n").expect("its end")];
        for (name, _) in PARAMETERS {
            assert!(
                table.contains(&format!("`{name}`")),
                "{name} is not in the README's table"
            );
        }
    }

    #[test]
    fn a_camera_track_onto_the_target_is_refused_at_its_line() {
        // The position track sets the camera onto the target at frame 0:
        // alone, the scene's own check catches it; with a zoom track, which
        // would otherwise pick a direction of its own, the zoom's does. Both
        // name the frame, the track and its line.
        let position = "\"camera.position\": (keys: [(time: 0, value: (0, 0, 0)), (time: 1, value: (0, 0, 2))])";
        let zoom = "\"camera.distance\": (keys: [(time: 0, value: 3), (time: 1, value: 2)])";
        for tracks in [position.to_string(), format!("\n{zoom},\n{position}")] {
            let text = with_track(&tracks).replace("size: (8, 6),", "size: (8, 6),\n");
            let at = spans::place_of(&text, "tracks[\"camera.position\"]").unwrap();
            let e = parse(&text).unwrap_err().to_string();
            let want = format!("test.ron:{}:{}: frame 0 ", at.line, at.column);
            assert!(e.starts_with(&want), "{e}");
            assert!(
                e.contains("coincide") && e.contains("\"camera.position\""),
                "{e}"
            );
        }
        // A light's error inside a list is found at the list's line.
        let text = "(fps: 10, frames: 2, size: (8, 6),\n scene: (look: (\n extra_lights: [(direction: (1, 1, 1), colour: (1, 1, 1), intensity: -1)])))";
        let e = parse(text).unwrap_err().to_string();
        assert!(
            e.starts_with(
                "test.ron:3:70: scene.look.extra_lights[0].intensity: must be non-negative"
            ),
            "{e}"
        );
    }

    #[test]
    fn messages_name_fractions_and_show_extreme_numbers_readably() {
        // A fraction where a count is wanted: RON alone says "Expected comma".
        let e = parse("(fps: 10, frames: 2,\n size: (320.5, 180))")
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "test.ron:2:12: `size[0]`: expected a whole number here, got 320.5"
        );
        let e = parse("(fps: 10, frames: 2.5, size: (8, 6))")
            .unwrap_err()
            .to_string();
        assert!(e.ends_with("expected a whole number here, got 2.5"), "{e}");
        // Other syntax errors keep RON's words.
        let e = parse("(fps: 10, frames: 2 size: (8, 6))")
            .unwrap_err()
            .to_string();
        assert!(e.contains("Expected comma"), "{e}");
        // 1e308 in e-notation, not 309 digits; an f32 field's overflow named.
        let fov = "(fps: 10, frames: 2, size: (8, 6), scene: (camera: (fov_degrees: 1e308)))";
        let e = parse(fov).unwrap_err().to_string();
        assert!(e.ends_with("got 1e308"), "{e}");
        let colour = "(fps: 10, frames: 2, size: (8, 6), scene: (look: (ambient: (1e300, 0, 0))))";
        let e = parse(colour).unwrap_err().to_string();
        assert!(
            e.contains("got (inf (or a number too large to hold), 0, 0)"),
            "{e}"
        );
        // A duration of too many frames says so (it said "at least one frame").
        let long = parse("(fps: 24, duration_seconds: 1e300, size: (8, 6))");
        let e = long.unwrap_err().to_string();
        assert!(
            e.contains("gives 2.4e301 frames at 24 fps, more than"),
            "{e}"
        );
    }

    #[test]
    fn a_camera_too_far_to_see_anything_is_refused_by_name() {
        // 1e300 away the view's length overflows: before, the error blamed
        // the up vector. Directly, and through a zoom track.
        let far =
            "(fps: 10, frames: 2, size: (8, 6), scene: (camera: (position: (0, 0.6, 1e300))))";
        let e = parse(far).unwrap_err().to_string();
        assert!(
            e.contains("scene.camera.position") && e.contains("1e15, got (0, 0.6, 1e300)"),
            "{e}"
        );
        let zoom = with_track(
            "\"camera.distance\": (keys: [(time: 0, value: 3), (time: 1, value: 1e300)])",
        );
        let e = parse(&zoom).unwrap_err().to_string();
        assert!(
            e.contains("scene.camera.position") && e.contains("camera.distance"),
            "{e}"
        );
    }
}
