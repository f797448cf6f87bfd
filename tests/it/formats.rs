//! PNG and EXR output decode, with the channels and metadata promised.

use crate::util::{says, stderr, tiny_timeline, with_scene, Dir};
use std::process::Command;

#[test]
fn png_and_exr_decode_with_expected_channels() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(1, 8.0));
    d.ok(&["render", "t.ron", "--format", "png,exr"]);
    assert_eq!(
        d.files("out/t"),
        [
            ".mandelreel-job.lock",
            "frame_00000.exr",
            "frame_00000.png",
            "mandelreel-job.json"
        ]
    );

    let png = image::open(d.path().join("out/t/frame_00000.png")).unwrap();
    assert_eq!((png.width(), png.height()), (48, 27));
    assert_eq!(png.color(), image::ColorType::Rgb8);

    let exr = d.exr("out/t/frame_00000.exr");
    assert_eq!(exr.size, (48, 27));
    assert_eq!(exr.names(), ["A", "B", "G", "R", "depth.Z"]);
    let channel = |name: &str| exr.channel(name);
    let z = channel("depth.Z");
    // depth.Z is the camera distance: about 2 in the middle (camera 3 from the centre), huge for background.
    assert!(
        z[13 * 48 + 24] > 1.0 && z[13 * 48 + 24] < 3.1,
        "{}",
        z[13 * 48 + 24]
    );
    assert!(z[0] >= 1.0e9);

    // The PNG's sRGB bytes and the EXR's linear values describe the same pixel.
    let r = channel("R");
    let i = 13 * 48 + 24;
    let srgb = png.to_rgb8().get_pixel(24, 13)[0] as f32 / 255.0;
    let linear = if srgb <= 0.04045 {
        srgb / 12.92
    } else {
        ((srgb + 0.055) / 1.055).powf(2.4)
    };
    assert!((linear - r[i]).abs() < 0.01, "png {linear} vs exr {}", r[i]);
}

#[test]
fn extra_layers_are_written_only_when_asked() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(1, 8.0));
    // Layers are EXR channels: asking without EXR is a usage error.
    let out = d.run(&["render", "t.ron", "--aov", "normal"]);
    assert_eq!(out.status.code(), Some(2));
    d.ok(&[
        "render",
        "t.ron",
        "--format",
        "exr",
        "--aov",
        "normal,albedo,traps,steps",
    ]);
    let exr = d.exr("out/t/frame_00000.exr");
    let names = exr.names();
    for n in [
        "N.X",
        "N.Y",
        "N.Z",
        "albedo.R",
        "albedo.G",
        "albedo.B",
        "trap.origin",
        "trap.x",
        "trap.y",
        "trap.z",
        "DE",
        "depth.Z",
    ] {
        assert!(names.contains(&n), "{n} missing from {names:?}");
    }
    let channel = |name: &str| exr.channel(name);
    let centre = 13 * 48 + 24;
    // The centre pixel sees the bulb: a unit normal facing the camera (+z side),
    // an albedo in range, and a cost of several estimates; the corner sees sky.
    let (nx, ny, nz) = (
        channel("N.X")[centre],
        channel("N.Y")[centre],
        channel("N.Z")[centre],
    );
    assert!(((nx * nx + ny * ny + nz * nz).sqrt() - 1.0).abs() < 1e-3);
    assert!(nz > 0.0, "normal faces the camera: {nz}");
    assert!(channel("albedo.R")[centre] > 0.0 && channel("albedo.R")[centre] <= 1.0);
    assert!(channel("DE")[centre] >= 5.0);
    assert_eq!(channel("N.X")[0], 0.0);
    // Asking for layers is part of what made the frame: a re-render without them re-renders.
    let out = d.ok(&["render", "t.ron", "--format", "exr"]);
    assert!(!crate::util::stderr(&out).contains("already complete"));
    // … and without them the file holds only the standard channels.
    assert_eq!(
        d.exr("out/t/frame_00000.exr").names(),
        ["A", "B", "G", "R", "depth.Z"]
    );
}

