//! Resume: complete frames are skipped, stale or partial ones re-rendered, and a
//! render killed mid-way leaves no damaged frame and finishes identically.

use crate::util::{
    long_frames, render_until_a_checkpoint, says, stderr, tiny_timeline, with_scene, Dir,
};
use std::time::{Duration, Instant};

fn mtimes(d: &Dir, sub: &str) -> Vec<std::time::SystemTime> {
    d.files(sub)
        .iter()
        .filter(|f| f.starts_with("frame_"))
        .map(|f| {
            std::fs::metadata(d.path().join(sub).join(f))
                .unwrap()
                .modified()
                .unwrap()
        })
        .collect()
}

#[test]
fn second_run_skips_complete_frames() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(3, 6.0));
    d.ok(&["render", "t.ron"]);
    let before = mtimes(&d, "out/t");
    let first = d.bytes("out/t/frame_00001.png");
    std::thread::sleep(Duration::from_millis(20));
    let out = d.ok(&["render", "t.ron"]);
    says(&out, "3 of 3 frames already complete");
    assert_eq!(
        mtimes(&d, "out/t"),
        before,
        "skipped frames must not be rewritten"
    );
    // --force renders them again, to the same bytes.
    let out = d.ok(&["render", "t.ron", "--force"]);
    says(&out, "3 frames rendered");
    assert_ne!(mtimes(&d, "out/t"), before);
    assert!(d.bytes("out/t/frame_00001.png") == first, "frame changed");
}

#[test]
fn changed_timeline_rerenders_only_what_changed() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(3, 6.0));
    d.ok(&["render", "t.ron"]);
    let old = d.bytes("out/t/frame_00002.png");
    let frame0 = d.bytes("out/t/frame_00000.png");
    // Frame 0 sits on the first key (power 8) either way; frames 1 and 2 change.
    d.write("t.ron", &tiny_timeline(3, 4.0));
    let out = d.ok(&["render", "t.ron"]);
    says(&out, "1 of 3 frames already complete");
    assert!(d.bytes("out/t/frame_00002.png") != old, "frame unchanged");
    assert!(d.bytes("out/t/frame_00000.png") == frame0, "frame changed");
    // A different size is a different sequence: refused, since it would
    // replace the folder's frames, unless --force asks for that.
    let before = d.bytes("out/t/frame_00002.png");
    let out = d.run(&["render", "t.ron", "--size", "40x20"]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("3 frame file(s) of t.ron at 48x27"), "{err}");
    assert!(err.contains("rendering t.ron at 40x20"), "{err}");
    assert!(d.bytes("out/t/frame_00002.png") == before, "frame replaced");
    let out = d.ok(&["render", "t.ron", "--size", "40x20", "--force"]);
    says(&out, "3 frames rendered");
    assert!(d.bytes("out/t/frame_00002.png") != before, "frame kept");
}

#[test]
fn another_timeline_is_not_rendered_over_a_folders_frames() {
    // `render other.ron --out out/t` over t.ron's finished frames: refused,
    // nothing touched, the job record still t.ron's; --force replaces them.
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 6.0));
    d.write("other.ron", &tiny_timeline(2, 4.0));
    d.ok(&["render", "t.ron"]);
    let (frame, record) = (
        d.bytes("out/t/frame_00001.png"),
        d.bytes("out/t/mandelreel-job.json"),
    );
    let out = d.run(&["render", "other.ron", "--out", "out/t"]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("of t.ron at 48x27") && err.contains("--replace"),
        "{err}"
    );
    assert!(d.bytes("out/t/frame_00001.png") == frame);
    assert!(d.bytes("out/t/mandelreel-job.json") == record);
    // An empty folder, or one with only another sequence's record, is free.
    d.ok(&["render", "other.ron", "--out", "out/o"]);
    std::fs::remove_file(d.path().join("out/o/frame_00000.png")).unwrap();
    std::fs::remove_file(d.path().join("out/o/frame_00001.png")).unwrap();
    d.ok(&["render", "t.ron", "--out", "out/o"]);
    // --replace renders what is not current for other.ron: frame 1 (both
    // timelines' frame 0 is the power-8 bulb, current as it stands).
    let out = d.ok(&["render", "other.ron", "--out", "out/t", "--replace"]);
    says(&out, "1 of 2 frames already complete");
    assert!(d.bytes("out/t/frame_00001.png") != frame);
    let out = d.ok(&["render", "other.ron", "--out", "out/t", "--replace"]);
    says(&out, "2 of 2 frames already complete");
}

