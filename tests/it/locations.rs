//! Every timeline error names the line and column of the value at fault and
//! its field path, found from RON's parse of the file: not a comment that
//! mentions the field, not a field of the same name in another block.

use crate::util::{stderr, Dir};
use mandelreel::timeline::Timeline;
use proptest::prelude::*;
use std::path::Path;

/// The error `info` prints for `text`, with its exit code checked.
fn info_error(text: &str) -> String {
    let d = Dir::new();
    d.write("bad.ron", text);
    let out = d.run(&["info", "bad.ron"]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(3), "{err}");
    err
}

#[test]
fn a_comment_naming_a_field_is_not_the_field() {
    let text =
        "// fps: 24 is what we want, but\n(\n    frames: 3,\n    fps: -24,\n    size: (8, 6),\n)\n";
    let err = info_error(text);
    assert!(err.contains("bad.ron:4:10: fps: must be a number"), "{err}");
}

#[test]
fn a_field_is_found_in_its_own_block_not_where_its_name_first_appears() {
    // Each bad field follows a block with a same-named (or same-suffixed)
    // field that is valid.
    let cases = [
        (
            "camera: (aperture_radius: 0.1), effects: (ambient_occlusion: (\n radius: -1))",
            "bad.ron:4:10: scene.effects.ambient_occlusion.radius: must be positive",
        ),
        (
            "effects: (shadows: (max_steps: 10)), quality: (\n max_steps: 0)",
            "bad.ron:4:13: scene.quality.max_steps: must be",
        ),
        (
            "look: (base_colour: (1, 1, 1)), effects: (fog: (\n colour: (-1, 0, 0)))",
            "bad.ron:4:10: scene.effects.fog.colour: colours must be",
        ),
        (
            "effects: (specular: (strength: 0.3), glow: (\n strength: -1))",
            "bad.ron:4:12: scene.effects.glow.strength: must be",
        ),
    ];
    for (scene, wanted) in cases {
        let text = format!("(\n fps: 24, frames: 2, size: (8, 6),\n scene: ({scene}),\n)\n");
        let err = info_error(&text);
        assert!(err.contains(wanted), "{wanted:?} not in {err}");
    }
}

#[test]
fn a_default_at_fault_points_at_the_block_that_leaves_it_out() {
    // Looking straight down, the default up (0, 1, 0) is parallel to the view.
    let text = "(\n fps: 24, frames: 2, size: (8, 6),\n scene: (\n  camera: (position: (0, 3, 0), target: (0, 0, 0)),\n ),\n)\n";
    let err = info_error(text);
    assert!(
        err.contains("bad.ron:4:11: scene.camera.up: must not be zero or parallel"),
        "{err}"
    );
    assert!(
        err.contains("(`up` is not given here, so it takes its default)"),
        "{err}"
    );
}

#[test]
fn a_value_of_the_wrong_shape_names_its_field() {
    let err = info_error("(\n fps: 24,\n frames: 2,\n size: 48,\n)\n");
    assert!(err.contains("bad.ron:4:8: `size`: "), "{err}");
    let err = info_error("(fps: 24, frames: 2, size: (8, 6), scene: (camera: (\n position: 3)))");
    assert!(
        err.contains("bad.ron:2:12: `scene.camera.position`: "),
        "{err}"
    );
}

/// The blocks of a scene, each a list of (field, valid value), and the
/// fields made bad one at a time: (block, field, bad value, error path).
const BLOCKS: &[(&str, &[(&str, &str)])] = &[
    (
        "camera",
        &[
            ("position", "(2.6, 1.5, 1.9)"),
            ("target", "(0, 0, 0)"),
            ("fov_degrees", "40"),
            ("aperture_radius", "0"),
        ],
    ),
    ("quality", &[("max_steps", "300"), ("fudge", "0.9")]),
    (
        "look",
        &[
            ("base_colour", "(0.7, 0.7, 0.7)"),
            ("ambient", "(0.1, 0.1, 0.1)"),
        ],
    ),
    (
        "effects.shadows",
        &[("softness", "16"), ("max_steps", "128")],
    ),
    (
        "effects.ambient_occlusion",
        &[("samples", "5"), ("radius", "0.04"), ("strength", "0.9")],
    ),
    (
        "effects.specular",
        &[("strength", "0.3"), ("shininess", "32")],
    ),
    (
        "effects.fog",
        &[("density", "0.5"), ("colour", "(0.1, 0.1, 0.1)")],
    ),
    (
        "effects.glow",
        &[
            ("colour", "(0.9, 0.6, 0.3)"),
            ("strength", "0.6"),
            ("width", "4"),
        ],
    ),
];

const BAD: &[(&str, &str, &str)] = &[
    ("camera", "aperture_radius", "-1"),
    ("camera", "fov_degrees", "0"),
    ("quality", "max_steps", "0"),
    ("look", "base_colour", "(-1, 0, 0)"),
    ("effects.shadows", "max_steps", "0"),
    ("effects.ambient_occlusion", "radius", "-1"),
    ("effects.specular", "strength", "-1"),
    ("effects.fog", "colour", "(-1, 0, 0)"),
    ("effects.glow", "strength", "-1"),
    (TRACK, "value", "90"),
];

