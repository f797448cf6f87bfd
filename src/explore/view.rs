//! What the page asks to see: a frame of the timeline, with the values it
//! has changed but not yet keyed laid over the tracks', at a size and
//! samples as `render --size --samples` take them; checked as the command
//! line checks them.

use crate::exact::{Component, Coordinates};
use crate::job::request::MAX_SAMPLES;
use crate::scene::Scene;
use crate::timeline::Timeline;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The most pixels a view may have: a 4K frame. A larger one is a render's
/// job, whose memory is checked before it starts.
pub const MAX_VIEW_PIXELS: u64 = 3840 * 2160;

/// The parameter `iterations: Auto` sets: read-only while the scene says so.
const AUTO_FIELD: &str = "fractal.iterations";

#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct View {
    pub frame: u32,
    /// Parameter values that replace the tracks' at this frame.
    #[serde(default)]
    pub overrides: BTreeMap<String, Override>,
    /// `WIDTHxHEIGHT`, as `--size`; the timeline's size where absent.
    #[serde(default)]
    pub size: Option<String>,
    /// As `--samples`; the timeline's where absent.
    #[serde(default)]
    pub samples: Option<u32>,
}

/// What a parameter that takes no digits says of a string of them.
pub const NOT_DIGITS: &str =
    "takes numbers; strings of digits are for the camera's position and target and the Julia constant";

/// A parameter's value in a view: numbers, and for a point a deep frame
/// needs more exactly than f64 holds, strings of digits among them.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(transparent)]
pub struct Override(Vec<Component>);

impl From<Vec<f64>> for Override {
    fn from(numbers: Vec<f64>) -> Override {
        Override(numbers.into_iter().map(Component::Number).collect())
    }
}

impl Override {
    fn numbers(&self) -> Vec<f64> {
        self.0.iter().map(Component::value).collect()
    }

    /// Whether a component is a string of digits.
    fn has_digits(&self) -> bool {
        self.0.iter().any(|c| matches!(c, Component::Digits(..)))
    }

    /// The point it is, where it is three components and one a string of
    /// digits.
    fn digits(&self) -> Option<Coordinates> {
        let parts: [Component; 3] = self.0.clone().try_into().ok()?;
        self.has_digits()
            .then(|| Coordinates::from_components(parts))
    }
}

/// A view's scenes (one per sample under motion blur), size and hash.
pub struct Prepared {
    pub scenes: Vec<Scene>,
    pub frame: u32,
    pub width: u32,
    pub height: u32,
    pub hash: String,
}

impl View {
    /// The scenes `render` would render for this view, or what is wrong.
    pub fn prepare(&self, timeline: &Timeline) -> Result<Prepared, String> {
        if self.frame >= timeline.frame_count {
            let last = timeline.frame_count - 1;
            return Err(format!(
                "frame {} is past the last frame ({last})",
                self.frame
            ));
        }
        let (width, height) = match &self.size {
            Some(s) => crate::job::request::parse_size("size", s).map_err(|e| e.to_string())?,
            None => (timeline.width, timeline.height),
        };
        if width as u64 * height as u64 > MAX_VIEW_PIXELS {
            return Err(format!(
                "size {width}x{height}: the explorer shows at most 3840x2160 pixels; render larger frames with `render --size`"
            ));
        }
        if self
            .samples
            .is_some_and(|n| !(1..=MAX_SAMPLES).contains(&n))
        {
            return Err(format!("samples must be 1..={MAX_SAMPLES}"));
        }
        let timeline = timeline.clone().with_samples(self.samples);
        timeline
            .check_scene_count()
            .map_err(|(_, message)| format!("samples: {message}"))?;
        let mut scenes = timeline.scenes_for_frame(self.frame);
        for scene in &mut scenes {
            self.lay_over(scene)?;
        }
        self.auto_count_over(&timeline, &mut scenes);
        let hash = crate::output::frames::frame_hash(&scenes, self.frame, width, height);
        Ok(Prepared {
            scenes,
            frame: self.frame,
            width,
            height,
            hash,
        })
    }

