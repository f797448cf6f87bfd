//! Adaptive sampling through the binary: fewer samples where the frame is
//! flat, `--samples` as its cap, the same bytes on any thread count and
//! after a kill, and its settings checked with their place.

use crate::util::{
    long_frames, render_until_a_checkpoint, says, stderr, stdout, tiny_timeline, with_scene, Dir,
};

/// The samples a pixel each frame took, from `render --stats`.
fn samples_a_pixel(out: &std::process::Output) -> Vec<f64> {
    let text = stderr(out) + &stdout(out);
    text.lines()
        .filter_map(|l| {
            let (before, _) = l.split_once(" samples a pixel")?;
            before.rsplit(['(', ' ']).next()?.parse().ok()
        })
        .collect()
}

#[test]
fn adaptive_sampling_spends_samples_where_the_frame_needs_them() {
    let d = Dir::new();
    let adaptive = "samples_per_pixel: 16, adaptive: (first: 2, noise: 0.02)";
    d.write("a.ron", &with_scene(&tiny_timeline(1, 8.0), adaptive));
    d.write(
        "u.ron",
        &with_scene(&tiny_timeline(1, 8.0), "samples_per_pixel: 16"),
    );
    let taken = |timeline: &str, extra: &[&str]| {
        let mut args = vec!["render", timeline, "--stats", "--quiet"];
        args.extend_from_slice(extra);
        samples_a_pixel(&d.ok(&args))
    };
    assert_eq!(taken("u.ron", &[]), [16.0]);
    // The background and the bulb's smooth parts stop early; its edges
    // take every sample.
    let a = taken("a.ron", &[]);
    assert!(a.len() == 1 && a[0] > 2.5 && a[0] < 12.0, "{a:?}");
    // --samples is the cap: a draft at 1 takes one sample everywhere.
    let capped = taken("a.ron", &["--samples", "4", "--out", "capped"]);
    assert!(capped[0] > 2.0 && capped[0] < 4.0, "{capped:?}");
    assert_eq!(taken("a.ron", &["--samples", "1", "--out", "draft"]), [1.0]);
    let info = stdout(&d.ok(&["info", "a.ron"]));
    assert!(
        info.contains("adaptive: 2 to 16 samples per pixel, to noise 0.02"),
        "{info}"
    );
}

#[test]
fn adaptive_frames_are_the_same_on_any_thread_count_and_after_a_kill() {
    let d = Dir::new();
    // Path traced: noisy, so pixels stop after different waves.
    let text = long_frames(1).replace(
        "samples_per_pixel: 64",
        "samples_per_pixel: 64, adaptive: (first: 2, noise: 0.01)",
    );
    assert!(text.contains("adaptive"));
    d.write("t.ron", &text);
    d.same_on_one_and_two_threads(
        "t.ron",
        &["--format", "exr", "--quiet"],
        &["frame_00000.exr"],
    );
    d.ok(&["render", "t.ron", "--out", "clean", "--quiet"]);
    let mut child = render_until_a_checkpoint(&d);
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(!d.files("out/t").contains(&"frame_00000.png".to_string()));
    let out = d.ok(&["render", "t.ron"]);
    says(&out, "resuming from a checkpoint at");
    assert!(
        d.bytes("out/t/frame_00000.png") == d.bytes("clean/frame_00000.png"),
        "the resumed adaptive frame differs from the uninterrupted one"
    );
}

#[test]
fn bad_adaptive_settings_are_refused_at_their_place() {
    for (fields, needle) in [
        (
            "adaptive: (noise: 0)",
            "scene.adaptive.noise: must be from 0.0001 to 1",
        ),
        (
            "adaptive: (first: 0)",
            "scene.adaptive.first: must be 1..=4096",
        ),
        ("adaptive: (noise: 0.01, fist: 2)", "fist"),
    ] {
        let d = Dir::new();
        d.write("bad.ron", &with_scene(&tiny_timeline(1, 8.0), fields));
        let out = d.run(&["render", "bad.ron"]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(3), "{fields}: {err}");
        assert!(err.contains(needle), "{fields}: {err}");
        assert!(err.contains("bad.ron:5:"), "{fields}: not located: {err}");
        assert!(!d.path().join("out").exists(), "{fields}: output written");
    }
}