#[test]
fn another_sequence_is_refused_while_a_render_still_works_on_its_first_frame() {
    // No frame is finished yet, but the folder's render is running: a
    // render of another size would take the record over and write the
    // same frame names.
    let d = Dir::new();
    d.write("t.ron", &long_frames(1));
    let mut child = render_until_a_checkpoint(&d);
    assert!(!d.files("out/t").iter().any(|f| f.ends_with(".png")));
    let record = d.bytes("out/t/mandelreel-job.json");
    let out = d.run(&["render", "t.ron", "--size", "40x20"]);
    child.kill().unwrap();
    child.wait().unwrap();
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("holds 0 frame file(s) of t.ron at 120x68")
            && err.contains("and 1 render(s) of it still running"),
        "{err}"
    );
    assert!(
        d.bytes("out/t/mandelreel-job.json") == record,
        "record rewritten"
    );
}

#[test]
fn stale_temporary_and_foreign_files_are_not_taken_for_frames() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 6.0));
    std::fs::create_dir_all(d.path().join("out/t")).unwrap();
    // Left by a killed run an hour ago: a half-written temporary.
    let stale = d.write("out/t/.frame_00000.png.x1y2z3.partial", "half a frame");
    let hour_ago = std::time::SystemTime::now() - Duration::from_secs(3600);
    std::fs::File::options()
        .write(true)
        .open(&stale)
        .unwrap()
        .set_modified(hour_ago)
        .unwrap();
    // A fresh one may belong to a render running beside this one: kept.
    d.write("out/t/.frame_00001.png.a1b2c3.partial", "being written");
    // And garbage under a final name.
    d.write("out/t/frame_00001.png", "not a png");
    let out = d.ok(&["render", "t.ron"]);
    let err = stderr(&out);
    assert!(!err.contains("already complete"), "{err}");
    assert!(err.contains("removed 1 temporary file"), "{err}");
    assert_eq!(
        d.files("out/t"),
        [
            ".frame_00001.png.a1b2c3.partial",
            ".mandelreel-job.lock",
            "frame_00000.png",
            "frame_00001.png",
            "mandelreel-job.json"
        ]
    );
    for f in ["frame_00000.png", "frame_00001.png"] {
        image::open(d.path().join("out/t").join(f)).unwrap();
    }
}

#[test]
fn killed_render_resumes_to_identical_frames() {
    let d = Dir::new();
    // Enough work per frame that the kill lands mid-sequence.
    let text = tiny_timeline(12, 6.0).replace("size: (48, 27)", "size: (160, 90)");
    d.write("t.ron", &text);
    let mut child = d
        .command(&["render", "t.ron", "--quiet", "--threads", "1"])
        .spawn()
        .unwrap();
    let start = Instant::now();
    while d
        .files("out/t")
        .iter()
        .filter(|f| f.starts_with("frame_"))
        .count()
        < 2
    {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no frames appeared"
        );
        if child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap(); // SIGKILL on Unix: no chance to clean up
    child.wait().unwrap();
    // Every file under a final name is a whole frame.
    for f in d.files("out/t").iter().filter(|f| f.starts_with("frame_")) {
        image::open(d.path().join("out/t").join(f))
            .unwrap_or_else(|e| panic!("{f} is damaged: {e}"));
    }
    let done_before = d
        .files("out/t")
        .iter()
        .filter(|f| f.starts_with("frame_"))
        .count();
    assert!(
        done_before < 12,
        "the render finished before it could be killed"
    );
    let out = d.ok(&["render", "t.ron"]);
    says(
        &out,
        &format!("{done_before} of 12 frames already complete"),
    );
    let finals: Vec<String> = d
        .files("out/t")
        .into_iter()
        .filter(|f| f.starts_with("frame_"))
        .collect();
    assert_eq!(finals.len(), 12);
    // The resumed sequence equals an uninterrupted render.
    d.ok(&["render", "t.ron", "--out", "clean"]);
    for f in finals {
        assert!(
            d.bytes(&format!("out/t/{f}")) == d.bytes(&format!("clean/{f}")),
            "frame {f} differs"
        );
    }
}

