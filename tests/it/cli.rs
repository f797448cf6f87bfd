//! Rendering through the command line: numbered frames, ranges, sizes, the
//! ffmpeg command, thread-count determinism, `info` and `pick`.

use crate::util::{ffmpeg_installed, says, stderr, stdout, tiny_timeline, with_scene, Dir};

#[test]
fn render_writes_numbered_frames_and_prints_the_ffmpeg_command() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(3, 6.0));
    let out = d.ok(&["render", "t.ron"]);
    assert_eq!(
        d.files("out/t"),
        [
            ".mandelreel-job.lock",
            "frame_00000.png",
            "frame_00001.png",
            "frame_00002.png",
            "mandelreel-job.json"
        ]
    );
    let cmd = stdout(&out);
    assert!(cmd.starts_with("ffmpeg "), "{cmd}");
    assert!(
        cmd.contains("-framerate 24 -start_number 0 -i out/t/frame_%05d.png -frames:v 3"),
        "{cmd}"
    );
    // Distinct frames: the power track changes every frame.
    assert!(
        d.bytes("out/t/frame_00000.png") != d.bytes("out/t/frame_00002.png"),
        "frames are equal"
    );
}

#[test]
fn frame_range_is_half_open_and_size_overrides() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(5, 6.0));
    let out = d.ok(&[
        "render", "t.ron", "--frames", "1..3", "--size", "20x10", "--out", "o",
    ]);
    assert_eq!(
        d.files("o"),
        [
            ".mandelreel-job.lock",
            "frame_00001.png",
            "frame_00002.png",
            "mandelreel-job.json"
        ]
    );
    let img = image::open(d.path().join("o/frame_00001.png")).unwrap();
    assert_eq!((img.width(), img.height()), (20, 10));
    assert!(stdout(&out).contains("-start_number 1 -i o/frame_%05d.png -frames:v 2"));
}

#[test]
fn only_a_complete_film_gets_the_command_that_writes_its_video() {
    // A part of the film gets a command naming that part's own video, and
    // is told what the whole one lacks; a shard whose range others are
    // still rendering gets none; once every frame is there, the render and
    // `status` print the command for <name>.mp4.
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(5, 6.0));
    let out = d.ok(&["render", "t.ron", "--frames", "1..3"]);
    let cmd = stdout(&out);
    assert!(
        cmd.contains("-start_number 1 -i out/t/frame_%05d.png -frames:v 2")
            && cmd.trim_end().ends_with(" out/t/t_frames_1-2.mp4"),
        "{cmd}"
    );
    says(&out, "frame(s) 0, 3-4 of the film are not complete yet");
    let cmd = stdout(&d.ok(&["render", "t.ron", "--frames", "4"]));
    assert!(cmd.trim_end().ends_with(" out/t/t_frame_4.mp4"), "{cmd}");
    let out = d.ok(&["render", "t.ron", "--shard", "0/2"]);
    assert_eq!(
        stdout(&out),
        "",
        "frame 3 is another shard's, still missing"
    );
    says(
        &out,
        "once they are, mandelreel status out/t prints the command",
    );
    assert!(!stdout(&d.run(&["status", "out/t"])).contains("encode:"));
    let cmd = stdout(&d.ok(&["render", "t.ron", "--quiet"]));
    assert!(
        cmd.contains("-start_number 0 -i out/t/frame_%05d.png -frames:v 5")
            && cmd.trim_end().ends_with(" out/t/t.mp4"),
        "{cmd}"
    );
    let status = stdout(&d.ok(&["status", "out/t"]));
    assert!(
        status.contains(&format!("encode: {}", cmd.trim())),
        "{status}"
    );
    let (_, v) = d.status_json(&["out/t"]);
    assert_eq!(v["video_command"], cmd.trim(), "{v}");
}

