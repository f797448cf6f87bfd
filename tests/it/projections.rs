//! Fisheye, equirectangular and stereo frames through the real binary:
//! each renders without NaN, a fisheye's corners are left transparent
//! black, a stereo frame's eyes differ, and pick follows the projection.

use crate::util::*;

/// A tiny timeline of `size` with `camera` fields, transparent background.
fn timeline(size: &str, camera: &str) -> String {
    let scene = "look: (transparent_background: true)";
    with_scene(&tiny_timeline(1, 8.0), scene)
        .replace("size: (48, 27)", &format!("size: {size}"))
        .replace("camera: (", &format!("camera: ({camera}, "))
}

/// Renders `t.ron` to EXR and checks every channel is finite.
fn rendered(d: &Dir) -> ExrFrame {
    d.ok(&["render", "t.ron", "--format", "exr"]);
    let frame = d.exr("out/t/frame_00000.exr");
    for (name, values) in &frame.channels {
        assert!(values.iter().all(|v| v.is_finite()), "{name} not finite");
    }
    frame
}

#[test]
fn each_projection_renders_without_nan() {
    for camera in [
        "projection: Perspective",
        "projection: Fisheye(degrees: 180)",
        "projection: Fisheye(degrees: 360)",
        "projection: Equirectangular",
        "projection: Equirectangular, stereo: (eye_separation: 0.03, layout: TopBottom)",
        "projection: Fisheye(degrees: 200), aperture_radius: 0.05",
    ] {
        let d = Dir::new();
        d.write("t.ron", &timeline("(48, 48)", camera));
        let frame = rendered(&d);
        let hits = frame.channel("A").iter().filter(|&&a| a > 0.0).count();
        assert!(hits > 20, "{camera}: {hits} hits");
    }
}

#[test]
fn a_fisheye_leaves_its_corners_transparent_black() {
    let d = Dir::new();
    // From inside the bulb's bounding sphere, a 180° dome all round.
    let camera = "projection: Fisheye(degrees: 180)";
    let close = timeline("(40, 30)", camera).replace("(0, 0.5, 3.0)", "(0, 0, 1.6)");
    d.write("t.ron", &close);
    let frame = rendered(&d);
    let (a, r) = (frame.channel("A"), frame.channel("R"));
    // The circle is 30 across at (20, 15): (2, 2) is outside, (20, 15) in.
    for (x, y) in [(0, 0), (39, 0), (2, 2), (39, 29), (4, 15)] {
        let i = y * 40 + x;
        assert_eq!((a[i], r[i]), (0.0, 0.0), "pixel ({x}, {y})");
    }
    assert_eq!(a[15 * 40 + 20], 1.0, "the centre sees the bulb");
    assert_eq!(
        frame.channel("depth.Z")[0],
        1e10,
        "a pixel that saw nothing"
    );
}

#[test]
fn a_stereo_frame_holds_two_different_eyes() {
    let halves = |separation: f64| {
        let d = Dir::new();
        let camera = format!(
            "projection: Fisheye(degrees: 120), stereo: (eye_separation: {separation}, layout: SideBySide)"
        );
        d.write("t.ron", &timeline("(64, 32)", &camera));
        let r = rendered(&d).channel("R").to_vec();
        let (left, right): (Vec<_>, Vec<_>) =
            r.chunks(32).enumerate().partition(|(i, _)| i % 2 == 0);
        let flat = |v: Vec<(usize, &[f32])>| {
            v.into_iter()
                .flat_map(|(_, c)| c.to_vec())
                .collect::<Vec<f32>>()
        };
        (flat(left), flat(right))
    };
    let (left, right) = halves(0.0);
    assert_eq!(left, right, "eyes together see the same");
    let (left, right) = halves(0.1);
    let differ = left.iter().zip(&right).filter(|(a, b)| a != b).count();
    assert!(differ > 20, "only {differ} pixels differ between the eyes");
}

#[test]
fn pick_on_a_fisheye_marches_the_rendered_ray() {
    let d = Dir::new();
    let camera = "projection: Fisheye(degrees: 180)";
    d.write("t.ron", &timeline("(48, 48)", camera));
    let depth = rendered(&d).channel("depth.Z").to_vec();
    // Off the axis, where a perspective's ray would differ.
    let (x, y) = (26, 21);
    let out = stdout(&d.ok(&["pick", "t.ron", "--pixel", &format!("{x},{y}"), "--json"]));
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["hit"], true, "{out}");
    let distance = v["distance"].as_f64().unwrap();
    let rendered = depth[y * 48 + x] as f64;
    assert!(
        (distance - rendered).abs() < 1e-5 * rendered,
        "{distance} vs {rendered}"
    );
    // The ray's angle from the axis: 90° × r / R, R = 24 pixels.
    let dir: Vec<f64> = (0..3)
        .map(|k| v["ray_direction"][k].as_f64().unwrap())
        .collect();
    let axis = [0.0, -0.5, -3.0].map(|c: f64| c / (0.25f64 + 9.0).sqrt());
    let cos: f64 = dir.iter().zip(axis).map(|(a, b)| a * b).sum();
    let r = (2.5f64).hypot(2.5);
    assert!(
        (cos.acos().to_degrees() - 90.0 * r / 24.0).abs() < 1e-6,
        "{dir:?}"
    );
    // Beyond the circle nothing is marched, as in the frame.
    let out = stdout(&d.ok(&["pick", "t.ron", "--pixel", "2,2", "--json"]));
    assert!(
        out.contains("\"hit\": false") || out.contains("\"hit\":false"),
        "{out}"
    );
}