#[test]
fn extra_layers_decide_the_exr_but_not_the_png() {
    // The layers add EXR channels and change no pixel: a PNG rendered
    // beside an EXR with layers is current without them, and an EXR is
    // current for the same set of layers in any order, not for another.
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 6.0));
    d.ok(&["render", "t.ron", "--format", "exr,png", "--aov", "normal"]);
    // Whether a render with these options found every frame current.
    let current = |options: &[&str]| {
        let out = d.ok(&[&["render", "t.ron"], options].concat());
        stderr(&out).contains("2 of 2 frames already complete")
    };
    assert!(current(&["--format", "png"]));
    assert!(!current(&["--format", "exr", "--aov", "normal,steps"]));
    assert!(current(&["--format", "exr", "--aov", "steps,normal"]));
    assert!(!current(&["--format", "exr"]));
}

#[test]
fn a_filmic_tone_map_rolls_highlights_off_in_pngs_and_leaves_exrs_linear() {
    // A bright key light clips many channels; the filmic curve maps each
    // PNG value from the same linear light, which the EXRs keep unchanged.
    let d = Dir::new();
    let bright = with_scene(&tiny_timeline(1, 8.0), "look: (light_colour: (4, 3, 2))");
    d.write("clip.ron", &bright);
    d.write(
        "filmic.ron",
        &bright.replace("look: (", "look: (tone_map: Filmic, "),
    );
    for t in ["clip.ron", "filmic.ron"] {
        d.ok(&["render", t, "--format", "png,exr", "--quiet"]);
    }
    let png = |rel: &str| image::open(d.path().join(rel)).unwrap().to_rgb8();
    let (clip, filmic) = (
        png("out/clip/frame_00000.png"),
        png("out/filmic/frame_00000.png"),
    );
    let white = |img: &image::RgbImage| img.as_raw().iter().filter(|&&b| b == 255).count();
    assert!(white(&clip) > 100, "{} clipped channels", white(&clip));
    assert!(
        white(&filmic) < white(&clip) / 10,
        "{} clipped",
        white(&filmic)
    );
    let (a, b) = (
        d.exr("out/clip/frame_00000.exr"),
        d.exr("out/filmic/frame_00000.exr"),
    );
    for c in ["R", "G", "B"] {
        assert!(a.channel(c) == b.channel(c), "EXR channel {c} changed");
    }
    // Each filmic byte from the EXR's linear value (half floats: within a
    // code), by the curve written out here: Narkowicz's fit, then sRGB.
    let curve = |x: f32| (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14);
    let srgb = |y: f32| {
        let y = y.clamp(0.0, 1.0);
        let s = if y <= 0.0031308 {
            12.92 * y
        } else {
            1.055 * y.powf(1.0 / 2.4) - 0.055
        };
        s * 255.0
    };
    let linear = [a.channel("R"), a.channel("G"), a.channel("B")];
    for (k, px) in filmic.pixels().enumerate() {
        for (c, (&byte, channel)) in px.0.iter().zip(linear).enumerate() {
            let expected = srgb(curve(channel[k].max(0.0)));
            let got = byte as f32;
            assert!(
                (got - expected).abs() <= 1.5,
                "pixel {k} channel {c}: {got} vs {expected}"
            );
        }
    }
}