#[test]
fn samples_on_the_command_line_render_what_the_timeline_would() {
    // `--samples 4` gives the very frames of a timeline that says
    // samples_per_pixel: 4, and the folder records it for `status`.
    let d = Dir::new();
    let text = tiny_timeline(2, 6.0);
    d.write("t.ron", &text);
    let four = with_scene(&text, "samples_per_pixel: 4");
    d.write("t4.ron", &four);
    d.ok(&["render", "t4.ron", "--quiet"]);
    d.ok(&["render", "t.ron", "--samples", "4", "--quiet"]);
    d.ok(&["render", "t.ron", "--out", "one", "--quiet"]);
    for f in ["frame_00000.png", "frame_00001.png"] {
        let given = d.bytes(&format!("out/t/{f}"));
        assert!(given == d.bytes(&format!("out/t4/{f}")), "{f} differs");
        assert!(given != d.bytes(&format!("one/{f}")), "{f} is one sample's");
    }
    assert!(stdout(&d.ok(&["status", "out/t"])).contains("2 of 2 frames complete"));
    let out = d.run(&["status", "t.ron"]);
    assert_eq!(
        out.status.code(),
        Some(4),
        "one sample's frames are not these"
    );
    d.ok(&["status", "t.ron", "--samples", "4"]);
    for bad in [&["--samples", "0"][..], &["--samples", "4", "--preview"]] {
        let out = d.run(&[&["render", "t.ron"][..], bad].concat());
        assert_eq!(out.status.code(), Some(2), "{bad:?}: {}", stderr(&out));
    }
}

#[test]
fn preview_renders_half_size_into_its_own_folder() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(1, 8.0));
    d.ok(&["render", "t.ron", "--preview"]);
    assert!(d.files("out/t").contains(&"preview".to_string()));
    let img = image::open(d.path().join("out/t/preview/frame_00000.png")).unwrap();
    assert_eq!((img.width(), img.height()), (24, 13));
}

#[test]
fn same_frame_is_byte_identical_with_one_or_two_threads() {
    let d = Dir::new();
    // Four samples per pixel exercise the jittered sampler too, and 160×96
    // spans several EXR blocks, whose order must not vary either.
    d.write(
        "t.ron",
        // Every sampled effect too: motion blur, a lens, shadows, occlusion.
        &with_scene(
            &tiny_timeline(2, 7.0),
            "samples_per_pixel: 4, effects: (motion_blur: (shutter: 0.8), shadows: (), ambient_occlusion: ())",
        )
            .replace("position: (0, 0.5, 3.0)", "position: (0, 0.5, 3.0), aperture_radius: 0.05")
            .replace("size: (48, 27)", "size: (160, 96)"),
    );
    d.same_on_one_and_two_threads(
        "t.ron",
        &["--format", "png,exr"],
        &[
            "frame_00000.png",
            "frame_00001.png",
            "frame_00000.exr",
            "frame_00001.exr",
        ],
    );
}

#[test]
fn path_traced_frame_is_byte_identical_with_one_or_two_threads() {
    let d = Dir::new();
    d.write(
        "t.ron",
        &with_scene(
            &tiny_timeline(1, 8.0),
            "samples_per_pixel: 4, effects: (path_tracing: (max_bounces: 4))",
        ),
    );
    d.same_on_one_and_two_threads("t.ron", &["--format", "exr"], &["frame_00000.exr"]);
    // And it is a different picture from the direct-lit one.
    d.write("plain.ron", &tiny_timeline(1, 8.0));
    d.ok(&["render", "plain.ron", "--out", "plain", "--format", "exr"]);
    assert!(d.bytes("one/frame_00000.exr") != d.bytes("plain/frame_00000.exr"));
}

#[test]
fn frames_have_no_nan_and_show_the_bulb() {
    let d = Dir::new();
    let transparent = "look: (transparent_background: true)";
    d.write("t.ron", &with_scene(&tiny_timeline(1, 8.0), transparent));
    d.ok(&["render", "t.ron", "--format", "exr"]);
    let image =
        exr::prelude::read_all_flat_layers_from_file(d.path().join("out/t/frame_00000.exr"))
            .unwrap();
    let layer = &image.layer_data[0];
    let mut hits = 0;
    for ch in &layer.channel_data.list {
        let values: Vec<f32> = ch.sample_data.values_as_f32().collect();
        assert!(
            values.iter().all(|v| v.is_finite()),
            "{} has non-finite values",
            ch.name
        );
        if ch.name.to_string() == "A" {
            hits = values.iter().filter(|&&a| a > 0.0).count();
            // The corners see background, the centre the bulb.
            assert_eq!(values[0], 0.0);
            assert_eq!(values[13 * 48 + 24], 1.0);
        }
    }
    assert!(hits > 48 * 27 / 10, "only {hits} pixels hit the bulb");
}

