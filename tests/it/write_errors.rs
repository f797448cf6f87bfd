//! A frame that cannot be written (a full disk, a file-size limit, an I/O
//! error): the error names the frame's own file and the system's reason,
//! the render exits 1, and no temporary file is left behind.
//!
//! A full disk needs a mount (farm.rs's `a_full_disk_fails_clearly…`);
//! here a file-size limit (`ulimit -f`) makes every write past it fail
//! with EFBIG on any machine, root or not, without one. The program itself
//! keeps SIGXFSZ from killing it (`interrupt::survive_file_size_limit`): the
//! shell here leaves the signal's default action in place.

use crate::util::{stderr, Dir};
use std::process::Command;

/// Every file under `dir`, at any depth.
fn all_files(dir: &std::path::Path) -> Vec<String> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    entries
        .flat_map(|e| {
            let path = e.unwrap().path();
            let mut below = all_files(&path);
            below.push(path.to_string_lossy().into_owned());
            below
        })
        .collect()
}

/// `mandelreel args` in `d` with files limited to 16 blocks (8 KiB in
/// dash's 512-byte blocks, 16 KiB in bash's): room for the job's record,
/// not for a 320×180 frame.
fn render_with_small_files(d: &Dir, args: &[&str]) -> std::process::Output {
    Command::new("sh")
        .current_dir(d.path())
        .arg("-c")
        .arg("ulimit -f 16 && exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_mandelreel"))
        .args(args)
        .output()
        .expect("run sh")
}

#[test]
fn a_frame_that_cannot_be_written_is_named_by_its_own_file() {
    let d = Dir::new();
    let timeline = "(fps: 24, frames: 2, size: (320, 180),
        scene: (camera: (position: (0, 0.5, 3.0)), fractal: (iterations: 8)))";
    d.write("t.ron", timeline);
    for (format, file) in [("exr", "frame_00000.exr"), ("png", "frame_00000.png")] {
        let out = render_with_small_files(&d, &["render", "t.ron", "--format", format, "--quiet"]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{format}: {err}");
        let named = format!("out/t/{file}: File too large");
        assert!(err.contains(&named), "{format}: {err}");
        assert!(!err.contains(".partial"), "{format}: {err}");
        let left: Vec<String> = all_files(d.path())
            .into_iter()
            .filter(|f| f.ends_with(".partial"))
            .collect();
        assert!(left.is_empty(), "{format}: {left:?}");
    }
}
