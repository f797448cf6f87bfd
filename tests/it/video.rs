//! The MP4 that the printed ffmpeg command makes: its colour tags as
//! ffprobe reads them, and its colours decoded back against the frames'.

use crate::util::{ffmpeg_installed, stdout, tiny_timeline, with_scene, Dir};
use std::process::Command;

/// A tiny film in greens: a saturated hue is where the BT.601 and BT.709
/// matrices differ most, and one hue keeps their errors from cancelling
/// in a frame's mean. Its 27 rows are padded to 28 for yuv420p.
fn green_film() -> String {
    with_scene(
        &tiny_timeline(2, 7.0),
        "look: (background_top: (0.05, 0.5, 0.06), background_bottom: (0.04, 0.3, 0.05), \
         base_colour: (0.1, 0.6, 0.1))",
    )
}

/// The colour fields of the first stream of `mp4`, as ffprobe names them.
fn colour_tags(d: &Dir, mp4: &str) -> Vec<String> {
    let out = Command::new("ffprobe")
        .args([
            "-v",
            "error",
            "-select_streams",
            "v:0",
            "-show_streams",
            mp4,
        ])
        .current_dir(d.path())
        .output()
        .expect("run ffprobe");
    let fields = [
        "color_space",
        "color_primaries",
        "color_transfer",
        "color_range",
    ];
    let text = stdout(&out);
    let mut tags: Vec<String> = text
        .lines()
        .filter(|l| fields.iter().any(|f| l.starts_with(&format!("{f}="))))
        .map(str::to_string)
        .collect();
    tags.sort();
    tags
}

/// The first frame of `mp4` as RGB, decoded with the matrix and range its
/// tags say (given, not left to ffmpeg's defaults, which have changed).
fn decoded_rgb(d: &Dir, mp4: &str) -> Vec<u8> {
    let out = Command::new("ffmpeg")
        .args(["-loglevel", "error", "-i", mp4, "-frames:v", "1"])
        .args(["-vf", "scale=in_color_matrix=bt709:in_range=tv"])
        .args(["-f", "rawvideo", "-pix_fmt", "rgb24", "-"])
        .current_dir(d.path())
        .output()
        .expect("run ffmpeg");
    assert!(out.status.success(), "{}", crate::util::stderr(&out));
    out.stdout
}

/// Mean of each channel over the first `rows` rows of `width`-wide RGB.
fn mean_rgb(rgb: &[u8], width: usize, rows: usize) -> [f64; 3] {
    let mut sum = [0.0; 3];
    for pixel in rgb[..width * rows * 3].chunks_exact(3) {
        for (s, &v) in sum.iter_mut().zip(pixel) {
            *s += f64::from(v);
        }
    }
    sum.map(|s| s / (width * rows) as f64)
}

#[test]
fn the_printed_command_converts_and_tags_the_video_as_bt709() {
    // ffmpeg's default RGB-to-YUV matrix is BT.601, with no tags: decoded
    // as BT.709, that frame's greens came out 14 code values darker, and
    // ffprobe read every tag as `unknown`. Both the PNG and the EXR
    // commands are run; the EXR's applies the sRGB curve itself.
    let d = Dir::new();
    d.write("t.ron", &green_film());
    let png_command = stdout(&d.ok(&["render", "t.ron", "--quiet"]));
    let exr_command = stdout(&d.ok(&["render", "t.ron", "--quiet", "--format", "exr"]));
    if !ffmpeg_installed() {
        return;
    }
    let frame = image::open(d.path().join("out/t/frame_00000.png")).unwrap();
    let (width, height) = (frame.width() as usize, frame.height() as usize);
    let want = mean_rgb(frame.to_rgb8().as_raw(), width, height);
    for command in [png_command, exr_command] {
        d.run_printed(&command);
        let tags = colour_tags(&d, "out/t/t.mp4");
        assert_eq!(
            tags,
            [
                "color_primaries=bt709",
                "color_range=tv",
                "color_space=bt709",
                "color_transfer=iec61966-2-1"
            ],
            "{command}"
        );
        let got = mean_rgb(&decoded_rgb(&d, "out/t/t.mp4"), width, height);
        let off = (0..3).map(|c| (got[c] - want[c]).abs()).fold(0.0, f64::max);
        assert!(off < 3.0, "{got:?} against the PNG's {want:?}: {command}");
    }
}