    /// With `iterations: Auto` and overrides, the count the edited view
    /// chooses (the frame's saved scene chose the one it has), shared by
    /// the frame's samples as a render shares it.
    fn auto_count_over(&self, timeline: &Timeline, scenes: &mut [Scene]) {
        let Some(first) = scenes.first() else {
            return;
        };
        let Some(auto) = first.fractal.auto.filter(|_| !self.overrides.is_empty()) else {
            return;
        };
        let size = [timeline.width, timeline.height];
        let count = crate::timeline::auto::resolve(first, auto, size).count;
        for scene in scenes {
            scene.fractal.iterations = count;
        }
    }

    /// The overrides written into `scene`, which must stay valid. The zoom's
    /// distance goes last, as a timeline applies it: along the line from the
    /// target through the position.
    fn lay_over(&self, scene: &mut Scene) -> Result<(), String> {
        let zoom = crate::timeline::ZOOM_TRACK;
        let (last, first): (Vec<_>, Vec<_>) = self.overrides.iter().partition(|(n, _)| *n == zoom);
        for (name, given) in first.into_iter().chain(last) {
            let parameter = crate::timeline::parameters::find(name)
                .ok_or_else(|| format!("{name}: no such parameter"))?;
            let values = &given.numbers();
            let wanted = parameter.shape.components();
            let digits = given.digits();
            if values.len() != wanted {
                return Err(format!(
                    "{name}: takes {wanted} numbers, got {}",
                    values.len()
                ));
            }
            if given.has_digits() && parameter.digits.is_none() {
                return Err(format!("{name}: {NOT_DIGITS}"));
            }
            if let Some(bad) = values.iter().find(|v| !v.is_finite()) {
                return Err(format!("{name}: values must be finite, got {bad}"));
            }
            if *name == AUTO_FIELD && scene.fractal.auto.is_some() {
                return Err(format!(
                    "{name}: the timeline's scene says `Auto`, which chooses each frame's count: write a number in place of `Auto` in the timeline's text to fix it"
                ));
            }
            if let Some(effect) = effect_left_off(scene, name) {
                return Err(format!(
                    "{name}: the scene leaves {effect} off; turn it on in the timeline first"
                ));
            }
            if palette_part_missing(scene, name) {
                return Err(format!(
                    "{name}: the scene's look has no such palette or stop; add it in the timeline first"
                ));
            }
            if let Some(lacking) = crate::timeline::parameters::camera_lacks(scene, name) {
                return Err(format!(
                    "{name}: the scene's camera lacks it; it needs {lacking}"
                ));
            }
            if *name == zoom && values[0] <= 0.0 {
                return Err(format!(
                    "{name}: a camera distance must be positive, got {}",
                    values[0]
                ));
            }
            match (digits, parameter.digits) {
                (Some(point), Some(exact)) => (exact.set)(scene, point),
                _ if crate::timeline::edit::rounds_digits(scene, parameter, values) => {}
                _ => (parameter.set)(scene, values),
            }
        }
        crate::timeline::validate_scene(scene)
            .map_err(|(field, message)| format!("{field}: {message}"))
    }
}

/// Every animatable parameter's value at `frame`: none for a field of an
/// effect the scene leaves off.
pub fn values(timeline: &Timeline, frame: u32) -> BTreeMap<&'static str, Option<Vec<f64>>> {
    let scene = timeline.scene_at(frame);
    // Exactly, where digits put the camera closer than f64 tells apart.
    let distance = scene.camera.distance();
    let json = serde_json::to_value(&scene).unwrap_or_default();
    let tenths = serde_json::to_value(tenths(scene)).unwrap_or_default();
    crate::timeline::parameters::all()
        .map(|p| {
            // The zoom's distance is a track's alone, not a field of the scene.
            if p.name == crate::timeline::ZOOM_TRACK {
                return (p.name, Some(vec![distance]));
            }
            // A field held in f32 reads back a tenth as f32's tenth.
            let single =
                field(&tenths, p.name).is_some_and(|v| v.iter().all(|&x| x == 0.1f32 as f64));
            let value = field(&json, p.name);
            (
                p.name,
                value.map(|v| match single {
                    true => v.into_iter().map(as_written).collect(),
                    false => v,
                }),
            )
        })
        .collect()
}

