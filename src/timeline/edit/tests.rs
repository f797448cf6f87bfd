use super::*;
use crate::timeline::Timeline;
use proptest::prelude::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Every example timeline, read when the test runs so new ones count.
fn examples() -> Vec<(PathBuf, String)> {
    let mut files = Vec::new();
    for folder in ["timelines", "timelines/bench"] {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(folder);
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "ron") {
                files.push(path);
            }
        }
    }
    files.sort();
    assert!(files.len() >= 9, "examples not found: {files:?}");
    let read = |p: PathBuf| (p.clone(), std::fs::read_to_string(&p).unwrap());
    files.into_iter().map(read).collect()
}

fn parsed(text: &str, path: &Path) -> Timeline {
    Timeline::parse(text, path).unwrap_or_else(|e| panic!("{}: {e}\n{text}", path.display()))
}

fn edited(text: &str, edit: Edit) -> String {
    apply(text, &edit).unwrap_or_else(|e| panic!("{edit:?}: {e}"))
}

/// Every comment written in `text`, `//` to the line's end or `/* … */`.
fn comments(text: &str) -> Vec<&str> {
    let mut found = Vec::new();
    let mut rest = text;
    while let Some(at) = rest.find("//").into_iter().chain(rest.find("/*")).min() {
        let end = match rest[at..].starts_with("//") {
            true => rest[at..].find('\n').map_or(rest.len(), |n| at + n),
            false => rest[at..].find("*/").map_or(rest.len(), |n| at + n + 2),
        };
        found.push(&rest[at..end]);
        rest = &rest[end..];
    }
    found
}

/// The bytes of `original` that `result` changed, as one range.
fn changed(original: &str, result: &str) -> Range<usize> {
    let (a, b) = (original.as_bytes(), result.as_bytes());
    let prefix = a.iter().zip(b).take_while(|(x, y)| x == y).count();
    let most = a.len().min(b.len()) - prefix;
    let suffix = a
        .iter()
        .rev()
        .zip(b.iter().rev())
        .take(most)
        .take_while(|(x, y)| x == y)
        .count();
    prefix..a.len() - suffix
}

/// What every edit keeps: the original's comments, and every byte outside
/// `within` (a range of the original).
fn check_kept(original: &str, result: &str, within: Range<usize>) {
    for comment in comments(original) {
        let count = |t: &str| t.matches(comment).count();
        assert!(
            count(result) >= count(original),
            "lost {comment:?}:\n{result}"
        );
    }
    let change = changed(original, result);
    assert!(
        within.start <= change.start && change.end <= within.end,
        "changed {change:?} outside {within:?}:\n{result}"
    );
}

fn value_of(components: &[Real]) -> KeyValue {
    match *components {
        [v] => KeyValue::Number(v),
        [x, y, z] => KeyValue::Triple(x, y, z),
        _ => unreachable!("values have 1 or 3 components"),
    }
}

#[test]
fn a_key_added_and_deleted_gives_back_every_example_byte_for_byte() {
    for (path, text) in examples() {
        let timeline = parsed(&text, &path);
        for track in &timeline.tracks {
            let name = track.name.clone();
            let keys = keys(&text, &name).unwrap().unwrap();
            let list = keys.block.inside.clone();
            let last = keys.times[keys.times.len() - 1];
            // A looping film's keys stay within its period.
            let end = if timeline.looping {
                timeline.duration_seconds()
            } else {
                last + 1.0
            };
            let mut times = vec![(last + end) / 2.0];
            times.retain(|&t| t > last + 1e-6);
            if keys.times.len() > 1 {
                times.push((keys.times[0] + keys.times[1]) / 2.0);
            }
            for time in times {
                let value = value_of(&track.sample(time));
                let set = Edit::SetKey {
                    track: name.clone(),
                    time,
                    value: value.clone(),
                };
                let added = edited(&text, set);
                check_kept(&text, &added, list.clone());
                let after = parsed(&added, &path);
                let sampled = after
                    .tracks
                    .iter()
                    .find(|t| t.name == name)
                    .unwrap()
                    .sample(time);
                assert_eq!(
                    value_of(&sampled),
                    value,
                    "{}: {name} at {time}",
                    path.display()
                );
                let index = keys.times.iter().filter(|&&t| t < time).count();
                let delete = Edit::DeleteKey {
                    track: name.clone(),
                    index,
                };
                assert_eq!(edited(&added, delete), text, "{}: {name}", path.display());
            }
        }
    }
}

