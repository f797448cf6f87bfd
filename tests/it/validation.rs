//! Bad input through the binary: a clear message with the place, a non-zero
//! exit code, and nothing written.

use crate::util::{says, stderr, tiny_timeline, Dir};

/// Renders `text` and expects exit code `code`, a message containing every
/// item of `needles`, and no output folder.
fn rejected(text: &str, extra: &[&str], code: i32, needles: &[&str]) {
    let d = Dir::new();
    d.write("bad.ron", text);
    let mut args = vec!["render", "bad.ron"];
    args.extend_from_slice(extra);
    let out = d.run(&args);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(code), "{err}");
    for n in needles {
        assert!(err.contains(n), "missing {n:?} in: {err}");
    }
    assert!(
        !d.path().join("out").exists(),
        "output was written for a bad timeline"
    );
}

#[test]
fn syntax_error_points_at_line_and_column() {
    rejected(
        "(\n  fps: 24,\n  frames: 3\n  size: (8, 6),\n)",
        &[],
        3,
        // At the end of the line that lacks the comma.
        &["bad.ron:3:12: expected a comma after this value"],
    );
}

#[test]
fn a_track_given_twice_is_refused_not_dropped() {
    // A map would keep the second and drop the first without a word.
    let text = tiny_timeline(2, 6.0).replace(
        "    },\n)",
        "        \"fractal.power\": (keys: [(time: 0, value: 3)]),\n    },\n)",
    );
    assert_eq!(text.matches("\"fractal.power\"").count(), 2);
    rejected(
        &text,
        &[],
        3,
        &["bad.ron:8:", "\"fractal.power\" is given twice"],
    );
}

#[test]
fn a_timeline_that_is_not_utf8_is_a_syntax_error_at_its_place() {
    // A Latin-1 "é" (byte 0xE9) in a comment at the end of line 2.
    let text = tiny_timeline(2, 6.0).replacen("fps: 24,", "fps: 24, // caf\u{1}", 1);
    let bytes: Vec<u8> = text
        .bytes()
        .map(|b| if b == 1 { 0xE9 } else { b })
        .collect();
    let d = Dir::new();
    d.write_bytes("bad.ron", &bytes);
    let out = d.run(&["render", "bad.ron"]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(3), "{err}");
    let column = "    fps: 24, // caf".len() + 1;
    assert!(
        err.contains(&format!("bad.ron:2:{column}: not UTF-8")),
        "{err}"
    );
    assert!(!d.path().join("out").exists());
    // A byte-order mark before the text is no error.
    d.write("marked.ron", &format!("\u{feff}{}", tiny_timeline(1, 6.0)));
    d.ok(&["info", "marked.ron"]);
}

#[test]
fn a_missing_file_is_named_with_the_systems_reason_once() {
    let d = Dir::new();
    let out = d.run(&["info", "nowhere.ron"]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.starts_with("error: nowhere.ron: "), "{err}");
    // The system's own words for it ("No such file or directory (os
    // error 2)" on Linux), once.
    let system = std::fs::File::open(d.path().join("nowhere.ron"))
        .unwrap_err()
        .to_string();
    assert_eq!(err.matches(&system).count(), 1, "{err}");
}

#[test]
fn values_that_would_draw_a_surface_where_there_is_none_are_refused() {
    // A Julia constant whose |z|² overflows, in a scene and through a
    // track; a bounding sphere rays run out of steps in.
    let julia = "fractal: (iterations: 8, julia: Some((1e154, 1e154, 1e154)))";
    rejected(
        &tiny_timeline(2, 6.0).replace("fractal: (iterations: 8)", julia),
        &[],
        3,
        &["bad.ron:5:", "fractal.julia", "1e15"],
    );
    let track = "\"fractal.julia\": (keys: [(time: 0, value: (0.3, 0, 0)), (time: 1, value: (1e20, 0, 0))]),\n    },\n)";
    rejected(
        &tiny_timeline(2, 6.0).replace("    },\n)", track),
        &[],
        3,
        &[
            "bad.ron:",
            "tracks[\"fractal.julia\"].keys[1].value",
            "1e15",
        ],
    );
    let big = "fractal: (iterations: 8), quality: (bounding_radius: 1e100))";
    rejected(
        &tiny_timeline(2, 6.0).replace("fractal: (iterations: 8))", big),
        &[],
        3,
        &["bad.ron:5:", "quality.bounding_radius"],
    );
}

/// `mandelreel render {args}` in `d` under a 2 GB address-space limit.
fn render_in_2gb(d: &Dir, args: &str) -> std::process::Output {
    std::process::Command::new("sh")
        .current_dir(d.path())
        .arg("-c")
        .arg(format!("ulimit -v 2000000 && exec \"$0\" render {args}"))
        .arg(env!("CARGO_BIN_EXE_mandelreel"))
        .output()
        .unwrap()
}