/// The strings of digits the scene of `frame` holds a point in, by
/// parameter: what the page shows and sends back for those points, which
/// `values` gives only as their nearest numbers. A camera the zoom's
/// distance placed nearer its target than f64 keeps apart is held in the
/// target's digits and that distance: its position's digits are theirs.
pub fn digits(timeline: &Timeline, frame: u32) -> BTreeMap<&'static str, [String; 3]> {
    let scene = timeline.scene_at(frame);
    let placed = scene.camera.placed_position_digits();
    crate::timeline::parameters::all()
        .filter_map(|p| {
            let point = (p.digits?.get)(&scene).and_then(|point| point.digits);
            let held = match (point, p.name) {
                (Some(digits), _) => digits.as_ref().clone(),
                (None, "camera.position") => placed.clone()?,
                (None, _) => return None,
            };
            Some((p.name, held))
        })
        .collect()
}

/// `scene` with every parameter but the zoom set to a tenth.
fn tenths(mut scene: Scene) -> Scene {
    for p in crate::timeline::parameters::all() {
        if p.name != crate::timeline::ZOOM_TRACK {
            (p.set)(&mut scene, &[0.1; 3][..p.shape.components()]);
        }
    }
    scene
}

/// A frame's iteration count as the page shows it: with `Auto`, the count
/// it chose and what decided it, read-only.
#[derive(Debug, Serialize)]
pub struct Iterations {
    /// `Auto`'s margin; none where the timeline gives the count.
    pub margin: Option<u32>,
    pub count: u32,
    /// What decided an `Auto` count (`auto::Decided::name`).
    pub decided: Option<&'static str>,
    /// One line for the page: `Auto → 13 (target)`, or the count.
    pub shown: String,
}

/// The iteration count of `frame`, which must be one of the timeline's.
pub fn iterations(timeline: &Timeline, frame: u32) -> Iterations {
    let margin = timeline.base.fractal.auto.map(|a| a.margin);
    match timeline.auto_count(frame) {
        Some(resolved) => Iterations {
            margin,
            count: resolved.count,
            decided: Some(resolved.decided.name()),
            shown: format!("Auto → {} ({})", resolved.count, resolved.decided.name()),
        },
        None => {
            let count = timeline.scene_at(frame).fractal.iterations;
            Iterations {
                margin,
                count,
                decided: None,
                shown: count.to_string(),
            }
        }
    }
}

/// The numbers at parameter `name`'s field of a scene written as JSON
/// (coordinates written as digits, as their nearest numbers). A look's
/// exposure of 1 is left out of the JSON. A palette stop's parameter
/// indexes its list (`look.palette.stops[1].colour`).
fn field(scene: &serde_json::Value, name: &str) -> Option<Vec<f64>> {
    use crate::timeline::spans::Step;
    let number = |v: &serde_json::Value| v.as_f64().or_else(|| v.as_str()?.parse().ok());
    // A projection is written as its variant: `{"Fisheye": {"degrees": D}}`.
    let path = match name {
        crate::timeline::parameters::FISHEYE_DEGREES => "camera.projection.Fisheye.degrees",
        _ => name,
    };
    let found = crate::timeline::spans::steps(path)
        .iter()
        .try_fold(scene, |v, step| match step {
            Step::Field(f) | Step::Key(f) => v.get(f),
            Step::Index(i) => v.get(i),
        });
    match found {
        Some(serde_json::Value::Array(a)) => a.iter().map(number).collect(),
        Some(v) if !v.is_null() => Some(vec![number(v)?]),
        _ if name == "look.exposure" => Some(vec![1.0]),
        _ => None,
    }
}

/// `v`, a value of a field held in f32, as the timeline wrote it: JSON
/// carries the f32's exact value, 1.0499999523162842 for 1.05, so it is
/// read as the f32's shortest decimal.
fn as_written(v: f64) -> f64 {
    let single = v as f32;
    match single as f64 == v {
        true => single.to_string().parse().unwrap_or(v),
        false => v,
    }
}

/// Whether `name` is a part of the look's palette that `scene` lacks: the
/// palette, or the stop the name indexes.
fn palette_part_missing(scene: &Scene, name: &str) -> bool {
    if !name.starts_with("look.palette.") {
        return false;
    }
    let scene = serde_json::to_value(scene).unwrap_or_default();
    field(&scene, name).is_none()
}