/// Parameters set in every example: some written there, some not.
const SET: [(&str, KeyValue); 6] = [
    ("fractal.power", KeyValue::Number(7.5)),
    ("fractal.iterations", KeyValue::Number(13.0)),
    ("camera.target", KeyValue::Triple(0.1, -0.2, 0.3)),
    ("look.exposure", KeyValue::Number(1.25)),
    ("effects.fog.density", KeyValue::Number(0.125)),
    ("quality.max_steps", KeyValue::Number(250.0)),
];

#[test]
fn a_scene_value_set_in_every_example_reads_back() {
    for (path, text) in examples() {
        let before = parsed(&text, &path);
        for (name, value) in SET {
            let set = Edit::SetScene {
                parameter: name.into(),
                value: value.clone(),
            };
            if name == "fractal.iterations" && before.base.fractal.auto.is_some() {
                assert!(apply(&text, &set).is_err(), "{}", path.display());
                continue;
            }
            let result = edited(&text, set);
            let scene = spans::range_at(&text, &[Step::Field("scene".into())]).unwrap();
            check_kept(&text, &result, scene);
            let after = parsed(&result, &path);
            let mut expected = before.base.clone();
            let parameter = parameters::find(name).unwrap();
            // An absent effect is enabled by setting its field.
            let enabled = name != "effects.fog.density" || before.base.effects.fog.is_some();
            if enabled {
                (parameter.set)(&mut expected, &value_components(&value));
                assert_eq!(after.base, expected, "{}: {name}", path.display());
            } else {
                let fog = after.base.effects.fog.as_ref().expect("fog inserted");
                assert_eq!(fog.density, 0.125, "{}", path.display());
            }
        }
    }
}

fn value_components(value: &KeyValue) -> Vec<Real> {
    match *value {
        KeyValue::Number(v) => vec![v],
        KeyValue::Triple(x, y, z) => vec![x, y, z],
        KeyValue::Digits(ref point) => point.value.to_array().to_vec(),
    }
}

#[test]
fn a_value_replaces_only_its_own_bytes() {
    let text = "(fps: 1, size: (8, 8), scene: (camera: (\n    fov_degrees: 40, // wide\n)))";
    let set = Edit::SetScene {
        parameter: "camera.fov_degrees".into(),
        value: KeyValue::Number(30.5),
    };
    assert_eq!(edited(text, set), text.replace("40", "30.5"));
    let digits = "(fps: 1, size: (8, 8), scene: (camera: (target: (\"0.5\", \"0\", \"0\"))))";
    let set = Edit::SetScene {
        parameter: "camera.target".into(),
        value: KeyValue::Triple(1.0, 2.0, 0.5),
    };
    assert_eq!(
        edited(digits, set),
        "(fps: 1, size: (8, 8), scene: (camera: (target: (1, 2, 0.5))))"
    );
}

