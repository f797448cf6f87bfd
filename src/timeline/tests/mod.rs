use super::spans;
use super::*;
use crate::math::DVec3;

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
    assert!(
        e.ends_with("`size[1]`: width and height must be 1..=32768, got -6"),
        "{e}"
    );
    let e = error_of("(fps: 24, frames: 99999999999, size: (8, 6))");
    assert!(
        e.ends_with(
            "`frames`: at most 1000000, got 99999999999: split a longer film into \
             timelines of its parts"
        ),
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

/// Every whole-number field of a timeline and the limit docs/timeline.md
/// gives it.
const COUNTED: [(&str, &str); 13] = [
    ("frames", "at most 1000000"),
    ("size[0]", "1..=32768"),
    ("size[1]", "1..=32768"),
    ("scene.samples_per_pixel", "1..=4096"),
    ("scene.adaptive.first", "1..=4096"),
    ("scene.fractal.iterations", "1..=10000"),
    ("scene.quality.max_steps", "1..=1000000"),
    ("scene.quality.cone_rays", "1..=4096"),
    ("scene.quality.refine_steps", "0..=64"),
    ("scene.effects.shadows.max_steps", "1..=100000"),
    ("scene.effects.ambient_occlusion.samples", "1..=64"),
    ("scene.effects.path_tracing.max_bounces", "1..=1024"),
    ("scene.seed", "at most 18446744073709551615"),
];

/// A timeline with `value` written at `field` (`scene.a.b` or one of the
/// film's fields), and every block on the way to it.
fn with_value(field: &str, value: &str) -> String {
    let (frames, size) = match field {
        "frames" => (value, "(8, 6)".to_string()),
        "size[0]" => ("3", format!("({value}, 6)")),
        "size[1]" => ("3", format!("(8, {value})")),
        _ => ("3", "(8, 6)".to_string()),
    };
    let scene = match field.strip_prefix("scene.") {
        Some(path) => {
            let names: Vec<&str> = path.split('.').collect();
            let opened: String = names.iter().map(|n| format!("{n}: (")).collect();
            let inner = opened.trim_end_matches('(').to_string() + value;
            format!(", scene: ({inner}{})", ")".repeat(names.len() - 1))
        }
        None => String::new(),
    };
    format!("(fps: 24, frames: {frames}, size: {size}{scene})")
}

#[test]
fn a_count_too_large_or_negative_for_its_type_is_told_the_fields_own_limit() {
    for (field, limit) in COUNTED {
        for written in ["99999999999999999999999", "-5"] {
            if field == "scene.seed" && written == "-5" {
                continue;
            }
            let e = error_of(&with_value(field, written));
            assert!(
                e.contains(&format!("`{field}`: ")) && e.contains(&format!("got {written}")),
                "{field} = {written}: {e}"
            );
            if written != "-5" || !field.starts_with("frames") {
                assert!(e.contains(limit), "{field} = {written}: {e}");
            }
            assert!(!e.contains("4294967295"), "{field} = {written}: {e}");
        }
    }
    for (field, says) in [
        ("frames", "`frames`: must be at least 1, got -5"),
        ("scene.seed", "`scene.seed`: must be 0 or more, got -5"),
    ] {
        let e = error_of(&with_value(field, "-5"));
        assert!(e.ends_with(says), "{e}");
    }
    // Placed at the number, not at the field's name or the space before it.
    let e = error_of("(fps: 24, size: (8, 6),\n frames:   5000000000)");
    assert!(
        e.starts_with("test.ron:2:12: `frames`: at most 1000000"),
        "{e}"
    );
}

#[test]
fn a_count_tracks_key_past_the_counts_type_is_shown_as_written() {
    for (value, got) in [("99999999999", "got 9.9999999999e10"), ("-7", "got -7")] {
        let e = error_of(&with_track(&format!(
            "\"fractal.iterations\": (keys: [(time: 0, value: {value})])"
        )));
        assert!(
            e.ends_with(&format!(
                "tracks[\"fractal.iterations\"].keys[0].value: must be 1..=10000, {got}"
            )),
            "{e}"
        );
    }
}

/// The paths of the whole numbers in `value`, a scene as JSON.
fn whole_numbers(value: &serde_json::Value, path: &str, found: &mut Vec<String>) {
    match value {
        serde_json::Value::Object(fields) => {
            for (name, v) in fields {
                whole_numbers(v, &format!("{path}.{name}"), found);
            }
        }
        serde_json::Value::Array(items) => {
            for (i, v) in items.iter().enumerate() {
                whole_numbers(v, &format!("{path}[{i}]"), found);
            }
        }
        serde_json::Value::Number(n) if !n.is_f64() => found.push(path.to_string()),
        _ => {}
    }
}

#[test]
fn every_whole_number_field_of_a_scene_has_its_limit_told() {
    // Every optional block given, so its fields are serialised.
    let every = "(adaptive: (), look: (extra_lights: [(direction: (0, 1, 0))]),
        effects: (shadows: (), ambient_occlusion: (), specular: (), fog: (), glow: (),
        motion_blur: (), path_tracing: ()))";
    let options =
        ron::Options::default().with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME);
    let scene: Scene = options.from_str(every).unwrap();
    let mut found = Vec::new();
    whole_numbers(&serde_json::to_value(&scene).unwrap(), "scene", &mut found);
    assert!(found.len() >= 9, "{found:?}");
    for field in found {
        assert!(COUNTED.iter().any(|(f, _)| *f == field), "{field}");
    }
}