/// The effect `name` is a field of (`effects.glow`), where the scene
/// leaves it off: its fields take no value then.
fn effect_left_off(scene: &Scene, name: &str) -> Option<String> {
    let (effect, _) = name.strip_prefix("effects.")?.split_once('.')?;
    let effects = serde_json::to_value(&scene.effects).ok()?;
    effects
        .get(effect)
        .is_none_or(serde_json::Value::is_null)
        .then(|| format!("effects.{effect}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;
    use std::sync::Arc;

    fn zoom() -> Timeline {
        let text = std::fs::read_to_string("timelines/zoom.ron").unwrap();
        Timeline::parse(&text, Path::new("zoom.ron")).unwrap()
    }

    #[test]
    fn an_edited_view_under_auto_renders_the_count_its_own_scene_chooses() {
        let text = std::fs::read_to_string("timelines/deep_zoom.ron").unwrap();
        let t = Timeline::parse(&text, Path::new("deep_zoom.ron")).unwrap();
        let saved = t.auto_count(300).unwrap().count;
        let mut view = View {
            frame: 300,
            ..View::default()
        };
        view.overrides
            .insert("camera.distance".into(), vec![1e-25].into());
        let prepared = view.prepare(&t).unwrap();
        let scene = &prepared.scenes[0];
        let auto = scene.fractal.auto.unwrap();
        let own = crate::timeline::auto::resolve(scene, auto, [t.width, t.height]).count;
        assert!(own > saved, "a camera far closer needs more than {saved}");
        assert_eq!(scene.fractal.iterations, own);
    }

    #[test]
    fn a_typed_distance_places_the_moved_camera_along_its_line() {
        let mut view = View {
            frame: 30,
            ..View::default()
        };
        view.overrides
            .insert("camera.distance".into(), vec![0.5].into());
        view.overrides
            .insert("camera.position".into(), vec![0.0, 1.0, 3.0].into());
        view.overrides
            .insert("camera.target".into(), vec![0.0, 1.0, 0.0].into());
        let camera = &view.prepare(&zoom()).unwrap().scenes[0].camera;
        assert!((camera.position - crate::math::DVec3::new(0.0, 1.0, 0.5)).length() < 1e-12);
    }

    #[test]
    fn values_are_the_frames_and_the_distance_is_the_cameras() {
        let t = zoom();
        let values = values(&t, 119);
        let scene = t.scene_at(119);
        // The zoom's own distance, not f64's difference of the two points.
        let distance = scene.camera.offset.unwrap().length();
        assert_eq!(values["camera.distance"], Some(vec![distance]));
        assert_eq!(values["fractal.iterations"], Some(vec![18.0]));
        assert_eq!(values["fractal.julia"], None);
    }

    #[test]
    fn a_palettes_stops_show_and_take_edits() {
        let text = "(fps: 1, frames: 1, size: (8, 6), scene: (look: (palette: (stops: [
            (position: 0, colour: (1, 0, 0)), (position: 1, colour: (0, 0, 1))]))))";
        let t = Timeline::parse(text, Path::new("p.ron")).unwrap();
        let shown = values(&t, 0);
        assert_eq!(
            shown["look.palette.stops[1].colour"],
            Some(vec![0.0, 0.0, 1.0])
        );
        assert_eq!(shown["look.palette.stops[1].position"], Some(vec![1.0]));
        assert_eq!(shown["look.palette.stops[2].colour"], None);
        assert_eq!(shown["look.palette.mix"], Some(vec![1.0]));
        let mut view = View::default();
        let green = vec![0.0, 1.0, 0.0];
        view.overrides
            .insert("look.palette.stops[1].colour".into(), green.into());
        let scene = &view.prepare(&t).unwrap().scenes[0];
        let stop = scene.look.palette.as_ref().unwrap().stops[1];
        assert_eq!(stop.colour, crate::math::Vec3::new(0.0, 1.0, 0.0));
        view.overrides
            .insert("look.palette.stops[2].colour".into(), vec![1.0; 3].into());
        assert!(view
            .prepare(&t)
            .err()
            .unwrap()
            .contains("no such palette or stop"));
        // Saved into the file where the stop is written.
        let edit = crate::timeline::edit::Edit::SetScene {
            parameter: "look.palette.stops[1].colour".into(),
            value: crate::timeline::KeyValue::Triple(0.0, 1.0, 0.0),
        };
        let saved = crate::timeline::edit::apply(text, &edit).unwrap();
        let t = Timeline::parse(&saved, Path::new("p.ron")).unwrap();
        let stop = t.scene_at(0).look.palette.unwrap().stops[1];
        assert_eq!(stop.colour, crate::math::Vec3::new(0.0, 1.0, 0.0));
    }

    #[test]
    fn a_point_typed_in_digits_is_viewed_and_shown_in_its_digits() {
        let text = std::fs::read_to_string("timelines/deep_zoom.ron").unwrap();
        let t = Timeline::parse(&text, Path::new("deep_zoom.ron")).unwrap();
        let written = "-1.10408951367381233764950538762334472132532660078012416551453";
        assert_eq!(
            digits(&t, 539)["camera.target"],
            ["0".to_string(), written.into(), "0".into()]
        );
        assert!(!digits(&zoom(), 0).contains_key("camera.target"));
        // The camera the zoom placed 1e-30 below the target, in digits.
        let position = &digits(&t, 539)["camera.position"];
        let camera = t.scene_at(539).camera;
        let held = Some(Arc::new(position.clone()));
        let below = crate::exact::difference(
            (camera.position, held.as_ref()),
            (camera.target, camera.target_digits.as_ref()),
        );
        let exact = camera.relative_position();
        assert!(
            (below - exact).length() <= 1e-12 * exact.length(),
            "{below}"
        );
        assert!(!digits(&t, 0).contains_key("camera.position"));
        // The same point 1e-40 along x, which no f64 tells from it.
        let moved = "0.0000000000000000000000000000000000000001";
        let typed: Override =
            serde_json::from_str(&format!(r#"["{moved}", "{written}", 0]"#)).unwrap();
        let view = View {
            frame: 539,
            overrides: [("camera.target".to_string(), typed)].into(),
            ..View::default()
        };
        let scene = &view.prepare(&t).unwrap().scenes[0];
        let held = scene.camera.target_digits.as_deref().unwrap();
        assert_eq!(held, &[moved.to_string(), written.into(), "0.0".into()]);
        // Digits only where a point takes them.
        let up: Override = serde_json::from_str(r#"["0.1", 1, 0]"#).unwrap();
        let view = View {
            overrides: [("camera.up".to_string(), up)].into(),
            ..View::default()
        };
        assert!(view.prepare(&t).err().unwrap().contains("takes numbers"));
        let refused = |name: &str, json: &str| {
            let view = View {
                overrides: [(name.to_string(), serde_json::from_str(json).unwrap())].into(),
                ..View::default()
            };
            view.prepare(&t).err().unwrap()
        };
        assert!(
            refused("camera.distance", r#"["1e-30"]"#).contains("camera.distance: takes numbers")
        );
        assert!(refused("camera.target", r#"["1", 2]"#).contains("takes 3 numbers, got 2"));
    }

    #[test]
    fn bad_views_say_what_is_wrong() {
        let t = zoom();
        let error = |view: View| view.prepare(&t).err().unwrap();
        let at = |name: &str, v: Vec<f64>| View {
            overrides: [(name.to_string(), v.into())].into(),
            ..View::default()
        };
        assert!(error(View {
            frame: 120,
            ..View::default()
        })
        .contains("past the last frame (119)"));
        assert!(error(at("camera.nope", vec![1.0])).contains("no such parameter"));
        assert!(error(at("camera.position", vec![1.0])).contains("takes 3 numbers"));
        assert!(error(at("camera.fov_degrees", vec![f64::NAN])).contains("finite"));
        assert!(error(at("camera.fov_degrees", vec![0.0])).contains("fov_degrees"));
        assert!(error(at("camera.distance", vec![-1.0])).contains("positive"));
        assert!(error(at("effects.glow.strength", vec![1.0])).contains("leaves effects.glow off"));
        // Values the scene's JSON leaves out, or writes as digits, are values.
        assert!(at("look.exposure", vec![1.0]).prepare(&t).is_ok());
        assert!(at("fractal.julia", vec![0.1, 0.2, 0.3]).prepare(&t).is_ok());
        assert!(at("camera.focus_distance", vec![2.0]).prepare(&t).is_ok());
        assert_eq!(values(&t, 0)["look.exposure"], Some(vec![1.0]));
        // zoom.ron's palette has four stops.
        let fifth = at("look.palette.stops[4].colour", vec![0.5, 0.5, 0.5]);
        assert!(error(fifth).contains("no such palette or stop"));
        let huge = View {
            size: Some("3841x2160".into()),
            ..View::default()
        };
        assert!(error(huge).contains("at most 3840x2160"));
    }
}
