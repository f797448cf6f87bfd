//! Palettes from the command line: every orbit quantity renders finite,
//! in f64 and deep frames; mix 0 is the look without one; an animated
//! offset changes the frames.

use crate::util::{tiny_timeline, with_scene, Dir};

/// A palette of three stops driven `by` an orbit quantity, with `extra` fields.
fn palette(by: &str, extra: &str) -> String {
    format!(
        "look: (palette: (by: {by}, stops: [(position: 0, colour: (0.9, 0.2, 0.1)), \
         (position: 0.5, colour: (0.1, 0.7, 0.3)), (position: 1, colour: (0.1, 0.2, 0.9))]{extra}))"
    )
}

/// Every channel of `rel`'s EXR frame finite.
fn assert_finite(d: &Dir, rel: &str) {
    for (name, values) in d.exr(rel).channels {
        assert!(
            values.iter().all(|v| v.is_finite()),
            "{rel}: {name} has NaN or ∞"
        );
    }
}

/// The decoded pixels of the PNG frame at `rel`.
fn pixels(d: &Dir, rel: &str) -> Vec<u8> {
    image::open(d.path().join(rel)).unwrap().into_bytes()
}

#[test]
fn every_quantity_renders_without_nan_and_colours_the_frame() {
    let d = Dir::new();
    d.write("plain.ron", &tiny_timeline(1, 8.0));
    d.ok(&["render", "plain.ron", "--format", "png,exr"]);
    for by in ["Trap", "SmoothIterations", "Angle"] {
        let name = format!("{by}.ron");
        let scene = palette(by, "");
        d.write(&name, &with_scene(&tiny_timeline(1, 8.0), &scene));
        d.ok(&["render", &name, "--format", "png,exr"]);
        assert_finite(&d, &format!("out/{by}/frame_00000.exr"));
        let (a, b) = (
            "out/plain/frame_00000.png",
            format!("out/{by}/frame_00000.png"),
        );
        assert_ne!(pixels(&d, a), pixels(&d, &b), "{by} changed nothing");
    }
}

#[test]
fn a_palette_with_mix_0_renders_the_frame_without_one() {
    let d = Dir::new();
    let plain = with_scene(&tiny_timeline(1, 8.0), "samples_per_pixel: 2");
    d.write("plain.ron", &plain);
    let mixed = palette("SmoothIterations", ", mix: 0");
    d.write("mix0.ron", &with_scene(&plain, &mixed));
    d.ok(&["render", "plain.ron"]);
    d.ok(&["render", "mix0.ron"]);
    let (a, b) = ("out/plain/frame_00000.png", "out/mix0/frame_00000.png");
    assert_eq!(pixels(&d, a), pixels(&d, b));
}

#[test]
fn an_offset_track_cycles_the_colours() {
    let d = Dir::new();
    let still = tiny_timeline(2, 8.0).replace(
        "\"fractal.power\": (interpolation: Linear, keys: [(time: 0, value: 8), (time: 1, value: 8)]),",
        "\"look.palette.offset\": (interpolation: Linear, keys: [(time: 0, value: 0), (time: 0.05, value: 0.5)]),",
    );
    assert!(still.contains("look.palette.offset"), "{still}");
    d.write(
        "t.ron",
        &with_scene(&still, &palette("SmoothIterations", "")),
    );
    d.ok(&["render", "t.ron"]);
    let (a, b) = ("out/t/frame_00000.png", "out/t/frame_00001.png");
    assert_ne!(pixels(&d, a), pixels(&d, b));
}

#[test]
fn a_deep_frame_takes_the_palette_too() {
    // 1e-20 from a point of the 60-iteration bulb's surface (tests/it/deep.rs).
    let deep = |look: &str| {
        format!(
            "(fps: 1, frames: 1, size: (48, 27), scene: (camera: (position: (2.4548, 3.5662, \
             1.9590), target: (\"0.503022307080229373071939037055122258\", \
             \"0.443273582773394260215122339228275534\", \
             \"0.397548797954846079557511169564137767\"), fov_degrees: 40), fractal: \
             (iterations: 60){look}), tracks: {{ \"camera.distance\": (keys: [(time: 0, value: \
             1e-20)]) }})"
        )
    };
    let d = Dir::new();
    d.write("plain.ron", &deep(""));
    d.write(
        "smooth.ron",
        &deep(&format!(
            ", {}",
            palette("SmoothIterations", ", scale: 0.5")
        )),
    );
    for name in ["plain", "smooth"] {
        d.ok(&["render", &format!("{name}.ron"), "--format", "png,exr"]);
    }
    assert_finite(&d, "out/smooth/frame_00000.exr");
    let (a, b) = ("out/plain/frame_00000.png", "out/smooth/frame_00000.png");
    assert_ne!(pixels(&d, a), pixels(&d, b));
}