#[test]
fn info_reports_frames_tracks_and_effects() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(7, 6.0));
    let out = stdout(&d.ok(&["info", "t.ron"]));
    assert!(out.contains("7 at 24 fps"), "{out}");
    assert!(
        out.contains("fractal.power") && out.contains("Linear"),
        "{out}"
    );
    assert!(out.contains("effects:"), "{out}");
    // No effects: the measured cost is exactly the plain render's.
    assert!(
        out.contains("1.00x the same frame without effects"),
        "{out}"
    );
    assert!(d.files("out").is_empty(), "info must not write anything");
}

/// Runs the binary with a standard output whose reader is already gone.
fn with_closed_stdout(d: &Dir, args: &[&str]) -> std::process::Output {
    let (reader, writer) = std::io::pipe().expect("a pipe");
    drop(reader);
    d.command(args)
        .stdout(writer)
        .output()
        .expect("run mandelreel")
}

#[test]
fn a_closed_standard_output_ends_quietly() {
    // `mandelreel info t.ron | head -1`: the reader is gone before the
    // first line, so every write fails with a broken pipe.
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(7, 6.0));
    for args in [
        &["info", "t.ron"][..],
        &["pick", "t.ron", "--pixel", "24,13"][..],
        &["pick", "t.ron", "--pixel", "24,13", "--json"][..],
    ] {
        let out = with_closed_stdout(&d, args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{args:?}: {:?} {stderr}", out.status);
        assert!(stderr.is_empty(), "{args:?}: {stderr}");
    }
    // `status` still says by its exit status that nothing is rendered yet.
    for args in [&["status", "t.ron"][..], &["status", "t.ron", "--json"][..]] {
        let out = with_closed_stdout(&d, args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(4), "{args:?}: {out:?}");
        assert!(stderr.is_empty(), "{args:?}: {stderr}");
    }
    // Any other failure to write is still an error (Linux's /dev/full).
    if let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") {
        let out = d
            .command(&["info", "t.ron"])
            .stdout(full)
            .output()
            .expect("run mandelreel");
        assert_eq!(out.status.code(), Some(1));
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            stderr.contains("cannot write to standard output"),
            "{stderr}"
        );
    }
}

#[test]
fn pick_json_hits_the_bulb_in_the_centre_and_misses_in_the_corner() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 8.0));
    let centre = stdout(&d.ok(&[
        "pick", "t.ron", "--frame", "1", "--pixel", "24,13", "--json",
    ]));
    let v: serde_json::Value = serde_json::from_str(&centre).unwrap();
    assert_eq!(v["hit"], true);
    let p: Vec<f64> = v["point"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let o: Vec<f64> = v["ray_origin"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let dir: Vec<f64> = v["ray_direction"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let t = v["distance"].as_f64().unwrap();
    // The point lies on the ray at the reported distance, inside the bounding sphere.
    for i in 0..3 {
        assert!((o[i] + dir[i] * t - p[i]).abs() < 1e-9);
    }
    assert!(p.iter().map(|x| x * x).sum::<f64>().sqrt() < 1.5);
    assert!(v["pixel_footprint"].as_f64().unwrap() > 0.0);
    assert_eq!(v["fractal"]["power"], 8.0);
    assert_eq!(v["fractal"]["formula"], "Quilez");
    let corner: serde_json::Value = serde_json::from_str(&stdout(
        &d.ok(&["pick", "t.ron", "--pixel", "0,0", "--json"]),
    ))
    .unwrap();
    assert_eq!(corner["hit"], false);
    assert!(corner["point"].is_null());
    // The corner's ray misses the bounding sphere too: no footprint to give.
    assert!(corner["pixel_footprint"].is_null(), "{corner}");
}

#[test]
fn ffmpeg_encodes_the_frames_with_the_printed_command() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(4, 7.0));
    let cmd = stdout(&d.ok(&["render", "t.ron"]));
    if !ffmpeg_installed() {
        return;
    }
    d.run_printed(&cmd);
    let mp4 = std::fs::metadata(d.path().join("out/t/t.mp4")).unwrap();
    assert!(mp4.len() > 100);
}