#[test]
fn a_change_of_grade_rerenders_pngs_but_leaves_exrs_and_fades_to_black() {
    // Exposure and tone map change how PNGs show the light, not the light:
    // an EXR-only sequence stays current, PNGs beside EXRs render again.
    let d = Dir::new();
    let text = tiny_timeline(2, 6.0);
    d.write("t.ron", &text);
    d.ok(&[
        "render", "t.ron", "--format", "exr", "--out", "exr", "--quiet",
    ]);
    d.ok(&[
        "render", "t.ron", "--format", "png,exr", "--out", "both", "--quiet",
    ]);
    let (exr, png) = (
        d.bytes("both/frame_00001.exr"),
        d.bytes("both/frame_00001.png"),
    );
    let graded = with_scene(&text, "look: (exposure: 2, tone_map: Filmic)");
    d.write("t.ron", &graded);
    let out = d.ok(&["render", "t.ron", "--format", "exr", "--out", "exr"]);
    says(&out, "2 of 2 frames already complete");
    let out = d.ok(&["render", "t.ron", "--format", "png,exr", "--out", "both"]);
    says(&out, "2 frames rendered");
    assert!(
        d.bytes("both/frame_00001.exr") == exr,
        "the EXR's light changed"
    );
    assert!(
        d.bytes("both/frame_00001.png") != png,
        "the PNG kept its grade"
    );
    // The exposure track fades frame 1 to black, background and all.
    let fade = text.replace(
        "tracks: {",
        "tracks: {\n        \"look.exposure\": (interpolation: Linear, keys: [(time: 0, value: 1), (time: 0.04, value: 0)]),",
    );
    d.write("fade.ron", &fade);
    d.ok(&["render", "fade.ron", "--quiet"]);
    let frame = |k: u32| {
        image::open(d.path().join(format!("out/fade/frame_{k:05}.png")))
            .unwrap()
            .to_rgb8()
    };
    assert!(frame(0).as_raw().iter().any(|&b| b > 0));
    assert!(
        frame(1).as_raw().iter().all(|&b| b == 0),
        "frame 1 is not black"
    );
}

/// A frame `size` of background alone (the camera looks away from the bulb).
fn background_only(size: &str) -> String {
    let away = "camera: (position: (0, 0, 3), target: (0, 0, 10))";
    tiny_timeline(1, 8.0)
        .replace("camera: (position: (0, 0.5, 3.0))", away)
        .replace("size: (48, 27)", &format!("size: {size}"))
}

#[test]
fn eight_bit_pngs_are_dithered_so_a_gradient_does_not_band() {
    // 1,080 rows of the background gradient: in 8 bits a few dozen codes,
    // each held for many rows. Dithered, each row's codes average to the
    // exact value, which the 16-bit PNG of the same frame gives.
    let d = Dir::new();
    d.write("t.ron", &background_only("(256, 1080)"));
    d.ok(&["render", "t.ron", "--out", "eight"]);
    d.ok(&["render", "t.ron", "--out", "sixteen", "--format", "png16"]);
    let eight = image::open(d.path().join("eight/frame_00000.png")).unwrap();
    let sixteen = image::open(d.path().join("sixteen/frame_00000.png")).unwrap();
    assert_eq!(eight.color(), image::ColorType::Rgb8);
    assert_eq!(sixteen.color(), image::ColorType::Rgb16);
    let (eight, sixteen) = (eight.to_rgb8(), sixteen.to_rgb16());
    let row_mean = |code: &dyn Fn(u32) -> f64| (0..256).map(code).sum::<f64>() / 256.0;
    let mut worst: f64 = 0.0;
    for y in 0..1080 {
        for k in 0..3 {
            let dithered = row_mean(&|x| eight.get_pixel(x, y)[k] as f64);
            let exact = row_mean(&|x| sixteen.get_pixel(x, y)[k] as f64 / 257.0);
            worst = worst.max((dithered - exact).abs());
        }
    }
    // Rounded to the nearest code, rows err by up to half a code.
    assert!(worst < 0.15, "a row's mean is {worst} of a code off");
}