/// Renders `args` under that limit and expects it refused with `code`
/// for want of memory, before any output folder; returns the message.
fn refused_in_2gb(d: &Dir, args: &str, code: i32) -> String {
    let out = render_in_2gb(d, args);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(code), "{err}");
    assert!(err.contains("this process may map"), "{err}");
    assert!(!d.path().join("out").exists());
    err
}

/// A folder with a tiny timeline of `size` in `name`, where this system
/// tells a process's address-space limit (only Linux does).
fn sized_where_limits_are_told(name: &str, size: &str) -> Option<Dir> {
    std::path::Path::new("/proc/self/limits").exists().then(|| {
        let d = Dir::new();
        let text = tiny_timeline(1, 6.0).replace("size: (48, 27)", &format!("size: {size}"));
        d.write(name, &text);
        d
    })
}

#[test]
fn a_size_past_the_memory_to_hand_is_refused_before_anything_is_written() {
    // Under a 2 GB address-space limit a 10000×10000 PNG frame (about
    // 2.6 GiB of buffers) cannot be had: refused up front with exit 2, no
    // folder made. 1000×1000 still renders.
    if !std::path::Path::new("/proc/self/limits").exists() {
        return; // only Linux tells the limit
    }
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(1, 6.0));
    let limited = |size: &str| render_in_2gb(&d, &format!("t.ron --size {size} --out o{size} -q"));
    let out = limited("10000x10000");
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("--size: 10000x10000 needs about"), "{err}");
    assert!(err.contains("this process may map"), "{err}");
    assert!(!d.path().join("o10000x10000").exists());
    let out = limited("1000x1000");
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn a_timelines_own_size_past_the_memory_to_hand_is_an_invalid_timeline() {
    // The size written in the timeline, not given on the command line:
    // the timeline is at fault (exit 3), at its line, and nothing is made.
    let Some(d) = sized_where_limits_are_told("t.ron", "(10000, 10000)") else {
        return;
    };
    let err = refused_in_2gb(&d, "t.ron -q", 3);
    assert!(
        err.contains("t.ron:4:11: size: 10000x10000 needs about"),
        "{err}"
    );
}

#[test]
fn a_size_halved_by_preview_past_the_memory_to_hand_says_so() {
    // --preview halves the size: the message names the size as written,
    // in the file (exit 3, at its line) or on the command line (exit 2),
    // and the halved size that was measured against the memory.
    let Some(d) = sized_where_limits_are_told("big.ron", "(30000, 30000)") else {
        return;
    };
    d.write("t.ron", &tiny_timeline(1, 6.0));
    let err = refused_in_2gb(&d, "big.ron --preview -q", 3);
    let said = "big.ron:4:11: size: 30000x30000, halved by --preview to 15000x15000, needs about";
    assert!(err.contains(said), "{err}");
    let err = refused_in_2gb(&d, "t.ron --size 30000x30000 --preview -q", 2);
    let said = "--size: halved by --preview to 15000x15000, needs about";
    assert!(err.contains(said), "{err}");
}

#[test]
fn frame_rates_past_a_thousand_are_refused() {
    for fps in ["1e300", "4294967296", "1000.5"] {
        let text = tiny_timeline(2, 6.0).replace("fps: 24", &format!("fps: {fps}"));
        rejected(&text, &[], 3, &["bad.ron:2:10: fps", "(0, 1000]"]);
    }
}

#[test]
fn unknown_field_is_named() {
    rejected(
        &tiny_timeline(2, 6.0).replace("fractal:", "fractl:"),
        &[],
        3,
        &["bad.ron:", "fractl"],
    );
}

#[test]
fn wrong_type_is_rejected() {
    rejected(
        &tiny_timeline(2, 6.0).replace("fps: 24", "fps: \"24\""),
        &[],
        3,
        &["bad.ron:2:"],
    );
}

#[test]
fn nan_value_is_rejected_with_its_track_and_key() {
    rejected(
        &tiny_timeline(2, 6.0).replace("value: 6", "value: NaN"),
        &[],
        3,
        &["tracks[\"fractal.power\"].keys[1].value", "finite"],
    );
}

#[test]
fn non_increasing_key_times_are_rejected() {
    rejected(
        &tiny_timeline(2, 6.0).replace("time: 1,", "time: 0,"),
        &[],
        3,
        &[
            "bad.ron:",
            "tracks[\"fractal.power\"].keys[1].time",
            "increase",
        ],
    );
}