#[test]
fn a_long_frame_killed_mid_way_resumes_from_its_checkpoint_identically() {
    let d = Dir::new();
    let text = long_frames(1);
    d.write("t.ron", &text);
    d.ok(&["render", "t.ron", "--out", "clean", "--quiet"]);
    let mut child = render_until_a_checkpoint(&d);
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(
        !d.files("out/t").contains(&"frame_00000.png".to_string()),
        "killed before the end"
    );
    // `status` counts the frame resumable, but not against other inputs,
    // for which the checkpoint is no use.
    let status = |timeline: &str| d.status_json(&[timeline, "--out", "out/t"]).1;
    assert_eq!(
        status("t.ron")["states"]["resumable"],
        serde_json::json!([0])
    );
    d.write("t2.ron", &text.replace("iterations: 8", "iterations: 7"));
    assert_eq!(
        status("t2.ron")["states"]["missing"],
        serde_json::json!([0])
    );
    let out = d.ok(&["render", "t.ron"]);
    says(&out, "resuming from a checkpoint at");
    assert!(
        d.bytes("out/t/frame_00000.png") == d.bytes("clean/frame_00000.png"),
        "the resumed frame differs from the uninterrupted one"
    );
    assert!(
        !d.files("out/t").iter().any(|f| f.ends_with(".ckpt")),
        "checkpoint left behind"
    );
}

#[test]
fn frames_cut_short_or_damaged_are_rendered_again() {
    // A frame file whose bytes are not all there (a copy cut short, a full
    // disk) or that has bytes after its end is not taken for a finished
    // frame, though its header carries the current hash; a damaged byte
    // inside a PNG is found by --verify, which reads every byte.
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(3, 6.0));
    let args = ["render", "t.ron", "--format", "png,exr", "--quiet"];
    d.ok(&args);
    let clean = |f: &str| d.bytes(&format!("out/t/{f}"));
    let (exr, png) = (clean("frame_00001.exr"), clean("frame_00002.png"));
    let states = |extra: &[&str]| -> serde_json::Value {
        let (code, v) = d.status_json(&[&["out/t"][..], extra].concat());
        assert_eq!(code, Some(4), "{v}");
        v["states"].clone()
    };
    // The EXR cut to half its length; one byte flipped in the PNG's image data.
    d.write_bytes("out/t/frame_00001.exr", &exr[..exr.len() / 2]);
    let mut flipped = png.clone();
    flipped[png.len() / 2] ^= 0x10;
    d.write_bytes("out/t/frame_00002.png", &flipped);
    assert_eq!(states(&[])["damaged"], serde_json::json!([1]));
    assert_eq!(states(&["--verify"])["damaged"], serde_json::json!([1, 2]));
    let out = d.ok(&["render", "t.ron", "--format", "png,exr"]);
    says(&out, "2 of 3 frames already complete");
    assert!(clean("frame_00001.exr") == exr, "EXR not rendered again");
    let out = d.ok(&["render", "t.ron", "--format", "png,exr", "--verify"]);
    says(&out, "2 of 3 frames already complete");
    assert!(clean("frame_00002.png") == png, "PNG not rendered again");
    // Bytes after a whole file's end are damage too.
    let mut longer = exr.clone();
    longer.extend_from_slice(b"tail");
    d.write_bytes("out/t/frame_00001.exr", &longer);
    let mut longer = png.clone();
    longer.extend_from_slice(b"tail");
    d.write_bytes("out/t/frame_00002.png", &longer);
    assert_eq!(states(&[])["damaged"], serde_json::json!([1, 2]));
    // A whole PNG that mandelreel did not make is another input's: stale.
    d.write_bytes("out/t/frame_00001.exr", &exr);
    d.write_bytes("out/t/frame_00002.png", &png);
    image::RgbImage::new(48, 27)
        .save(d.path().join("out/t/frame_00000.png"))
        .unwrap();
    assert_eq!(states(&[])["stale"], serde_json::json!([0]));
}

#[test]
fn a_checkpoint_that_cannot_be_saved_warns_and_the_frame_goes_on() {
    // A full disk (here, a folder in the checkpoint's place) must not end a
    // render whose frames still fit.
    let d = Dir::new();
    let text = with_scene(&tiny_timeline(1, 8.0), "samples_per_pixel: 16");
    d.write("t.ron", &text);
    d.ok(&["render", "t.ron", "--out", "clean", "--quiet"]);
    std::fs::create_dir_all(d.path().join("out/t/.frame_00000.ckpt")).unwrap();
    let out = d.ok(&["render", "t.ron", "--checkpoint-seconds", "0", "--quiet"]);
    says(&out, "warning: frame 0: could not save a checkpoint");
    assert_eq!(
        stderr(&out).matches("could not save").count(),
        1,
        "one warning a frame: {}",
        stderr(&out)
    );
    assert!(d.bytes("out/t/frame_00000.png") == d.bytes("clean/frame_00000.png"));
}