#[test]
fn example_timelines_are_valid() {
    let d = Dir::new();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for name in [
        "zoom.ron",
        "julia_morph.ron",
        "effects.ron",
        "path_traced.ron",
        "quaternion.ron",
    ] {
        let path = root.join("timelines").join(name);
        let out = d.ok(&["info", path.to_str().unwrap()]);
        assert!(stdout(&out).contains("frames:"), "{}", stderr(&out));
    }
    // Declared effects show their measured price in `info`.
    let fx = stdout(&d.ok(&["info", root.join("timelines/effects.ron").to_str().unwrap()]));
    let ratio: f64 = fx
        .split("estimates, ")
        .nth(1)
        .and_then(|r| r.split('x').next())
        .and_then(|r| r.parse().ok())
        .unwrap_or_else(|| panic!("no cost line in {fx}"));
    assert!(ratio > 1.1, "{fx}");
    // The zoom spans at least four decades of scale.
    let zoom = stdout(&d.ok(&["info", root.join("timelines/zoom.ron").to_str().unwrap()]));
    let before = &zoom[..zoom.find(" decades").expect("zoom line in info")];
    let decades: f64 = before.rsplit(' ').next().unwrap().parse().unwrap();
    assert!(decades >= 4.0, "{zoom}");
    // The Julia morph is a seamless loop.
    let morph = stdout(&d.ok(&[
        "info",
        root.join("timelines/julia_morph.ron").to_str().unwrap(),
    ]));
    assert!(morph.contains("loop:     seamless"), "{morph}");
}

#[test]
fn sheet_tiles_frames_and_refuses_what_it_cannot_make() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(3, 6.0));
    d.ok(&["render", "t.ron", "--quiet"]);
    // Three 48×27 frames as 24-pixel thumbnails (13 high), two a row, 2 apart.
    let out = d.ok(&[
        "sheet",
        "out/t",
        "--count",
        "3",
        "--columns",
        "2",
        "--thumb-width",
        "24",
    ]);
    assert!(
        stdout(&out).contains("3 of 3 frames tiled into"),
        "{}",
        stdout(&out)
    );
    let sheet = image::open(d.path().join("out/t/sheet.png")).unwrap();
    assert_eq!((sheet.width(), sheet.height()), (2 * 26 - 2, 2 * 15 - 2));
    // Too large, a name that is not .png, a folder without frames: exit 2,
    // nothing written.
    let refused = [
        (
            &[
                "sheet",
                "out/t",
                "--thumb-width",
                "100000",
                "--out",
                "big.png",
            ][..],
            "at most 32768",
        ),
        (&["sheet", "out/t", "--out", "sheet.jpg"], "name it .png"),
        (
            &["sheet", "."],
            "no PNG frames named frame_##### in this folder",
        ),
    ];
    for (args, what) in refused {
        let out = d.run(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        says(&out, what);
    }
    assert!(!d.path().join("big.png").exists() && !d.path().join("sheet.jpg").exists());
    // A preview's frames are pointed at.
    d.ok(&["render", "t.ron", "--preview", "--out", "p", "--quiet"]);
    let out = d.run(&["sheet", "p"]);
    says(&out, "a preview's are in p/preview");
}