#[test]
fn zero_or_negative_fps_size_fov_are_rejected() {
    rejected(
        &tiny_timeline(2, 6.0).replace("fps: 24", "fps: 0"),
        &[],
        3,
        &["bad.ron:2:10: fps"],
    );
    rejected(
        &tiny_timeline(2, 6.0).replace("size: (48, 27)", "size: (0, 27)"),
        &[],
        3,
        &["size"],
    );
    rejected(
        &tiny_timeline(2, 6.0).replace(
            "position: (0, 0.5, 3.0)",
            "position: (0, 0.5, 3.0), fov_degrees: -5",
        ),
        &[],
        3,
        &["scene.camera.fov_degrees"],
    );
}

#[test]
fn empty_track_is_rejected() {
    rejected(
        &tiny_timeline(2, 6.0).replace(
            "keys: [(time: 0, value: 8), (time: 1, value: 6)]",
            "keys: []",
        ),
        &[],
        3,
        &["tracks[\"fractal.power\"].keys", "at least one key"],
    );
}

#[test]
fn bad_flags_exit_with_usage_code_and_write_nothing() {
    rejected(
        &tiny_timeline(2, 6.0),
        &["--frames", "0..9"],
        2,
        &["--frames", "2 frames"],
    );
    rejected(&tiny_timeline(2, 6.0), &["--size", "0x10"], 2, &["--size"]);
    rejected(&tiny_timeline(2, 6.0), &["--format", "jpg"], 2, &["jpg"]);
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 6.0));
    d.write("afile", "not a folder");
    let out = d.run(&["render", "t.ron", "--out", "afile"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    says(&out, "--out: afile is a file, not a folder");
    std::fs::create_dir(d.path().join("empty")).unwrap();
    let out = d.run(&["status", "empty"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    says(&out, "empty: not a mandelreel output folder");
    for threads in ["0", "10000"] {
        let args = ["--threads", threads];
        rejected(&tiny_timeline(2, 6.0), &args, 2, &["--threads", "1..=1024"]);
    }
    for bad in ["0", "-1", "inf", "soon", "1e30"] {
        let flag = format!("--claim-timeout={bad}");
        rejected(
            &tiny_timeline(2, 6.0),
            &[&flag],
            2,
            &["--claim-timeout", "positive"],
        );
    }
    // Beyond what a duration holds, negative, not a number.
    for bad in ["1e30", "-1", "NaN"] {
        let flag = format!("--checkpoint-seconds={bad}");
        rejected(
            &tiny_timeline(2, 6.0),
            &[&flag],
            2,
            &["--checkpoint-seconds", "0 or more"],
        );
    }
}

#[test]
fn missing_timeline_is_an_io_failure() {
    let d = Dir::new();
    let out = d.run(&["render", "nope.ron"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("nope.ron"));
    assert!(!d.path().join("out").exists());
}

#[test]
fn motion_blur_instants_between_frames_are_checked_too() {
    // Every frame sits on a key, so each frame's own scene is valid, but the
    // Catmull-Rom curve dips below bailout 1 between the keys at 0 s and
    // 1 s, where frame 0's open shutter sends its samples.
    let timeline = "(
    fps: 1,
    frames: 3,
    size: (8, 6),
    scene: (samples_per_pixel: 4, effects: (motion_blur: (shutter: 1))),
    tracks: {
        \"fractal.bailout\": (interpolation: CatmullRom, keys: [(time: 0, value: 4), (time: 1, value: 1.01), (time: 2, value: 50)]),
    },
)";
    rejected(
        timeline,
        &[],
        3,
        &[
            "frame 0 (t = 0.",
            "fractal.bailout",
            "set by track \"fractal.bailout\"",
        ],
    );
    // Without the blur the same tracks render.
    let d = Dir::new();
    d.write(
        "ok.ron",
        &timeline.replace(", effects: (motion_blur: (shutter: 1))", ""),
    );
    d.ok(&["render", "ok.ron", "--quiet"]);
}

#[test]
fn a_blurred_frames_own_instant_is_checked_too() {
    // Frame 1's own instant dips below bailout 1 while every instant its open
    // shutter samples (1.025 s to 1.175 s) is past the dip: previews, `info`
    // and `pick` show that instant, so it is rejected as well, and the key
    // that sets it is named.
    let timeline = "(
    fps: 1,
    frames: 3,
    size: (8, 6),
    scene: (samples_per_pixel: 4, effects: (motion_blur: (shutter: 0.2))),
    tracks: {
        \"fractal.bailout\": (interpolation: Linear, keys: [(time: 0, value: 4), (time: 1, value: 0.9), (time: 1.01, value: 4)]),
    },
)";
    let key = "bad.ron:7:97: tracks[\"fractal.bailout\"].keys[1].value: must be a finite number above 1, got 0.9";
    rejected(timeline, &[], 3, &[key]);
}
