//! `fractal.iterations: Auto` through the binary: `info` lists the counts,
//! a frame renders as it does with the count Auto chose, and the same on
//! any number of threads.

use crate::util::{stdout, Dir};

/// A zoom from the whole bulb to a point on its pole, 64×36, with `Auto`.
pub(super) const ZOOM: &str = "(
    fps: 24,
    frames: 3,
    size: (64, 36),
    scene: (
        camera: (position: (0.0, 0.66, 3.0), target: (0.0, 0.66, 0.0)),
        fractal: (iterations: Auto(margin: 1)),
    ),
    tracks: {
        \"camera.distance\": (keys: [(time: 0, value: 3.0), (time: 0.1, value: 0.01)]),
    },
)";

/// The counts `info` prints for frames 0..=2 (`frames A..=B: N (…)` lines).
pub(super) fn counts(info: &str) -> Vec<u32> {
    let mut counts = Vec::new();
    for line in info.lines() {
        let Some(rest) = line.strip_prefix("          frame") else {
            continue;
        };
        let (frames, count) = rest.split_once(": ").expect("frames: count");
        let frames = frames.trim_start_matches('s').trim();
        let (a, b) = frames.split_once("..=").unwrap_or((frames, frames));
        let n: u32 = count.split(' ').next().unwrap().parse().unwrap();
        for _ in a.parse::<u32>().unwrap()..=b.parse::<u32>().unwrap() {
            counts.push(n);
        }
    }
    counts
}

#[test]
fn info_lists_each_frames_auto_count() {
    let dir = Dir::new();
    let path = dir.write("zoom.ron", ZOOM);
    let info = stdout(&dir.ok(&["info", path.to_str().unwrap()]));
    assert!(info.contains("iterations: Auto, margin 1: "), "{info}");
    let counts = counts(&info);
    assert_eq!(counts.len(), 3, "{info}");
    assert!(counts[2] > counts[0], "{info}");
    assert!(info.contains("(target)"), "{info}");
}

#[test]
fn a_frame_renders_with_auto_as_with_the_count_it_chose() {
    let dir = Dir::new();
    let path = dir.write("zoom.ron", ZOOM);
    let info = stdout(&dir.ok(&["info", path.to_str().unwrap()]));
    let chosen = counts(&info)[2];
    let fixed = ZOOM.replace("Auto(margin: 1)", &chosen.to_string());
    dir.write("fixed.ron", &fixed);
    for (timeline, out) in [("zoom.ron", "auto"), ("fixed.ron", "fixed")] {
        dir.ok(&["render", timeline, "--frames", "2", "--out", out, "--quiet"]);
    }
    let name = "frame_00002.png";
    assert!(dir.bytes(&format!("auto/{name}")) == dir.bytes(&format!("fixed/{name}")));
}

#[test]
fn auto_frames_are_the_same_on_one_and_two_threads() {
    let dir = Dir::new();
    dir.write("zoom.ron", ZOOM);
    let files = ["frame_00000.png", "frame_00001.png", "frame_00002.png"];
    dir.same_on_one_and_two_threads("zoom.ron", &["--quiet"], &files);
}