#[test]
fn a_value_ron_cannot_read_is_named_by_its_field_at_its_first_character() {
    let e = error_of("(\n    size: (8, 6),\n    fps: 2.4.0,\n    frames: 3,\n)");
    assert_eq!(e, "test.ron:3:10: `fps`: Expected float");
    for (text, at) in [
        (
            "(fps: 24, frames: 3, size: (8, 6),\n scene: (camera: (fov_degrees:  4.5.6)))",
            "test.ron:2:33: `scene.camera.fov_degrees`: ",
        ),
        (
            &with_track("\"camera.position\": (keys: [(time: 0, value: (1, 2.3.4, 3))])"),
            "test.ron:1:95: `tracks[\"camera.position\"].keys[0].value[1]`: ",
        ),
        (
            "(fps: 24, frames: /* many */ 3.0.0, size: (8, 6))",
            "test.ron:1:30: `frames`: ",
        ),
    ] {
        let e = error_of(text);
        assert!(e.starts_with(at), "{e}");
    }
}

#[test]
fn an_escaped_key_is_named_alike_in_a_file_ron_reads_and_one_it_cannot() {
    for key in [r#""fractal.\"power""#, r#""fractal.\u{70}ower""#] {
        // A value of the wrong type (RON) and one RON cannot read.
        let track = |value: &str| format!("{key}: (keys: [(time: 0, value: {value})])");
        let read = error_of(&with_track(&track("\"x\"")));
        let broken = error_of(&with_track(&track("1.2.3")));
        let path = |e: &str| e.split("`").nth(1).map(str::to_string);
        assert!(path(&read).is_some(), "{read}");
        assert_eq!(path(&read), path(&broken), "{read}\n{broken}");
    }
}

