//! `--frame-name`: frames named by a pattern are found again by `status`,
//! `sheet`, a resume and the printed ffmpeg command; their claims and
//! temporaries keep apart from other names'; bad patterns are refused.

use crate::util::{ffmpeg_installed, says, stderr, stdout, tiny_timeline, Dir};

/// The frame files in `sub`: what is not hidden and not the job record.
fn frame_files(d: &Dir, sub: &str) -> Vec<String> {
    let files = d.files(sub).into_iter();
    files
        .filter(|f| !f.starts_with('.') && f != "mandelreel-job.json")
        .collect()
}

/// Frames `ffprobe` counts in the video `mp4`.
fn frames_in(d: &Dir, mp4: &str) -> String {
    let out = std::process::Command::new("ffprobe")
        .args(["-v", "error", "-count_frames", "-select_streams", "v:0"])
        .args([
            "-show_entries",
            "stream=nb_read_frames",
            "-of",
            "csv=p=0",
            mp4,
        ])
        .current_dir(d.path())
        .output()
        .expect("run ffprobe");
    stdout(&out).trim().to_string()
}

#[test]
fn frames_named_by_a_pattern_are_found_resumed_and_encoded() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(3, 6.0));
    let shot = ["--frame-name", "shot_####"];
    let render = [&["render", "t.ron"][..], &shot].concat();
    let cmd = stdout(&d.ok(&render));
    let names = ["shot_0000.png", "shot_0001.png", "shot_0002.png"];
    assert_eq!(frame_files(&d, "out/t"), names);
    assert!(
        cmd.contains(" -i out/t/shot_%04d.png -frames:v 3 "),
        "{cmd}"
    );
    // The name changes no pixel: the frames are those of the default names.
    d.ok(&["render", "t.ron", "--out", "plain", "--quiet"]);
    assert!(d.bytes("out/t/shot_0001.png") == d.bytes("plain/frame_00001.png"));
    // `status` finds them by the folder's record, or given the pattern.
    let (code, v) = d.status_json(&["out/t"]);
    assert_eq!((code, &v["complete"]), (Some(0), &serde_json::json!(3)));
    assert_eq!(v["video_command"], cmd.trim(), "{v}");
    d.ok(&[&["status", "t.ron"][..], &shot].concat());
    let out = d.run(&["status", "t.ron"]);
    assert_eq!(out.status.code(), Some(4), "no frame_##### there");
    let note = "note: the folder's png frames are named shot_####: add --frame-name shot_####";
    assert!(stdout(&out).contains(note), "{}", stdout(&out));
    let out = d.ok(&["sheet", "out/t"]);
    assert!(stdout(&out).contains("3 of 3 frames"), "{}", stdout(&out));
    // A resume skips them, rewriting none.
    let modified = |f: &str| {
        std::fs::metadata(d.path().join("out/t").join(f))
            .unwrap()
            .modified()
            .unwrap()
    };
    let before: Vec<_> = names.iter().map(|f| modified(f)).collect();
    says(&d.ok(&render), "3 of 3 frames already complete");
    assert_eq!(
        names.iter().map(|f| modified(f)).collect::<Vec<_>>(),
        before
    );
    if ffmpeg_installed() {
        d.run_printed(&cmd);
        assert_eq!(frames_in(&d, "out/t/t.mp4"), "3");
    }
}

#[test]
fn a_resume_under_other_names_is_refused_unless_replacing() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 6.0));
    d.ok(&["render", "t.ron", "--frame-name", "shot_####", "--quiet"]);
    // The default names: the folder's frames would not be found, and all
    // would be rendered again beside them.
    let out = d.run(&["render", "t.ron"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    says(&out, "--frame-name");
    says(&out, "holds 2 png frame(s) named shot_####");
    assert_eq!(frame_files(&d, "out/t"), ["shot_0000.png", "shot_0001.png"]);
    // Other formats are their own: EXRs may be named otherwise.
    d.ok(&["render", "t.ron", "--format", "exr", "--quiet"]);
    let (code, v) = d.status_json(&["out/t"]);
    assert_eq!(
        (code, &v["complete"]),
        (Some(0), &serde_json::json!(2)),
        "{v}"
    );
    // --replace renders them under the new names; the record counts those.
    d.ok(&["render", "t.ron", "--replace", "--quiet"]);
    let (code, v) = d.status_json(&["out/t"]);
    assert_eq!(
        (code, &v["complete"]),
        (Some(0), &serde_json::json!(2)),
        "{v}"
    );
    let cmd = v["video_command"].as_str().unwrap().to_string();
    assert!(cmd.contains("/frame_%05d.png"), "{cmd}");
}

#[test]
fn claims_and_temporaries_of_other_names_are_not_taken_for_these() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(4, 6.0));
    let shot = ["--frame-name", "shot_####"];
    let status_shot = || d.status_json(&[&["t.ron"][..], &shot].concat()).1;
    // A live worker elsewhere: its claim, and another's temporary file.
    d.claim_named_elsewhere(".shot_0000.claim", 0);
    d.write(
        "out/t/.shot_0001.png.node7.42.Ab12Cd.partial",
        "being written",
    );
    // The same frames' hidden files under the default names.
    d.claim_named_elsewhere(".frame_00002.claim", 2);
    d.write(
        "out/t/.frame_00003.png.node7.42.Ab12Cd.partial",
        "being written",
    );
    let v = status_shot();
    assert_eq!(v["states"]["in_progress"], serde_json::json!([0, 1]), "{v}");
    assert_eq!(v["states"]["missing"], serde_json::json!([2, 3]), "{v}");
    let (_, plain) = d.status_json(&["t.ron"]);
    assert_eq!(plain["states"]["in_progress"], serde_json::json!([2, 3]));
    // A claim worker takes the frames by its own claims, leaving none (had
    // it gone by the default names' claims, it would have waited out the
    // timeout on frame 2 and taken that claim over).
    std::fs::remove_file(d.path().join("out/t/.shot_0000.claim")).unwrap();
    d.ok(&[
        &[
            "render",
            "t.ron",
            "--claim",
            "--quiet",
            "--frames",
            "2..4",
            "--claim-timeout",
            "30",
        ][..],
        &shot,
    ]
    .concat());
    assert_eq!(frame_files(&d, "out/t"), ["shot_0002.png", "shot_0003.png"]);
    assert!(d.files("out/t").contains(&".frame_00002.claim".to_string()));
    assert!(!d
        .files("out/t")
        .iter()
        .any(|f| f.starts_with(".shot_") && f.ends_with(".claim")));
}

#[test]
fn bad_frame_names_are_refused_naming_the_option() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(1, 6.0));
    d.ok(&["render", "t.ron", "--quiet"]);
    let bad = [
        "",
        "shot",
        "shot_##_v##",
        "a/b_####",
        "shot_%04d",
        ".shot_##",
        "shot_##.png",
        "v2#",
    ];
    for pattern in bad {
        for command in [
            &["render", "t.ron", "--out", "o"][..],
            &["status", "t.ron"],
            &["sheet", "out/t"],
        ] {
            let out = d.run(&[command, &["--frame-name", pattern]].concat());
            assert_eq!(out.status.code(), Some(2), "{pattern:?}: {}", stderr(&out));
            says(&out, "invalid value");
            says(&out, "--frame-name");
        }
    }
    assert!(!d.path().join("o").exists(), "nothing written");
    // A folder records its frames' names: they are not given with it.
    let out = d.run(&["status", "out/t", "--frame-name", "shot_####"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    says(&out, "--frame-name");
    says(&out, "layers, frame names and EXR compression");
}