#[test]
fn labels_mark_each_thumbnail_in_its_corner_and_nowhere_else() {
    // Three frames as 192×108 thumbnails, one row, 2 px apart, with and
    // without labels: they differ only in a small box at each thumbnail's
    // top-left corner, dark at its corners, with light text inside, and
    // each box shows its own frame's number.
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(3, 6.0));
    d.ok(&["render", "t.ron", "--quiet"]);
    let sheet = |labels: &[&str], name: &str| {
        let mut args = vec!["sheet", "out/t", "--columns", "3", "--thumb-width", "192"];
        args.extend(["--out", name]);
        args.extend(labels);
        d.ok(&args);
        image::open(d.path().join(name)).unwrap().to_rgb8()
    };
    let plain = &sheet(&[], "plain.png");
    let labelled = &sheet(&["--labels"], "labelled.png");
    assert_eq!(plain.dimensions(), labelled.dimensions());
    let mut boxes = Vec::new();
    for thumb in 0..3u32 {
        let x0 = thumb * 194;
        let changed: Vec<(u32, u32)> = (0..108)
            .flat_map(|y| (x0..(x0 + 194).min(plain.width())).map(move |x| (x, y)))
            .filter(|&(x, y)| plain[(x, y)] != labelled[(x, y)])
            .collect();
        let box_w = changed.iter().map(|p| p.0).max().expect("a label") + 1 - x0;
        let box_h = changed.iter().map(|p| p.1).max().expect("a label") + 1;
        assert!(
            box_w < 96 && box_h < 54,
            "thumbnail {thumb}: box {box_w}x{box_h}"
        );
        let inside: Vec<[u8; 3]> = (0..box_h)
            .flat_map(|y| (x0..x0 + box_w).map(move |x| labelled[(x, y)].0))
            .collect();
        for corner in [(x0, 0), (x0 + box_w - 1, 0), (x0, box_h - 1)] {
            assert_eq!(
                labelled[corner].0,
                [16, 16, 16],
                "{thumb}: corner {corner:?}"
            );
        }
        let text = inside
            .iter()
            .filter(|p| p.iter().all(|&c| c >= 200))
            .count();
        assert!(text >= 3, "thumbnail {thumb}: {text} text pixels");
        boxes.push(inside);
    }
    assert!(
        boxes[0] != boxes[1] && boxes[1] != boxes[2],
        "each box its own number"
    );
}

#[test]
fn effects_declared_with_too_few_samples_render_with_a_warning() {
    // A lens with 1 sample a pixel, motion blur with 4: rendered, but each
    // says what it needs; with enough samples, or as a preview (one sample
    // by design), nothing is said.
    let d = Dir::new();
    let scene = |spp: u32| {
        tiny_timeline(1, 6.0).replace(
            "scene: (camera: (position: (0, 0.5, 3.0)),",
            &format!(
                "scene: (samples_per_pixel: {spp}, effects: (motion_blur: (shutter: 0.5)), \
                 camera: (position: (0, 0.5, 3.0), aperture_radius: 0.01),"
            ),
        )
    };
    d.write("few.ron", &scene(1));
    let err = stderr(&d.ok(&["render", "few.ron", "--size", "16x9"]));
    assert!(
        err.contains("depth of field needs samples_per_pixel of 4"),
        "{err}"
    );
    assert!(
        err.contains("motion blur needs samples_per_pixel of 8"),
        "{err}"
    );
    // info says the same, before anything is rendered.
    let info = stdout(&d.ok(&["info", "few.ron"]));
    assert!(
        info.contains("warning:  depth of field needs samples_per_pixel of 4")
            && info.contains("warning:  motion blur needs samples_per_pixel of 8"),
        "{info}"
    );
    d.write("some.ron", &scene(4));
    let err = stderr(&d.ok(&["render", "some.ron", "--size", "16x9"]));
    assert!(!err.contains("depth of field needs"), "{err}");
    assert!(err.contains("motion blur needs"), "{err}");
    d.write("enough.ron", &scene(8));
    let err = stderr(&d.ok(&["render", "enough.ron", "--size", "16x9"]));
    assert!(!err.contains("warning"), "{err}");
    let err = stderr(&d.ok(&["render", "few.ron", "--preview"]));
    assert!(!err.contains("warning"), "{err}");
}

#[test]
fn a_track_whose_keys_all_lie_outside_the_film_is_warned_of() {
    let d = Dir::new();
    let timeline = |keys: &str| {
        format!("(fps: 24, frames: 3, size: (16, 9), tracks: {{ \"fractal.power\": (keys: [{keys}]) }})")
    };
    // Three frames at 24 fps end at 1/12 s.
    d.write(
        "late.ron",
        &timeline("(time: 5, value: 4), (time: 10, value: 8)"),
    );
    let late = "every key of track \"fractal.power\" (5 s .. 10 s) is after the last frame (t = 0.083 s): it does not animate, every frame holds its first key's value";
    assert!(stdout(&d.ok(&["info", "late.ron"])).contains(late));
    says(&d.ok(&["render", "late.ron"]), late);
    d.write(
        "early.ron",
        &timeline("(time: -2, value: 4), (time: -1, value: 8)"),
    );
    let early = "(-2 s .. -1 s) is before the first frame (t = 0 s)";
    assert!(stdout(&d.ok(&["info", "early.ron"])).contains(early));
    // Keys on both sides of the film animate it: nothing to say.
    d.write(
        "across.ron",
        &timeline("(time: -1, value: 4), (time: 1, value: 8)"),
    );
    assert!(!stdout(&d.ok(&["info", "across.ron"])).contains("warning"));
    assert!(!stderr(&d.ok(&["render", "across.ron"])).contains("warning"));
    // In a looping film keys after the last frame still animate it: the
    // track wraps (its period is 3 frames, 0.125 s: the key there is the
    // start's, so frame 0 is 8 and the power falls to 4 at 0.1 s).
    let looped = timeline("(time: 0.1, value: 4), (time: 0.125, value: 8)")
        .replace("size: (16, 9),", "size: (16, 9), loop: true,");
    d.write("looped.ron", &looped);
    assert!(!stdout(&d.ok(&["info", "looped.ron"])).contains("warning"));
}

