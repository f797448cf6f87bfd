//! docs/tools/gallery.sh, which made docs/gallery.md's pictures, run as
//! written at a small size: every film's four frames rendered and timed,
//! a JPEG of each, a strip of each film's four.

use crate::util::{tool, Dir};
use std::process::Command;

#[test]
fn the_gallery_script_renders_times_and_strips_every_example() {
    if !tool("ffmpeg", "-version") {
        return;
    }
    let d = Dir::new();
    let root = env!("CARGO_MANIFEST_DIR");
    let out = Command::new("sh")
        .arg(format!("{root}/docs/tools/gallery.sh"))
        .arg("32x18")
        .current_dir(root)
        .env("MANDELREEL", env!("CARGO_BIN_EXE_mandelreel"))
        .env("GALLERY_OUT", d.path().join("frames"))
        .env("GALLERY_DOCS", d.path().join("docs"))
        .output()
        .expect("sh runs");
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{table}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows: Vec<&str> = table
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| film"))
        .collect();
    assert_eq!(rows.len(), 16, "{table}");
    for film in ["zoom", "julia_morph", "deep_zoom", "quaternion"] {
        let strip = image::open(d.path().join(format!("docs/{film}_strip.png"))).expect("a strip");
        // Four frames of 32x18 side by side, each shown 640 wide.
        assert_eq!(strip.height(), 360, "{film}");
        assert!((4 * 640..4 * 650).contains(&strip.width()), "{film}");
        let jpegs = std::fs::read_dir(d.path().join("docs"))
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| {
                let name = e.file_name().to_string_lossy().into_owned();
                name.starts_with(&format!("{film}_")) && name.ends_with(".jpg")
            })
            .count();
        assert_eq!(jpegs, 4, "{film}");
        assert!(
            rows.iter()
                .filter(|r| r.starts_with(&format!("| {film} |")))
                .count()
                == 4
        );
    }
}