/// The bad block that is a track's second key (the power, which must be 1..=64).
const TRACK: &str = "tracks[\"fractal.power\"].keys[1]";

/// Marks where the bad value is written, to be found and taken out.
const MARK: &str = "@@";

/// A small deterministic stream of choices from proptest's seed.
struct Choices(u64);

impl Choices {
    fn next(&mut self, n: usize) -> usize {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 % n as u64) as usize
    }

    /// A separator between fields: plain, a new line, or decoy comments
    /// naming a field of another block.
    fn separator(&mut self, decoy: &str) -> String {
        match self.next(4) {
            0 => ", ".into(),
            1 => ",\n   ".into(),
            2 => format!(",\n   // é {decoy}: 1 \"\n   "),
            _ => format!(", /* {decoy}: \"//\" /* {decoy}: 2 */ */\n   "),
        }
    }

    fn shuffled<T: Clone>(&mut self, items: &[T]) -> Vec<T> {
        let mut items = items.to_vec();
        for i in (1..items.len()).rev() {
            items.swap(i, self.next(i + 1));
        }
        items
    }
}

/// A timeline with every block of `BLOCKS` in a random order and layout,
/// `bad` written (after `MARK`) in place of its field's valid value.
fn timeline(bad: (&str, &str, &str), choices: &mut Choices) -> String {
    let (bad_block, bad_field, bad_value) = bad;
    let block_text = |choices: &mut Choices, block: &str, fields: &[(&str, &str)]| {
        let mut text = String::from("(");
        for (i, (field, value)) in choices.shuffled(fields).into_iter().enumerate() {
            if i > 0 {
                text.push_str(&choices.separator(bad_field));
            }
            let value = if (block, field) == (bad_block, bad_field) {
                format!("{MARK}{bad_value}")
            } else {
                value.to_string()
            };
            text.push_str(&format!("{field}: {value}"));
        }
        text + ")"
    };
    let mut scene = Vec::new();
    let mut effects = Vec::new();
    for (block, fields) in choices.shuffled(BLOCKS) {
        let text = block_text(choices, block, fields);
        match block.strip_prefix("effects.") {
            Some(effect) => effects.push(format!("{effect}: {text}")),
            None => scene.push(format!("{block}: {text}")),
        }
    }
    let separator = choices.separator(bad_field);
    scene.push(format!("effects: ({})", effects.join(&separator)));
    let scene = choices.shuffled(&scene).join(&choices.separator(bad_field));
    let power = if bad_block == TRACK {
        format!("{MARK}{bad_value}")
    } else {
        "9".into()
    };
    let keys = format!(
        "(time: 0, value: 8),{}(time: 0.04, value: {power})",
        choices.separator(bad_field).trim_start_matches(',')
    );
    let top = [
        "fps: 24".to_string(),
        "frames: 2".to_string(),
        "size: (8, 6)".to_string(),
        format!("scene: ({scene})"),
        format!("tracks: {{ \"fractal.power\": (keys: [{keys}]) }}"),
    ];
    let top = choices.shuffled(&top).join(&choices.separator(bad_field));
    let text = format!("// {bad_field}: 3 in a leading comment\n({top})\n");
    match choices.next(2) {
        0 => text,
        _ => text.replace('\n', "\r\n"),
    }
}

/// The 1-based line and column of `MARK` in `text`, and `text` without it.
fn marked(text: &str) -> ((usize, usize), String) {
    let at = text.find(MARK).expect("the bad value is marked");
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let column = before[before.rfind('\n').map_or(0, |i| i + 1)..]
        .chars()
        .count()
        + 1;
    ((line, column), text.replacen(MARK, "", 1))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]
    #[test]
    fn a_bad_value_is_reported_where_it_is_written(bad in 0..BAD.len(), seed in 1..u64::MAX) {
        let ((line, column), text) = marked(&timeline(BAD[bad], &mut Choices(seed)));
        let err = Timeline::parse(&text, Path::new("t.ron"))
            .expect_err("the timeline has a bad value")
            .to_string();
        let (block, field, _) = BAD[bad];
        let scene = if block == TRACK { "" } else { "scene." };
        let wanted = format!("t.ron:{line}:{column}: {scene}{block}.{field}: ");
        prop_assert!(err.starts_with(&wanted), "{} not at the start of {}\n{}", wanted, err, text);
        prop_assert!(!err.contains("is not given here"), "{}", err);
    }
}

#[test]
fn every_block_of_the_generated_timelines_is_valid() {
    // The property above blames the bad value only if nothing else is bad.
    let mut choices = Choices(7);
    for _ in 0..20 {
        let (_, text) = marked(&timeline(("camera", "fov_degrees", "40"), &mut choices));
        if let Err(e) = Timeline::parse(&text, Path::new("t.ron")) {
            panic!("{e}\n{text}");
        }
    }
}