#[test]
fn untouched_components_keep_their_text() {
    // Typing one component wrote the other two anew: `0.50` became `0.5`.
    let text = "(fps: 1, size: (8, 8), scene: (look: (base_colour: ( 0.55, 0.50,0.450 )), camera: (fov_degrees: 40.0)),
    tracks: { \"camera.position\": (keys: [(time: 0, value: (1.0, 2.00, 3))]) })";
    let set = Edit::SetScene {
        parameter: "look.base_colour".into(),
        value: KeyValue::Triple(0.9, 0.5, 0.45),
    };
    assert_eq!(edited(text, set), text.replace("0.55", "0.9"));
    let key = Edit::SetKey {
        track: "camera.position".into(),
        time: 0.0,
        value: KeyValue::Triple(1.0, 2.0, -3.5),
    };
    assert_eq!(edited(text, key), text.replace("2.00, 3)", "2.00, -3.5)"));
    let same = Edit::SetScene {
        parameter: "camera.fov_degrees".into(),
        value: KeyValue::Number(40.0),
    };
    assert_eq!(edited(text, same), text);
    // Over lines with a trailing comma, as well.
    let listed = text.replace("( 0.55, 0.50,0.450 )", "(\n  0.55,\n  0.50,\n  0.450,\n)");
    let set = Edit::SetScene {
        parameter: "look.base_colour".into(),
        value: KeyValue::Triple(0.55, 0.5, 0.9),
    };
    assert_eq!(edited(&listed, set), listed.replace("0.450", "0.9"));
    // A deep point's digits that stay are kept; a moved one is written.
    let digits = "(fps: 1, size: (8, 8), scene: (camera: (target: (\"0.5\", \"0.25\", \"0\"))))";
    let point = |y: &str| {
        let digits = ["0.5", y, "0"].map(|d| d.to_string());
        KeyValue::Digits(crate::exact::Coordinates {
            value: glam::DVec3::new(0.5, y.parse().unwrap(), 0.0),
            digits: Some(std::sync::Arc::new(digits)),
        })
    };
    let set = Edit::SetScene {
        parameter: "camera.target".into(),
        value: point("0.125"),
    };
    assert_eq!(edited(digits, set), digits.replace("0.25", "0.125"));
}

#[test]
fn a_field_is_inserted_like_its_siblings() {
    let text = "(\n    fps: 1,\n    size: (8, 8),\n    scene: (\n        look: (exposure: 1), // bright\n    ),\n)\n";
    let set = |p: &str, v| Edit::SetScene {
        parameter: p.into(),
        value: KeyValue::Number(v),
    };
    assert_eq!(
        edited(text, set("fractal.power", 3.0)),
        text.replace("// bright\n", "// bright\n        fractal: (power: 3),\n")
    );
    assert_eq!(
        edited(text, set("look.trap_occlusion", 0.5)),
        text.replace("(exposure: 1)", "(exposure: 1, trap_occlusion: 0.5)")
    );
    let bare = "(fps: 1, frames: 1, size: (8, 8))";
    assert_eq!(
        edited(bare, set("effects.fog.density", 0.25)),
        "(fps: 1, frames: 1, size: (8, 8), scene: (effects: (fog: (density: 0.25))))"
    );
    parsed(
        &edited(bare, set("effects.fog.density", 0.25)),
        Path::new("t.ron"),
    );
}

#[test]
fn whole_number_fields_are_written_whole_and_refuse_fractions() {
    let bare = "(fps: 1, frames: 1, size: (8, 8))";
    // A palette stop's fields need the stop written first; a fisheye's
    // angle and stereo's separation are fields of parts of the camera a
    // bare scene lacks (a track on them is refused there).
    let in_bare = |p: &&Parameter| p.shape == Shape::Number && p.name != ZOOM_TRACK;
    let bare_has = |p: &&Parameter| {
        parameters::camera_lacks(&crate::scene::Scene::default(), p.name).is_none()
    };
    for parameter in parameters::all()
        .filter(in_bare)
        .filter(|p| !p.name.contains('['))
        .filter(bare_has)
    {
        let set = |v| Edit::SetScene {
            parameter: parameter.name.into(),
            value: KeyValue::Number(v),
        };
        let reads = |text: &str| {
            let options = ron::Options::default()
                .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME);
            options
                .from_str::<crate::timeline::schema::TimelineFile>(text)
                .is_ok()
        };
        // RON reads 0.5 into every field but those the list names.
        let mut path = vec![Step::Field("scene".into())];
        path.extend(parameter.name.split('.').map(|f| Step::Field(f.into())));
        let half = set_field(bare, &path, "0.5").unwrap();
        let whole = WHOLE_NUMBERS.contains(&parameter.name);
        assert_eq!(reads(&half), !whole, "{}", parameter.name);
        assert_eq!(apply(bare, &set(0.5)).is_err(), whole, "{}", parameter.name);
        assert!(reads(&edited(bare, set(2.0))), "{}", parameter.name);
    }
}

#[test]
fn a_track_is_created_where_there_are_no_tracks() {
    let text = "(\n    fps: 10,\n    frames: 11,\n    size: (8, 6),\n)\n";
    let set = Edit::SetKey {
        track: "fractal.power".into(),
        time: 0.5,
        value: KeyValue::Number(7.0),
    };
    let result = edited(text, set);
    assert_eq!(
        result,
        text.replace(
            "6),\n",
            "6),\n    tracks: {\"fractal.power\": (keys: [(time: 0.5, value: 7)])},\n"
        )
    );
    let timeline = parsed(&result, Path::new("t.ron"));
    assert_eq!(timeline.scene_at_time(0.5).fractal.power, 7.0);
    let second = Edit::SetKey {
        track: "look.exposure".into(),
        time: 0.0,
        value: KeyValue::Number(2.0),
    };
    let both = parsed(&edited(&result, second), Path::new("t.ron"));
    assert_eq!(both.tracks.len(), 2);
}

