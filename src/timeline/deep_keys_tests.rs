use crate::exact::{big_from_digits, Big};
use crate::math::Real;
use crate::timeline::Timeline;
use std::path::Path;

const Y: &str = "-1.10408951367381233764950538762334472132532660078012416551453";

/// A 1 s film of 10 frames whose target track has `keys` (`(time, x)`,
/// x as digits) and `interpolation`, y the tip's, z 0.
fn film(keys: &[(Real, &str)], interpolation: &str, looping: bool) -> Timeline {
    parsed(keys, interpolation, looping).unwrap()
}

/// `film`, or what refuses it.
fn parsed(
    keys: &[(Real, &str)],
    interpolation: &str,
    looping: bool,
) -> crate::error::Result<Timeline> {
    let keys: Vec<String> = keys
        .iter()
        .map(|(t, x)| format!("(time: {t}, value: ({x:?}, {Y:?}, \"0\"))"))
        .collect();
    let text = format!(
        "(fps: 10, frames: 10, size: (8, 6), loop: {looping}, tracks: {{ \"camera.target\": \
         (interpolation: {interpolation}, keys: [{}]) }})",
        keys.join(", ")
    );
    Timeline::parse(&text, Path::new("test.ron"))
}

/// The target's x at `time` less `from`, exactly, as f64.
fn x_from(timeline: &Timeline, time: Real, from: &str) -> Real {
    let camera = timeline.scene_at_time(time).camera;
    let digits = camera.target_digits.expect("the target keeps digits");
    assert_eq!(digits[1], Y, "an unmoved component keeps its digits");
    let x: Big = big_from_digits(&digits[0], 1024) - big_from_digits(from, 1024);
    x.to_f64().value()
}

#[test]
fn a_target_keyed_with_digits_moves_by_less_than_f64_resolves() {
    let t = film(
        &[(0.0, "0.5"), (1.0, "0.5000000000000000000000000000001")],
        "Linear",
        false,
    );
    for (time, want) in [
        (0.0, 0.0),
        (0.3, 3e-32),
        (0.5, 5e-32),
        (1.0, 1e-31),
        (2.0, 1e-31),
    ] {
        let got = x_from(&t, time, "0.5");
        assert!(
            (got - want).abs() <= 1e-15 * 1e-31,
            "{time} s: {got:e}, not {want:e}"
        );
    }
    // Every key's digits exactly at its time.
    let end = t.scene_at_time(1.0).camera.target_digits.unwrap();
    assert_eq!(end[0], "0.5000000000000000000000000000001");
}

/// Uniform Catmull–Rom between p1 and p2 at `u`, written out.
fn catmull_rom([p0, p1, p2, p3]: [Real; 4], u: Real) -> Real {
    0.5 * (2.0 * p1
        + (p2 - p0) * u
        + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * u * u
        + (3.0 * p1 - p0 - 3.0 * p2 + p3) * u * u * u)
}

#[test]
fn a_curved_path_of_digit_keys_is_the_catmull_rom_spline_through_them() {
    // x = 0.5 + offsets of 1e-25, a curve (not a line) at every key.
    let offsets = [0.0, 1.0, 3.0, 2.0, -1.0, 0.5].map(|o| o * 1e-25);
    let digits: Vec<String> = offsets
        .iter()
        .map(|o| crate::exact::moved("0.5", *o))
        .collect();
    let keys: Vec<(Real, &str)> = digits
        .iter()
        .enumerate()
        .map(|(k, d)| (k as Real * 0.2, d.as_str()))
        .collect();
    let t = film(&keys, "CatmullRom", false);
    let key = |k: isize| match k {
        // Phantom keys mirror the ends, as a track's splines do.
        -1 => 2.0 * offsets[0] - offsets[1],
        6 => 2.0 * offsets[5] - offsets[4],
        k => offsets[k as usize],
    };
    for step in 0..=50 {
        let time = step as Real * 0.02;
        let k = ((time / 0.2).floor() as isize).min(4);
        let u = time / 0.2 - k as Real;
        let want = catmull_rom([key(k - 1), key(k), key(k + 1), key(k + 2)], u);
        let got = x_from(&t, time, "0.5");
        assert!(
            (got - want).abs() < 1e-12 * 3e-25,
            "{time} s: {got:e}, not {want:e}"
        );
    }
}

#[test]
fn a_looping_digit_track_crosses_the_period_exactly() {
    // Keys at 0.25 s and 0.75 s of a 1 s loop: midway from the second to
    // the first again, at 0 s, is the mean.
    let t = film(
        &[(0.25, "0.5"), (0.75, "0.5000000000000000000000000000002")],
        "Linear",
        true,
    );
    let got = x_from(&t, 0.0, "0.5");
    assert!((got - 1e-31).abs() < 1e-15 * 1e-31, "{got:e}");
    let got = x_from(&t, 0.9, "0.5");
    assert!((got - 1.4e-31).abs() < 1e-15 * 1e-31, "{got:e}");
}

#[test]
fn a_stepped_digit_track_holds_each_keys_digits() {
    let far = "0.5000000000000000000000000000001";
    let t = film(&[(0.0, "0.5"), (0.5, far)], "Step", false);
    let digits = |time| t.scene_at_time(time).camera.target_digits.unwrap()[0].clone();
    assert_eq!(digits(0.49), "0.5");
    assert_eq!(digits(0.5), far);
}

#[test]
fn digits_are_refused_where_a_parameter_takes_numbers() {
    let text = "(fps: 10, frames: 10, size: (8, 6), tracks: {\n  \"look.base_colour\": (keys: [\n    (time: 0, value: (\"0.5\", 0.5, 0.5)),\n  ]),\n})";
    let e = Timeline::parse(text, Path::new("test.ron"))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("test.ron:3:"), "{e}");
    assert!(
        e.contains("look.base_colour takes numbers: strings of digits are for camera.position, camera.target, fractal.julia"),
        "{e}"
    );
    let number = text.replace("(\"0.5\", 0.5, 0.5)", "(\"0.5\")");
    let e = Timeline::parse(&number, Path::new("test.ron"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("a number is written as a number"), "{e}");
    let bad = text.replace("\"0.5\", 0.5", "\"0.5.1\", 0.5");
    let e = Timeline::parse(&bad, Path::new("test.ron"))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("test.ron:3:") && e.contains("not a decimal number"),
        "{e}"
    );
}

#[test]
fn a_loops_end_key_in_digits_must_be_its_start_to_the_last_digit() {
    let keys = |end| {
        parsed(
            &[(0.0, "0.5"), (0.5, "0.6"), (1.0, end)],
            "CatmullRom",
            true,
        )
    };
    assert!(keys("0.50").is_ok());
    let e = keys("0.5000000000000000000000000000001")
        .unwrap_err()
        .to_string();
    assert!(e.contains("must have the same value"), "{e}");
}