#[test]
fn status_lists_a_running_render_and_forgets_a_killed_one() {
    // A plain render (no claims) is listed as running while it runs, and
    // not once it has been killed; the next render clears its record.
    let d = Dir::new();
    d.write("t.ron", &long_frames(1));
    let running = |d: &Dir| -> Vec<String> {
        serde_json::from_value(d.status_json(&["t.ron"]).1["workers"].clone()).unwrap()
    };
    let mut child = render_until_a_checkpoint(&d);
    let me = format!(":{}", child.id());
    let seen = running(&d);
    // A second plain render on the folder is warned that the work doubles
    // (one sample a pixel: done long before the first).
    let out = d.ok(&["render", "t.ron", "--samples", "1", "--quiet"]);
    says(&out, "warning: another render is running on out/t");
    says(&out, &me);
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(seen.iter().any(|w| w.ends_with(&me)), "{seen:?} lacks {me}");
    assert!(running(&d).is_empty(), "a killed render is not running");
    let records = |d: &Dir| {
        let files = d.files("out/t");
        files
            .into_iter()
            .filter(|f| f.starts_with(".mandelreel-run-"))
            .count()
    };
    assert_eq!(
        records(&d),
        1,
        "the killed render's record stays until the next"
    );
    d.ok(&["render", "t.ron", "--quiet"]);
    assert_eq!(records(&d), 0, "the next render clears it, and its own");
}

/// Sends `signal` to the running `child` and waits for it: its stderr and
/// exit status.
pub fn interrupt(
    child: std::process::Child,
    signal: nix::sys::signal::Signal,
) -> std::process::Output {
    let pid = nix::unistd::Pid::from_raw(child.id() as i32);
    nix::sys::signal::kill(pid, signal).unwrap();
    child.wait_with_output().unwrap()
}

#[test]
fn ctrl_c_says_what_is_done_leaves_no_record_and_the_same_command_resumes() {
    use std::os::unix::process::ExitStatusExt;
    let d = Dir::new();
    d.write("t.ron", &long_frames(2));
    let args = [
        "render",
        "t.ron",
        "--checkpoint-seconds",
        "0",
        "--threads",
        "1",
    ];
    let mut command = d.command(&args);
    command.stderr(std::process::Stdio::piped());
    // Frame 0 done, frame 1 part-way: its first checkpoint saved.
    let child = d.spawn_command_until(command, "out/t", "00001.ckpt");
    let out = interrupt(child, nix::sys::signal::Signal::SIGINT);
    // Ended by the signal itself, as a shell sees it (130), so a script's
    // loop stops too.
    assert_eq!(out.status.signal(), Some(2), "{}", stderr(&out));
    says(
        &out,
        "interrupted: 1 of 2 frames complete; the same command resumes",
    );
    let left = d.files("out/t");
    assert!(
        !left
            .iter()
            .any(|f| f.starts_with(".mandelreel-run-") || f.ends_with(".partial")),
        "run record or temporary file left: {left:?}"
    );
    assert!(left.contains(&".frame_00001.ckpt".to_string()), "{left:?}");
    let out = d.ok(&["render", "t.ron"]);
    says(&out, "1 of 2 frames already complete");
    says(&out, "frame 1: resuming from a checkpoint");
    d.ok(&[
        "render", "t.ron", "--frames", "1", "--out", "clean", "--quiet",
    ]);
    assert!(
        d.bytes("out/t/frame_00001.png") == d.bytes("clean/frame_00001.png"),
        "the interrupted frame differs from an uninterrupted one"
    );
}

#[test]
fn a_render_interrupted_before_it_wrote_anything_leaves_nothing() {
    // No frame finished and no checkpoint saved (not due for 60 s): the
    // folders it made, its record and its lock go too.
    let d = Dir::new();
    d.write("t.ron", &long_frames(1));
    let args = ["render", "t.ron", "--out", "new/seq", "--threads", "1"];
    let mut command = d.command(&args);
    command.stderr(std::process::Stdio::piped());
    let child = d.spawn_command_until(command, "new/seq", "mandelreel-job.json");
    let out = interrupt(child, nix::sys::signal::Signal::SIGINT);
    says(&out, "interrupted");
    assert!(!d.path().join("new").exists(), "{:?}", d.files("new/seq"));
}