#[test]
fn keys_move_past_neighbours_and_the_last_one_deleted_takes_its_track() {
    let text = "(fps: 10, frames: 11, size: (8, 6), tracks: {\n    \"fractal.power\": (keys: [\n        (time: 0, value: 8),\n        (time: 0.5, value: 6), // low\n        (time: 1, value: 9),\n    ]),\n})";
    let power = |t: &str, at: Real| {
        parsed(t, Path::new("t.ron"))
            .scene_at_time(at)
            .fractal
            .power
    };
    let moved = edited(
        text,
        Edit::MoveKey {
            track: "fractal.power".into(),
            index: 0,
            time: 0.75,
        },
    );
    assert!(
        moved.contains("(time: 0.5, value: 6), // low\n        (time: 0.75, value: 8),\n"),
        "{moved}"
    );
    assert_eq!((power(&moved, 0.75), power(&moved, 0.5)), (8.0, 6.0));
    let in_place = edited(
        text,
        Edit::MoveKey {
            track: "fractal.power".into(),
            index: 1,
            time: 0.25,
        },
    );
    assert_eq!(in_place, text.replace("0.5, value", "0.25, value"));
    let taken = Edit::MoveKey {
        track: "fractal.power".into(),
        index: 0,
        time: 1.0,
    };
    assert!(apply(text, &taken).unwrap_err().contains("already"));

    let delete = |t: &str| {
        edited(
            t,
            Edit::DeleteKey {
                track: "fractal.power".into(),
                index: 0,
            },
        )
    };
    let last = delete(&delete(text));
    // The comment on a key's line goes with the key.
    assert!(!last.contains("// low"), "{last}");
    let commented = "(fps: 10, frames: 11, size: (8, 6), tracks: {\n    \"fractal.power\": (keys: [\n        (time: 0, value: 8), // first\n        (time: 1, value: 9) // last\n    ]),\n})";
    let second = Edit::DeleteKey {
        track: "fractal.power".into(),
        index: 1,
    };
    let first_left = edited(commented, second);
    assert!(
        first_left.contains("(time: 0, value: 8), // first\n    ]"),
        "{first_left}"
    );
    assert!(!first_left.contains("// last"), "{first_left}");
    assert_eq!(
        delete(&last),
        "(fps: 10, frames: 11, size: (8, 6), tracks: {\n})"
    );
}

#[test]
fn wrong_edits_say_what_is_wrong() {
    let text = "(fps: 10, frames: 11, size: (8, 6), tracks: {\"fractal.power\": (keys: [(time: 0, value: 8)])})";
    let error = |edit: Edit| apply(text, &edit).unwrap_err();
    let number = KeyValue::Number;
    assert!(error(Edit::SetKey {
        track: "fractal.powr".into(),
        time: 0.0,
        value: number(1.0)
    })
    .contains("no parameter"));
    assert!(error(Edit::DeleteKey {
        track: "fractal.power".into(),
        index: 1
    })
    .contains("no key 1"));
    assert!(error(Edit::DeleteKey {
        track: "look.exposure".into(),
        index: 0
    })
    .contains("no track"));
    assert!(error(Edit::SetKey {
        track: "fractal.power".into(),
        time: 1.0,
        value: number(Real::NAN)
    })
    .contains("finite"));
    assert!(error(Edit::SetKey {
        track: "fractal.power".into(),
        time: Real::INFINITY,
        value: number(1.0)
    })
    .contains("finite"));
    assert!(error(Edit::SetKey {
        track: "fractal.power".into(),
        time: -1.0,
        value: number(1.0)
    })
    .contains("0 or later"));
    assert!(error(Edit::SetKey {
        track: "camera.target".into(),
        time: 0.0,
        value: number(1.0)
    })
    .contains("3 number"));
    assert!(error(Edit::SetScene {
        parameter: "camera.distance".into(),
        value: number(1.0)
    })
    .contains("only a track"));
    assert!(error(Edit::SetScene {
        parameter: "fractal.iterations".into(),
        value: number(8.5)
    })
    .contains("whole"));
    let not_ron = Edit::SetScene {
        parameter: "fractal.power".into(),
        value: number(1.0),
    };
    assert!(apply("(fps: ", &not_ron)
        .unwrap_err()
        .contains("not a timeline"));
}