#[test]
fn info_gives_a_looping_zooms_reach_from_its_frames() {
    // The end key is the start again: first and last keys say nothing.
    let d = Dir::new();
    d.write(
        "z.ron",
        "(fps: 4, frames: 8, size: (16, 9), loop: true,
          scene: (camera: (position: (0, 0, 3), target: (0, 0, 1.1))),
          tracks: { \"camera.distance\": (interpolation: Linear, keys: [
            (time: 0, value: 3), (time: 1, value: 0.03), (time: 2, value: 3)]) })",
    );
    let info = stdout(&d.ok(&["info", "z.ron"]));
    assert!(
        info.contains("log-space zoom 3.000e0 -> 3.000e-2, 2.0 decades"),
        "{info}"
    );
}

#[test]
fn the_readmes_reference_timeline_is_valid_and_draws_no_warning() {
    let readme = include_str!("../../docs/timeline.md");
    let section = &readme[readme.find("# Timeline format").unwrap()..];
    let start = section.find("```ron\n").unwrap() + "```ron\n".len();
    let block = &section[start..start + section[start..].find("```").unwrap()];
    let d = Dir::new();
    d.write("reference.ron", block);
    let info = stdout(&d.ok(&["info", "reference.ron"]));
    assert!(info.contains("frames:   120 at 24 fps"), "{info}");
    assert!(!info.contains("warning"), "{info}");
}

/// A key of `looping_morph`: time, Julia constant, camera position.
type MorphKey = (f64, [f64; 3], [f64; 3]);

