//! EXR frames as compositors and other tools read them: premultiplied
//! alpha laid over a plate by oiiotool, depth under a name every reader
//! takes, and each compression read back by OpenEXR's own tools.

use crate::util::{tiny_timeline, tool, with_scene, Dir};
use std::process::Command;

/// A 48×27 frame with four samples a pixel (so edges are partly
/// covered), its background transparent or not.
fn frame(transparent: bool) -> String {
    let look = format!("samples_per_pixel: 4, look: (transparent_background: {transparent})");
    with_scene(&tiny_timeline(1, 8.0), &look)
}

/// Runs `program` with `args` in `d`, failing the test unless it succeeds;
/// returns its stdout and stderr.
fn run_tool(d: &Dir, program: &str, args: &[&str]) -> (String, String) {
    let out = Command::new(program)
        .args(args)
        .current_dir(d.path())
        .output()
        .unwrap_or_else(|e| panic!("{program}: {e}"));
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    assert!(
        out.status.success(),
        "{program} {args:?}: {}",
        text(&out.stderr)
    );
    (text(&out.stdout), text(&out.stderr))
}

#[test]
fn oiiotool_lays_a_transparent_frame_over_a_plate_as_premultiplied() {
    if !tool("oiiotool", "--help") {
        return;
    }
    let d = Dir::new();
    d.write("t.ron", &frame(true));
    d.ok(&["render", "t.ron", "--format", "exr"]);
    let plate = [0.2f32, 0.5, 0.8];
    let pattern = format!("constant:color={},{},{},1", plate[0], plate[1], plate[2]);
    run_tool(
        &d,
        "oiiotool",
        &[
            "out/t/frame_00000.exr",
            "--ch",
            "R,G,B,A",
            "--pattern",
            &pattern,
            "48x27",
            "4",
            "--over",
            "-d",
            "float",
            "-o",
            "comp.exr",
        ],
    );
    let (fg, comp) = (d.exr("out/t/frame_00000.exr"), d.exr("comp.exr"));
    let alpha = fg.channel("A");
    assert_eq!(alpha[0], 0.0, "a corner sees background");
    let partial = alpha.iter().filter(|&&a| a > 0.0 && a < 1.0).count();
    assert!(partial > 10, "{partial} partly covered pixels");
    // Over: the frame's colour plus the plate where the frame lets it through.
    for (k, name) in ["R", "G", "B"].into_iter().enumerate() {
        let (f, c) = (fg.channel(name), comp.channel(name));
        for i in 0..alpha.len() {
            let expected = f[i] + (1.0 - alpha[i]) * plate[k];
            let tolerance = 2e-3 * expected.abs().max(1.0);
            assert!(
                (c[i] - expected).abs() < tolerance,
                "{name} at pixel {i}: {} over the plate is {}, not {expected}",
                f[i],
                c[i]
            );
        }
        // Where the frame shows background, the plate alone.
        assert!((c[0] - plate[k]).abs() < 1e-3, "{name}: {}", c[0]);
    }
}

#[test]
fn an_opaque_frame_covers_the_plate_and_keeps_its_background() {
    let d = Dir::new();
    d.write("opaque.ron", &frame(false));
    d.write("clear.ron", &frame(true));
    d.ok(&["render", "opaque.ron", "--format", "exr"]);
    d.ok(&["render", "clear.ron", "--format", "exr"]);
    let (opaque, clear) = (
        d.exr("out/opaque/frame_00000.exr"),
        d.exr("out/clear/frame_00000.exr"),
    );
    assert!(opaque.channel("A").iter().all(|&a| a == 1.0));
    // The background is drawn into the opaque frame's colour and left out
    // of the transparent one's, which where the bulb covers a pixel whole
    // is the same.
    let (a, r_opaque, r_clear) = (clear.channel("A"), opaque.channel("R"), clear.channel("R"));
    assert!(
        r_opaque[0] > 0.0 && r_clear[0] == 0.0,
        "{} {}",
        r_opaque[0],
        r_clear[0]
    );
    let whole: Vec<usize> = (0..a.len()).filter(|&i| a[i] == 1.0).collect();
    assert!(whole.len() > 100);
    assert!(whole.iter().all(|&i| r_opaque[i] == r_clear[i]));
}

#[test]
fn depth_reads_without_complaint_in_exrheader_oiiotool_and_ffmpeg() {
    if !tool("exrheader", "--help") || !tool("oiiotool", "--help") || !tool("ffmpeg", "-version") {
        return;
    }
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 7.0));
    d.ok(&["render", "t.ron", "--format", "exr"]);
    let (header, _) = run_tool(&d, "exrheader", &["out/t/frame_00000.exr"]);
    assert!(
        header.contains("depth.Z, 32-bit floating-point"),
        "{header}"
    );
    let (info, _) = run_tool(&d, "oiiotool", &["--info", "-v", "out/t/frame_00000.exr"]);
    assert!(
        info.contains("R (half), G (half), B (half), A (half), depth.Z (float)"),
        "{info}"
    );
    // ffmpeg takes a bare Z for a third colour channel and says so on
    // every frame; it passes over depth.Z.
    let args = [
        "-v",
        "warning",
        "-i",
        "out/t/frame_%05d.exr",
        "-f",
        "null",
        "-",
    ];
    let (_, said) = run_tool(&d, "ffmpeg", &args);
    assert!(!said.contains("Multiple channels"), "{said}");
}