/// One step of a random edit sequence: a key set or a key deleted.
#[derive(Clone, Debug)]
enum Change {
    Set(usize, u8, Real),
    Delete(usize, usize),
}

const TRACKS: [&str; 3] = [
    "camera.distance",
    "fractal.iterations",
    "camera.roll_degrees",
];

fn steps() -> impl Strategy<Value = Vec<Change>> {
    let set =
        (0..TRACKS.len(), 0u8..12, 1.0..20.0f64).prop_map(|(t, time, v)| Change::Set(t, time, v));
    let delete = (0..TRACKS.len(), 0usize..6).prop_map(|(t, i)| Change::Delete(t, i));
    proptest::collection::vec(prop_oneof![set, delete], 1..12)
}

proptest! {
    #[test]
    fn random_key_edits_match_a_model(steps in steps()) {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("timelines/zoom.ron");
        let mut text = std::fs::read_to_string(&path).unwrap();
        let mut model: BTreeMap<&str, BTreeMap<u64, Real>> = BTreeMap::new();
        model.insert("camera.distance", [(0.0f64, 2.6), (5.0, 0.0002)].map(|(t, v)| (t.to_bits(), v)).into());
        model.insert("fractal.iterations", [(0.0f64, 10.0), (5.0, 18.0)].map(|(t, v)| (t.to_bits(), v)).into());
        for step in steps {
            match step {
                Change::Set(t, time, v) => {
                    // Quarter seconds: exact in binary, so the model's keys match.
                    let time = time as Real / 4.0;
                    let v = if TRACKS[t] == "fractal.iterations" { (v / 2.0 + 8.0).round() } else { v };
                    text = edited(&text, Edit::SetKey { track: TRACKS[t].into(), time, value: KeyValue::Number(v) });
                    model.entry(TRACKS[t]).or_default().insert(time.to_bits(), v);
                }
                Change::Delete(t, i) => {
                    let edit = Edit::DeleteKey { track: TRACKS[t].into(), index: i };
                    let keys = model.entry(TRACKS[t]).or_default();
                    match keys.keys().nth(i).copied() {
                        Some(time) => {
                            text = edited(&text, edit);
                            keys.remove(&time);
                        }
                        None => prop_assert!(apply(&text, &edit).is_err()),
                    }
                }
            }
            model.retain(|_, keys| !keys.is_empty());
            let timeline = parsed(&text, &path);
            let mut names: Vec<_> = timeline.tracks.iter().map(|t| t.name.as_str()).collect();
            names.sort();
            prop_assert_eq!(names, model.keys().copied().collect::<Vec<_>>());
            for (name, keys) in &model {
                let track = timeline.tracks.iter().find(|t| t.name == *name).unwrap();
                for (&time, &v) in keys {
                    let sampled = track.sample(f64::from_bits(time))[0];
                    prop_assert!((sampled - v).abs() <= 1e-9 * v.abs(), "{name} at {}: {sampled} != {v}", f64::from_bits(time));
                }
                let times = super::keys(&text, name).unwrap().unwrap().times;
                prop_assert_eq!(times, keys.keys().map(|&t| f64::from_bits(t)).collect::<Vec<_>>());
            }
        }
    }
}

#[test]
fn a_track_in_an_empty_block_over_lines_is_laid_out_as_the_examples_are() {
    let text = "(\n    fps: 10,\n    frames: 11,\n    size: (8, 6),\n    tracks: {\n    },\n)\n";
    let set = |text: &str, time: Real, value: Real| {
        edited(
            text,
            Edit::SetKey {
                track: "fractal.power".into(),
                time,
                value: KeyValue::Number(value),
            },
        )
    };
    let one = set(text, 0.0, 7.0);
    let expected = "    tracks: {\n        \"fractal.power\": (\n            keys: [\n                (time: 0, value: 7),\n            ],\n        ),\n    },\n";
    assert!(one.contains(expected), "{one}");
    let two = set(&one, 1.0, 9.0);
    assert!(
        two.contains("                (time: 1, value: 9),\n            ],"),
        "{two}"
    );
    assert_eq!(
        parsed(&two, Path::new("t.ron"))
            .scene_at_time(1.0)
            .fractal
            .power,
        9.0
    );
    let delete = Edit::DeleteKey {
        track: "fractal.power".into(),
        index: 0,
    };
    assert_eq!(edited(&edited(&two, delete.clone()), delete), text);
}