/// A looping Julia morph with an orbiting camera, 24 frames at 4 fps (a 6 s
/// period).
fn looping_morph(keys: &[MorphKey]) -> String {
    let track = |pick: &dyn Fn(&MorphKey) -> [f64; 3]| {
        let keys: Vec<String> = keys
            .iter()
            .map(|k| {
                let [x, y, z] = pick(k);
                format!("(time: {}, value: ({x}, {y}, {z}))", k.0)
            })
            .collect();
        format!("(keys: [{}])", keys.join(", "))
    };
    format!(
        "(fps: 4, frames: 24, size: (48, 27), loop: true,
          scene: (fractal: (iterations: 8, julia: (0.5, 0.5, 0.5))),
          tracks: {{ \"fractal.julia\": {}, \"camera.position\": {} }})",
        track(&|k| k.1),
        track(&|k| k.2)
    )
}

#[test]
fn a_looping_film_has_no_start_a_quarter_period_later_is_the_same_film() {
    let shapes = [
        [0.5, 0.5, 0.5],
        [0.8, -0.4, 0.2],
        [-0.6, -0.2, -0.6],
        [-0.2, 0.7, -0.3],
    ];
    let orbit = [
        [3.1, 0.8, 0.0],
        [0.0, 0.8, 3.1],
        [-3.1, 0.8, 0.0],
        [0.0, 0.8, -3.1],
    ];
    // `a` closes its loop with a key at 6 s equal to the first; `b` starts
    // at `a`'s second key (1.5 s, 6 frames in) and leaves the end key out.
    let mut a: Vec<_> = (0..4)
        .map(|k| (1.5 * k as f64, shapes[k], orbit[k]))
        .collect();
    a.push((6.0, shapes[0], orbit[0]));
    let b: Vec<_> = (0..4)
        .map(|k| (1.5 * k as f64, shapes[(k + 1) % 4], orbit[(k + 1) % 4]))
        .collect();
    let d = Dir::new();
    d.write("a.ron", &looping_morph(&a));
    d.write("b.ron", &looping_morph(&b));
    assert!(stdout(&d.ok(&["info", "a.ron"])).contains("loop:     seamless"));
    // Frame 1 of `a` (0.25 s) lies between its first two keys, where the
    // loop's last key leads in; `b` reaches it at frame 19, between its last
    // key and the end of the period. Frame 23 of `a`, before its end, is
    // `b`'s frame 17.
    d.ok(&["render", "a.ron", "-q", "--frames", "0..2"]);
    d.ok(&["render", "a.ron", "-q", "--frames", "23"]);
    d.ok(&["render", "b.ron", "-q", "--frames", "17"]);
    d.ok(&["render", "b.ron", "-q", "--frames", "19"]);
    let pixels = |f: &str| image::open(d.path().join(f)).unwrap().to_rgb8().into_raw();
    assert_ne!(
        pixels("out/a/frame_00000.png"),
        pixels("out/a/frame_00001.png"),
        "the film moves"
    );
    for (of_a, of_b) in [(1, 19), (23, 17)] {
        assert!(
            pixels(&format!("out/a/frame_{of_a:05}.png"))
                == pixels(&format!("out/b/frame_{of_b:05}.png")),
            "frame {of_a} of a differs from frame {of_b} of b"
        );
    }
}

#[test]
fn a_membership_walk_renders_deeper_and_the_same_on_any_thread_count() {
    // The walk goes on past where the estimate stops, so where both hit,
    // no depth is nearer than the estimate's and some are further; and
    // its frames, like every frame, do not depend on the threads.
    let d = Dir::new();
    d.write("trust.ron", &tiny_timeline(1, 8.0));
    d.write(
        "walk.ron",
        &with_scene(&tiny_timeline(1, 8.0), "quality: (membership_step: 0.25)"),
    );
    let info = stdout(&d.ok(&["info", "walk.ron"]));
    assert!(
        info.contains("membership walk in steps of 0.25 x footprint"),
        "{info}"
    );
    d.same_on_one_and_two_threads("walk.ron", &["--format", "exr"], &["frame_00000.exr"]);
    d.ok(&["render", "trust.ron", "--format", "exr", "--out", "trust"]);
    let (trust, walk) = (d.exr("trust/frame_00000.exr"), d.exr("one/frame_00000.exr"));
    let (a, b) = (trust.channel("depth.Z"), walk.channel("depth.Z"));
    let both: Vec<(f32, f32)> = a
        .iter()
        .zip(b)
        .filter(|(a, b)| **a < 1e9 && **b < 1e9)
        .map(|(a, b)| (*a, *b))
        .collect();
    assert!(both.len() > 100, "{} pixels hit in both", both.len());
    assert!(
        both.iter().all(|(a, b)| b >= a),
        "a walked hit nearer than the estimate's"
    );
    assert!(both.iter().filter(|(a, b)| b > a).count() > both.len() / 2);
}

#[test]
fn pick_aim_writes_the_hit_as_the_target_and_refine_moves_it_onto_the_surface() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 8.0));
    let before = std::fs::read_to_string(d.path().join("t.ron")).unwrap();
    let out = stdout(&d.ok(&["pick", "t.ron", "--pixel", "24,13", "--aim"]));
    let line = out
        .lines()
        .find(|l| l.starts_with("As a zoom target:"))
        .unwrap();
    let target = line.rsplit("target: ").next().unwrap();
    let after = std::fs::read_to_string(d.path().join("t.ron")).unwrap();
    assert!(after.contains(&format!("target: {target}")), "{after}");
    assert_eq!(after.replace(&format!(", target: {target}"), ""), before);
    // The timeline with its new target: the centre pixel hits it.
    let again = stdout(&d.ok(&["pick", "t.ron", "--pixel", "24,13", "--json"]));
    let v: serde_json::Value = serde_json::from_str(&again).unwrap();
    assert_eq!(v["hit"], true);
    // A miss writes nothing and says why.
    let miss = d.run(&["pick", "t.ron", "--pixel", "0,0", "--aim"]);
    assert_eq!(miss.status.code(), Some(1));
    says(&miss, "nothing to aim at");
    assert_eq!(
        std::fs::read_to_string(d.path().join("t.ron")).unwrap(),
        after
    );
    // --refine --aim writes the re-centred target's digits.
    let refined = stdout(&d.ok(&["pick", "t.ron", "--frame", "1", "--refine", "--aim"]));
    assert!(
        refined.contains("Aimed: t.ron now has target: (\""),
        "{refined}"
    );
}