#[test]
fn sixteen_bit_pngs_hold_the_light_and_the_coverage_as_straight_alpha() {
    let d = Dir::new();
    let clear = with_scene(
        &tiny_timeline(1, 8.0),
        "samples_per_pixel: 4, look: (transparent_background: true)",
    );
    d.write("t.ron", &clear);
    d.ok(&["render", "t.ron", "--format", "png16alpha,exr"]);
    if crate::util::tool("oiiotool", "--help") {
        let info = Command::new("oiiotool")
            .args(["--info", "out/t/frame_00000.png"])
            .current_dir(d.path())
            .output()
            .unwrap();
        let info = String::from_utf8_lossy(&info.stdout);
        assert!(info.contains("4 channel, uint16 png"), "{info}");
    }
    let png = image::open(d.path().join("out/t/frame_00000.png"))
        .unwrap()
        .to_rgba16();
    let exr = d.exr("out/t/frame_00000.exr");
    let (alpha, red) = (exr.channel("A"), exr.channel("R"));
    let linear = |code: u16| {
        let s = code as f32 / 65535.0;
        if s <= 0.04045 {
            s / 12.92
        } else {
            ((s + 0.055) / 1.055).powf(2.4)
        }
    };
    let mut partial = 0;
    for (i, p) in png.pixels().enumerate() {
        let a = p[3] as f32 / 65535.0;
        assert!(
            (a - alpha[i]).abs() < 1e-3,
            "alpha at {i}: {a} vs {}",
            alpha[i]
        );
        if alpha[i] > 0.0 {
            // Straight colour times coverage is the EXR's premultiplied colour.
            let premultiplied = linear(p[0]) * a;
            assert!(
                (premultiplied - red[i]).abs() < 2e-3 * red[i].max(1.0),
                "red at {i}"
            );
            partial += (alpha[i] < 1.0) as usize;
        }
    }
    assert!(partial > 10, "{partial} partly covered pixels");
    assert_eq!(png.get_pixel(0, 0).0, [0; 4], "a corner is transparent");
}

#[test]
fn two_png_kinds_in_one_render_are_refused() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(1, 8.0));
    let out = d.run(&["render", "t.ron", "--format", "png,png16"]);
    assert_eq!(out.status.code(), Some(2));
    says(&out, "--format");
    says(
        &out,
        "png and png16 would write the same files, frame_NNNNN.png",
    );
    assert!(d.files("out/t").is_empty(), "{:?}", d.files("out/t"));
}

#[test]
fn a_sixteen_bit_png_sequence_is_found_by_status_and_sheet_like_any_other() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(4, 7.0));
    let named = ["--frame-name", "shot_####"];
    d.ok(&[&["render", "t.ron", "--format", "png16,exr"][..], &named].concat());
    // The video is made from the PNGs, whatever their kind.
    let status = crate::util::stdout(&d.ok(&["status", "out/t"]));
    assert!(
        status.contains("shot_%04d.png") && !status.contains("apply_trc"),
        "{status}"
    );
    d.ok(&["sheet", "out/t", "--out", "sheet.png"]);
    // Another PNG kind over part of the film keeps the film's span: the
    // frames it did not render are stale, not forgotten.
    d.ok(&[
        &["render", "t.ron", "--format", "png", "--frames", "1"][..],
        &named,
    ]
    .concat());
    let json = crate::util::stdout(&d.run(&["status", "out/t", "--json"]));
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let png = &v["formats"]["png"];
    assert_eq!(
        (png["total"].as_u64(), png["complete"].as_u64()),
        (Some(4), Some(1)),
        "{json}"
    );
    // Changing the names and the kind at once is refused like a rename.
    let out = d.run(&["render", "t.ron", "--format", "png16alpha"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    says(&out, "--frame-name");
}

#[test]
fn a_sheet_too_big_for_memory_is_refused_before_it_is_made() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(1, 8.0));
    d.ok(&["render", "t.ron"]);
    // 32768 × 18432 is within the side limit but 600 million pixels.
    let out = d.run(&["sheet", "out/t", "--thumb-width", "32768"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    says(&out, "pixels in all");
    assert!(!d.path().join("out/t/sheet.png").exists());
}

#[test]
fn alpha_asked_of_a_scene_that_draws_its_background_is_warned_of() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(1, 8.0));
    let out = d.ok(&["render", "t.ron", "--format", "png16alpha"]);
    says(
        &out,
        "alpha is 1 in every pixel; set look: (transparent_background: true)",
    );
    let png = image::open(d.path().join("out/t/frame_00000.png"))
        .unwrap()
        .to_rgba16();
    assert!(png.pixels().all(|p| p[3] == 65535));
    let clear = with_scene(
        &tiny_timeline(1, 8.0),
        "look: (transparent_background: true)",
    );
    d.write("clear.ron", &clear);
    let out = d.ok(&["render", "clear.ron", "--format", "png16alpha"]);
    assert!(!stderr(&out).contains("alpha is 1"), "{}", stderr(&out));
}