#[test]
fn a_file_with_crlf_lines_keeps_them() {
    let text = "(\r\n    fps: 10,\r\n    frames: 11,\r\n    size: (8, 6), // small\r\n    tracks: {\r\n    },\r\n)\r\n";
    let set = Edit::SetKey {
        track: "fractal.power".into(),
        time: 0.0,
        value: KeyValue::Number(7.0),
    };
    let result = edited(text, set);
    assert_eq!(
        result.matches('\n').count(),
        result.matches("\r\n").count(),
        "{result:?}"
    );
    assert!(result.contains("(time: 0, value: 7),\r\n"), "{result:?}");
    let delete = Edit::DeleteKey {
        track: "fractal.power".into(),
        index: 0,
    };
    assert_eq!(edited(&result, delete), text);
}

#[test]
fn inner_attributes_before_the_timeline_are_kept() {
    let text = "// made by hand\n#![enable(implicit_some)]\n(\n    fps: 10,\n    frames: 11,\n    size: (8, 6),\n    scene: (fractal: (power: 8)),\n)\n";
    let set = Edit::SetScene {
        parameter: "fractal.power".into(),
        value: KeyValue::Number(5.0),
    };
    let result = edited(text, set);
    assert_eq!(result, text.replace("power: 8", "power: 5"));
    assert_eq!(parsed(&result, Path::new("t.ron")).base.fractal.power, 5.0);
}

#[test]
fn a_target_is_set_in_place_with_its_digits_and_comments_kept() {
    let text = "(\n    fps: 10,\n    frames: 11,\n    size: (8, 6),\n    scene: (\n        camera: (\n            // on the bud\n            target: (0.5, 0.4, 0.3),\n        ),\n    ),\n)\n";
    let digits = "(\"0.503044367725\", \"0.44\", \"-0.3975664467990001\")";
    let result = set_target(text, digits).unwrap();
    assert_eq!(result, text.replace("(0.5, 0.4, 0.3)", digits));
    let target = parsed(&result, Path::new("t.ron")).base.camera.target;
    assert_eq!(target.z, -0.3975664467990001);
    // No camera block: one is written.
    let bare = "(fps: 10, frames: 11, size: (8, 6))";
    let result = set_target(bare, "(1, 2, 3)").unwrap();
    assert_eq!(
        parsed(&result, Path::new("t.ron")).base.camera.target.y,
        2.0
    );
}

#[test]
fn a_target_set_by_a_track_is_not_overwritten() {
    let text =
        "(fps: 10, frames: 11, tracks: {\"camera.target\": (keys: [(time: 0, value: (1, 2, 3))])})";
    let problem = set_target(text, "(0, 0, 0)").unwrap_err();
    assert!(problem.contains("\"camera.target\" track"), "{problem}");
}

#[test]
fn no_number_is_written_over_auto_iterations() {
    let text = "(fps: 10, frames: 11, scene: (fractal: (iterations: Auto(margin: 3))))";
    let count = KeyValue::Number(20.0);
    let edits = [
        Edit::SetScene {
            parameter: "fractal.iterations".into(),
            value: count.clone(),
        },
        Edit::SetKey {
            track: "fractal.iterations".into(),
            time: 0.5,
            value: count,
        },
    ];
    for edit in edits {
        let problem = apply(text, &edit).unwrap_err();
        assert!(problem.contains("is `Auto`"), "{edit:?}: {problem}");
    }
    // A fixed count, and other fields beside `Auto`, are edited as ever.
    let fixed = text.replace("Auto(margin: 3)", "12");
    let set = Edit::SetScene {
        parameter: "fractal.iterations".into(),
        value: KeyValue::Number(20.0),
    };
    assert!(edited(&fixed, set).contains("iterations: 20"));
    let power = Edit::SetScene {
        parameter: "fractal.power".into(),
        value: KeyValue::Number(7.0),
    };
    assert!(edited(text, power).contains("Auto(margin: 3)"));
}