/// A dome master's outside is no part of the picture: with the default
/// opaque background its alpha is 0 (its colour black) in every format
/// with alpha, and the circle's edge is anti-aliased by its samples.
#[test]
fn a_fisheyes_outside_is_transparent_over_an_opaque_background() {
    let d = Dir::new();
    let t = with_scene(&tiny_timeline(1, 8.0), "samples_per_pixel: 16")
        .replace("size: (48, 27)", "size: (40, 30)")
        .replace("camera: (", "camera: (projection: Fisheye(degrees: 180), ")
        .replace("(0, 0.5, 3.0)", "(0, 0, 1.6)");
    d.write("t.ron", &t);
    d.ok(&["render", "t.ron", "--format", "exr", "--out", "exr"]);
    d.ok(&["render", "t.ron", "--format", "png16alpha", "--out", "png"]);
    let exr = d.exr("exr/frame_00000.exr");
    let png = image::open(d.path().join("png/frame_00000.png"))
        .unwrap()
        .to_rgba16();
    let (a, r) = (exr.channel("A"), exr.channel("R"));
    let png_alpha = |x: u32, y: u32| png.get_pixel(x, y).0[3] as f32 / 65535.0;
    // The circle, 30 across at (20, 15), crosses pixel (9, 4) (45° up-left).
    for (x, y, what) in [(0, 0, "corner"), (9, 4, "edge"), (20, 15, "inside")] {
        let (exr_a, png_a) = (a[y as usize * 40 + x as usize], png_alpha(x, y));
        match what {
            "corner" => {
                assert_eq!((exr_a, r[0], png_a), (0.0, 0.0, 0.0), "{what}");
                assert_eq!(png.get_pixel(x, y).0, [0; 4], "{what}");
            }
            "edge" => assert!(
                exr_a > 0.0 && exr_a < 1.0 && png_a > 0.0 && png_a < 1.0,
                "{what}: {exr_a}, {png_a}"
            ),
            _ => assert_eq!((exr_a, png_a), (1.0, 1.0), "{what}"),
        }
    }
}

/// A track animates the fisheye's angle, and frames follow it; on a
/// scene without a fisheye (or stereo) such a track is refused at its
/// place in the file, naming the field.
#[test]
fn a_track_animates_the_fisheyes_angle_and_needs_a_fisheye() {
    let d = Dir::new();
    let track = "\"camera.projection.degrees\": (interpolation: Linear, keys: [(time: 0, value: 180), (time: 1, value: 90)]),";
    let t = timeline("(32, 32)", "projection: Fisheye(degrees: 180)")
        .replace("frames: 1", "frames: 2")
        .replace("fps: 24", "fps: 1")
        .replace("tracks: {", &format!("tracks: {{ {track}"));
    d.write("t.ron", &t);
    d.ok(&["render", "t.ron", "--format", "exr"]);
    let r = |frame: u32| {
        d.exr(&format!("out/t/frame_{frame:05}.exr"))
            .channel("R")
            .to_vec()
    };
    let differ = r(0).iter().zip(r(1)).filter(|(a, b)| *a != b).count();
    assert!(differ > 50, "only {differ} pixels differ");
    for (camera, field) in [
        ("fov_degrees: 45", "camera.projection.degrees"),
        (
            "projection: Fisheye(degrees: 180)",
            "camera.stereo.eye_separation",
        ),
    ] {
        let track = format!("\"{field}\": (keys: [(time: 0, value: 0.5)]),");
        let bad = timeline("(32, 32)", camera).replace("tracks: {", &format!("tracks: {{ {track}"));
        d.write("bad.ron", &bad);
        let out = d.run(&["info", "bad.ron"]);
        assert_eq!(out.status.code(), Some(3));
        let said = stderr(&out);
        assert!(
            said.contains("bad.ron:") && said.contains(&format!("tracks[\"{field}\"]")),
            "{said}"
        );
    }
}

/// A stereo pair's split side must be even, or one eye would have a pixel
/// more: an odd timeline size is an invalid timeline at its `size`, an odd
/// `--size` a bad argument, and --preview halves to an even side.
#[test]
fn a_stereo_pair_refuses_an_odd_side() {
    let d = Dir::new();
    let pair = |layout: &str| format!("stereo: (eye_separation: 0.03, layout: {layout})");
    for (size, layout, side) in [
        ("(47, 28)", "SideBySide", "width"),
        ("(48, 27)", "TopBottom", "height"),
    ] {
        d.write("t.ron", &timeline(size, &pair(layout)));
        let out = d.run(&["render", "t.ron"]);
        let e = stderr(&out);
        assert_eq!(out.status.code(), Some(3), "{e}");
        assert!(e.contains("t.ron:4:11: size: "), "{e}");
        assert!(e.contains(layout) && e.contains(side), "{e}");
    }
    d.write("t.ron", &timeline("(48, 28)", &pair("SideBySide")));
    let out = d.run(&["render", "t.ron", "--size", "47x28"]);
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{e}");
    assert!(e.contains("--size") && e.contains("SideBySide"), "{e}");
    assert!(d.files("out").is_empty(), "nothing is left behind");
    // 50x28 halves to 25x14: the preview renders 24x14.
    d.ok(&[
        "render",
        "t.ron",
        "--size",
        "50x28",
        "--preview",
        "--format",
        "exr",
    ]);
    assert_eq!(d.exr("out/t/preview/frame_00000.exr").size, (24, 14));
}