#[test]
fn every_exr_compression_reads_back_in_openexr_and_oiiotool() {
    if !tool("exrheader", "--help") || !tool("oiiotool", "--help") {
        return;
    }
    let d = Dir::new();
    d.write("t.ron", &frame(true));
    let cases = [
        ("none", "none", true),
        ("rle", "run-length encoding", true),
        ("zips", "zip, individual scanlines", true),
        ("zip", "zip, multi-scanline blocks", true),
        ("piz", "piz", true),
        ("pxr24", "pxr24", false),
        ("b44", "b44", false),
        ("b44a", "b44a", false),
        ("dwaa", "dwa, small scanline blocks", false),
        ("dwab", "dwa, medium scanline blocks", false),
    ];
    let mut reference: Option<Vec<f32>> = None;
    for (name, described, lossless) in cases {
        let out = format!("c_{name}");
        let args = [
            "render",
            "t.ron",
            "--format",
            "exr",
            "--exr-compression",
            name,
        ];
        d.ok(&[&args[..], &["--out", &out]].concat());
        let file = format!("{out}/frame_00000.exr");
        let (header, _) = run_tool(&d, "exrheader", &[&file]);
        let expected = format!("compression (type compression): {described}\n");
        assert!(header.contains(&expected), "{name}: {header}");
        // oiiotool decodes every pixel: it fails on a damaged block.
        run_tool(&d, "oiiotool", &[&file, "--printstats"]);
        let red = d.exr(&file).channel("R").to_vec();
        let reference = reference.get_or_insert_with(|| red.clone());
        let squares: f32 = red
            .iter()
            .zip(reference.iter())
            .map(|(a, b)| (a - b) * (a - b))
            .sum();
        let rms = (squares / red.len() as f32).sqrt();
        if lossless {
            assert_eq!(rms, 0.0, "{name} is lossless");
        } else {
            // B44's 4×4 blocks blur this tiny frame's sharp edges most: 0.014.
            assert!(rms < 0.03, "{name}: rms error {rms}");
        }
    }
}

#[test]
fn glow_around_a_transparent_frame_is_light_without_coverage() {
    let d = Dir::new();
    let glow = "effects: (glow: (colour: (0.9, 0.6, 0.3), strength: 0.6, width: 4))";
    d.write("t.ron", &with_scene(&frame(true), glow));
    d.ok(&["render", "t.ron", "--format", "exr,png16alpha"]);
    let exr = d.exr("out/t/frame_00000.exr");
    let (alpha, red) = (exr.channel("A"), exr.channel("R"));
    // Where glow falls on a partly covered pixel, its straight colour in
    // the PNG keeps the glow's hue (red over blue), not clipped to white.
    let png = image::open(d.path().join("out/t/frame_00000.png"))
        .unwrap()
        .to_rgba16();
    let blue = exr.channel("B");
    let edges =
        (0..alpha.len()).filter(|&i| alpha[i] > 0.0 && alpha[i] < 0.5 && red[i] > 2.0 * blue[i]);
    let (mut seen, mut white) = (0, 0);
    for i in edges {
        let p = png.get_pixel(i as u32 % 48, i as u32 / 48);
        seen += 1;
        white += (p[2] > 60000) as usize;
        assert!(
            p[0] > p[2],
            "pixel {i}: straight {:?} lost the glow's hue",
            p.0
        );
    }
    assert!(
        seen > 0 && white == 0,
        "{seen} glowing edge pixels, {white} white"
    );
    // Misses near the bulb carry the glow, with alpha 0: "over" adds it.
    let glowing = (0..alpha.len())
        .filter(|&i| alpha[i] == 0.0 && red[i] > 0.0)
        .count();
    assert!(glowing > 10, "{glowing} glowing pixels with no coverage");
}

#[test]
fn every_new_kind_of_file_is_the_same_on_any_thread_count() {
    let d = Dir::new();
    d.write("t.ron", &frame(true));
    for (format, compression) in [("png16alpha,exr", "piz"), ("png16,exr", "dwaa")] {
        let extra = [
            "--format",
            format,
            "--exr-compression",
            compression,
            "--force",
        ];
        let files = ["frame_00000.png", "frame_00000.exr"];
        d.same_on_one_and_two_threads("t.ron", &extra, &files);
    }
    // The dithered 8-bit PNG too, at a size whose rows split unevenly.
    d.write("wide.ron", &frame(false).replace("(48, 27)", "(203, 77)"));
    d.same_on_one_and_two_threads("wide.ron", &["--replace"], &["frame_00000.png"]);
}

#[test]
fn a_lossy_compression_is_part_of_an_exr_and_a_lossless_one_is_not() {
    let d = Dir::new();
    d.write("t.ron", &frame(true));
    d.ok(&["render", "t.ron", "--format", "exr", "--out", "c_zip"]);
    // A lossy compression is part of what a file records: another
    // re-renders it; lossless ones hold the same samples and do not.
    let again = |compression: &str| {
        let args = ["render", "t.ron", "--format", "exr", "--out", "c_zip"];
        let out = d.ok(&[&args[..], &["--exr-compression", compression]].concat());
        crate::util::stderr(&out).contains("already complete")
    };
    assert!(again("piz"), "a lossless change keeps the frame");
    assert!(!again("dwaa"), "a lossy one re-renders it");
}