#[test]
fn pick_aim_writes_through_a_link_and_keeps_the_files_permissions() {
    let d = Dir::new();
    let real = d.linked_private_timeline(&tiny_timeline(2, 8.0));
    d.ok(&["pick", "link.ron", "--pixel", "24,13", "--aim"]);
    d.assert_written_through_the_link(&real, "target: (");
}

#[test]
fn pick_refine_settles_the_target_in_one_command() {
    // The README's tutorial: a bud picked on the still, refined at the
    // last frame. One round moves the target far along the view, where
    // the next walk in meets another surface: the command goes round
    // until the target stays put, so a second refine finds nothing to do.
    let d = Dir::new();
    let zoom = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/timelines/zoom.ron"));
    d.write("z.ron", &zoom.unwrap());
    d.ok(&["pick", "z.ron", "--pixel", "100,60", "--aim"]);
    let first = stdout(&d.ok(&["pick", "z.ron", "--frame", "119", "--refine", "--aim"]));
    assert!(first.contains("round 2:"), "{first}");
    let again = stdout(&d.ok(&["pick", "z.ron", "--frame", "119", "--refine", "--json"]));
    let v: serde_json::Value = serde_json::from_str(&again).unwrap();
    assert_eq!(v["round"], 1, "{v}");
    assert!(v["move_pixels"].as_f64().unwrap() < 0.5, "{v}");
}

#[test]
fn pick_refine_on_a_deep_frame_gives_a_rounds_target_and_says_which() {
    // deep_zoom.ron's frame 300: whether a later round settles or stops,
    // the command gives a round's target, and says which.
    let d = deep_zoom_copy();
    let out = stdout(&d.ok(&["pick", "deep.ron", "--frame", "300", "--refine"]));
    assert!(
        out.contains("Re-centred for frame 300:  target: (\""),
        "{out}"
    );
    let stopped = out
        .lines()
        .any(|l| l.starts_with("note: round ") && l.contains("stopped"));
    let settled = out
        .lines()
        .any(|l| l.starts_with("round ") && !l.contains("note"));
    assert!(stopped || settled, "{out}");
}

#[test]
fn pick_refine_puts_the_deepest_frame_of_the_dive_on_the_surface() {
    // deep_zoom.ron's own recipe, at 1e-30: each step's camera stays clear
    // of where the last step placed the target, a ray grazing the tip is
    // not carried into the set far beyond it, and `iterations: Auto`
    // follows the target as the frame's own count will.
    let d = deep_zoom_copy();
    let refine = ["pick", "deep.ron", "--frame", "539", "--refine", "--aim"];
    let out = stdout(&d.ok(&refine));
    assert!(out.contains("Aimed: deep.ron now has target: (\""), "{out}");
    assert!(out.contains("check: on the surface"), "{out}");
    // The ray through the middle of the aimed frame (a pixel's centre at an
    // odd size) meets the surface at the camera's distance from the target.
    let centre = ["--pixel", "160,90", "--size", "321x181", "--json"];
    let pick = stdout(&d.ok(&[&["pick", "deep.ron", "--frame", "539"][..], &centre].concat()));
    let report: serde_json::Value = serde_json::from_str(&pick).unwrap();
    let (distance, footprint) = (
        report["distance"].as_f64().expect("the centre ray hits"),
        report["pixel_footprint"].as_f64().unwrap(),
    );
    assert!(
        (distance - 1e-30).abs() < 8.0 * footprint,
        "hit {distance:e} from a camera 1e-30 away (footprint {footprint:e})"
    );
}

/// A folder holding a copy of timelines/deep_zoom.ron as deep.ron.
fn deep_zoom_copy() -> Dir {
    let d = Dir::new();
    let deep = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/timelines/deep_zoom.ron"
    ));
    d.write("deep.ron", &deep.unwrap());
    d
}