#[test]
fn deep_nesting_names_the_field_its_shallow_cousin_names() {
    let deep = |open: &str, close: &str, depth: usize, inner: &str| {
        format!(
            "(fps: 24, frames: 3, size: (8, 6), scene: (camera: (fov_degrees: {}{inner}{})))",
            open.repeat(depth),
            close.repeat(depth)
        )
    };
    for (open, close, inner, field) in [
        ("(", ")", "", "`scene.camera.fov_degrees`: "),
        ("Some(", ")", "\"x\"", "`scene.camera.fov_degrees`: "),
        ("Some(", ")", "1.2.3", "`scene.camera.fov_degrees`: "),
        ("[", "]", "1", "`scene.camera.fov_degrees`: "),
    ] {
        let shallow = error_of(&deep(open, close, 3, inner));
        let deeper = error_of(&deep(open, close, 400, inner));
        assert!(shallow.contains(field), "{shallow}");
        assert!(deeper.contains(field), "{deeper}");
    }
    let scene = |depth: usize| {
        let parens = format!("{}{}", "(".repeat(depth), ")".repeat(depth));
        format!("(fps: 24, frames: 3, size: (8, 6), scene: ({parens}))")
    };
    assert_eq!(error_of(&scene(400)), error_of(&scene(3)));
    assert!(error_of(&scene(400)).contains("`scene[0]`: "));
    // Tracks given as a list, of tracks by name or of pairs.
    for list in [
        "[\"fractal.power\": (keys: [(time: 0, value: 8)])]",
        "[(\"fractal.power\", (keys: [(time: 0, value: 8)]))]",
    ] {
        let e = error_of(&format!(
            "(fps: 24, frames: 3, size: (8, 6), tracks: {list})"
        ));
        assert!(e.starts_with("test.ron:1:44: `tracks`: "), "{e}");
    }
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
fn a_fisheye_narrower_than_the_narrowest_field_of_view_is_refused() {
    let text = "(fps: 24, frames: 3, size: (8, 6), \
                scene: (camera: (projection: Fisheye(degrees: 1e-12))))";
    let column = text.find("1e-12").expect("the value is in the text") + 1;
    let e = error_of(text);
    let place = format!("test.ron:1:{column}: scene.camera.projection.degrees: ");
    assert!(e.starts_with(&place), "{e}");
    assert!(e.contains("from 1e-7 to 360 degrees, got 1e-12"), "{e}");
    let at_floor = text.replace("1e-12", "1e-7");
    assert!(parse(&at_floor).is_ok());
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
        e.contains("tracks[\"camera.fov_degrees\"].keys[1].value: must be from 1e-7 to below 179"),
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
    let e = error_of(
        "(fps: 10, frames: 1, size: (8, 6), scene: (effects: (ambient_occlusion: (samples: 0))))",
    );
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
fn a_camera_track_onto_the_target_is_refused_at_its_line() {
    // The position track sets the camera onto the target at frame 0:
    // alone, the scene's own check catches it; with a zoom track, which
    // would otherwise pick a direction of its own, the zoom's does. Both
    // name the frame, the track and its line.
    let position =
        "\"camera.position\": (keys: [(time: 0, value: (0, 0, 0)), (time: 1, value: (0, 0, 2))])";
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
        e.starts_with("test.ron:3:70: scene.look.extra_lights[0].intensity: must be non-negative"),
        "{e}"
    );
}

#[test]
fn messages_name_fractions_and_show_extreme_numbers_readably() {
    // A fraction where a count is wanted: RON alone says "Expected comma",
    // at the point; the number is shown from its start.
    let e = parse("(fps: 10, frames: 2,\n size: (320.5, 180))")
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "test.ron:2:9: `size[0]`: expected a whole number here, got 320.5"
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
    let far = "(fps: 10, frames: 2, size: (8, 6), scene: (camera: (position: (0, 0.6, 1e300))))";
    let e = parse(far).unwrap_err().to_string();
    assert!(
        e.contains("scene.camera.position") && e.contains("1e15, got (0, 0.6, 1e300)"),
        "{e}"
    );
    let zoom =
        with_track("\"camera.distance\": (keys: [(time: 0, value: 3), (time: 1, value: 1e300)])");
    let e = parse(&zoom).unwrap_err().to_string();
    assert!(
        e.contains("scene.camera.position") && e.contains("camera.distance"),
        "{e}"
    );
}

/// timelines/zoom.ron with `iterations: Auto` and its iterations track cut.
fn zoom_with_auto() -> String {
    let text = include_str!("../../../timelines/zoom.ron");
    let line = "iterations: 10,     // raised by a track as the zoom deepens";
    assert!(text.contains(line), "zoom.ron's iterations line moved");
    let text = text.replace(line, "iterations: Auto,");
    let start = text
        .find("        // Deeper views need longer")
        .expect("the track");
    let end = text.find("    },\n)").expect("the tracks' end");
    format!("{}\n{}", text[..start].trim_end(), &text[end..])
}

#[test]
fn auto_iterations_deepen_with_the_zoom() {
    let t = parse(&zoom_with_auto()).unwrap();
    let counts: Vec<u32> = (0..t.frame_count)
        .map(|f| t.scene_at(f).fractal.iterations)
        .collect();
    assert!(counts.windows(2).all(|w| w[0] <= w[1]), "{counts:?}");
    assert!(counts[counts.len() - 1] > counts[0], "{counts:?}");
    let told: Vec<u32> = (0..t.frame_count)
        .map(|f| t.auto_count(f).expect("Auto").count)
        .collect();
    assert_eq!(told, counts);
}

#[test]
fn bad_auto_iterations_are_refused_at_their_place() {
    let at = |value: &str| {
        let text = format!(
            "(fps: 10, frames: 2, size: (8, 6),\n scene: (fractal: (\n    iterations: {value})))"
        );
        error_of(&text)
    };
    // At the margin's value, not at the `)` after it.
    for (margin, told) in [("-1", "0..=100, got -1"), ("200", "0..=100, got 200")] {
        let e = at(&format!("Auto(margin: {margin})"));
        let want =
            format!("test.ron:3:30: `scene.fractal.iterations.margin`: margin must be {told}");
        assert!(e.starts_with(&want), "{e}");
    }
    for word in ["Banana", "Automatic", "()"] {
        let e = at(word);
        assert!(e.starts_with("test.ron:3:17: "), "{e}");
        assert!(
            e.contains(&format!("`Auto` or `Auto(margin: 2)`, got `{word}`")),
            "{e}"
        );
    }
    let e = at("Auto(margins: 2)");
    assert!(
        e.starts_with("test.ron:3:") && e.contains("`margin`, got `margins`"),
        "{e}"
    );
}

#[test]
fn auto_iterations_and_an_iterations_track_contradict() {
    let text = "(fps: 10, frames: 2, size: (8, 6), scene: (fractal: (iterations: Auto)),\n tracks: { \"fractal.iterations\": (keys: [(time: 0, value: 10)]) })";
    let e = error_of(text);
    assert!(e.starts_with("test.ron:2:"), "{e}");
    assert!(
        e.contains("is `Auto`, which chooses the count per frame"),
        "{e}"
    );
}

#[test]
fn a_count_and_auto_hash_alike_where_auto_chose_that_count() {
    let auto = parse(&zoom_with_auto()).unwrap().scene_at(100);
    let count = auto.fractal.iterations;
    let text = zoom_with_auto().replace("iterations: Auto,", &format!("iterations: {count},"));
    let fixed = parse(&text).unwrap().scene_at(100);
    assert_eq!(
        serde_json::to_string(&auto).unwrap(),
        serde_json::to_string(&fixed).unwrap()
    );
}

#[test]
fn a_frames_motion_blur_samples_share_its_auto_count() {
    // A fast zoom: over the open shutter the distance falls a decade, so
    // each sample's own scene would ask for another count.
    let text = "(fps: 10, frames: 4, size: (64, 36), scene: (samples_per_pixel: 4,
        camera: (position: (0, 2, 2), target: (0, 0.6505, 0)),
        fractal: (iterations: Auto), effects: (motion_blur: (shutter: 1))),
        tracks: { \"camera.distance\": (interpolation: Linear, keys: [(time: 0, value: 1), (time: 0.3, value: 1e-4)]) })";
    let t = parse(text).unwrap();
    for frame in 0..4 {
        let own = t.auto_count(frame).unwrap().count;
        let counts: Vec<u32> = t
            .scenes_for_frame(frame)
            .iter()
            .map(|s| s.fractal.iterations)
            .collect();
        assert!(
            counts.iter().all(|&c| c == own),
            "frame {frame}: {counts:?} against {own}"
        );
    }
    // The samples' own scenes do differ: the test can fail.
    let late = t.scene_at_time(0.1 + 0.09);
    let own = crate::timeline::auto::resolve(&late, late.fractal.auto.unwrap(), [64, 36]);
    assert_ne!(own.count, t.auto_count(1).unwrap().count);
}
