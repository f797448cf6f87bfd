//! Never losing a night's work, and sharing it out: crash-and-resume under
//! repeated SIGKILL, `status`, `--shard`, `--claim` workers, a full disk.

use crate::util::{long_frames, says, stderr, stdout, tiny_timeline, Dir};
use std::collections::BTreeMap;
use std::time::Duration;

/// Frame numbers that `render` reported rendering, from its log lines.
fn rendered_frames(log: &str) -> Vec<u32> {
    log.lines()
        .filter(|l| l.starts_with("frame ") && l.contains(" rendered in "))
        .filter_map(|l| l.split_whitespace().nth(1)?.parse().ok())
        .collect()
}

fn frames_in(d: &Dir, sub: &str) -> Vec<String> {
    d.files(sub)
        .into_iter()
        .filter(|f| f.starts_with("frame_"))
        .collect()
}

#[test]
fn thirty_random_kills_then_resume_match_an_uninterrupted_render() {
    let d = Dir::new();
    let text = tiny_timeline(10, 6.0).replace("size: (48, 27)", "size: (96, 54)");
    d.write("t.ron", &text);
    let started = std::time::Instant::now();
    d.ok(&["render", "t.ron", "--out", "clean", "--quiet"]);
    // Kills land within a clean render's time (at least 60 ms): on a loaded
    // machine a fixed window could end every run before its first frame.
    let window = (started.elapsed().as_millis() as u64).max(60);
    // A seeded generator: the same kill moments every run.
    let mut state: u64 = 0x5eed_1234_abcd_0001;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        state >> 33
    };
    let (mut kills, mut most_kept) = (0, 0);
    while kills < 30 {
        let mut child = d
            .command(&["render", "t.ron", "--quiet", "--threads", "1"])
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(next() % window));
        let killed = child.try_wait().unwrap().is_none();
        if killed {
            child.kill().unwrap(); // SIGKILL
            kills += 1;
        }
        child.wait().unwrap();
        // Whatever sits under a final name is a whole, current frame.
        let kept = frames_in(&d, "out/t");
        for f in &kept {
            image::open(d.path().join("out/t").join(f))
                .unwrap_or_else(|e| panic!("after kill {kills}, {f} is damaged: {e}"));
        }
        // Frames kept through a kill are what the resumes build on.
        if killed {
            most_kept = most_kept.max(kept.len());
        }
        if kept.len() == 10 {
            // Finished between kills: start over so every kill lands mid-sequence.
            std::fs::remove_dir_all(d.path().join("out/t")).unwrap();
        }
    }
    assert!(
        most_kept > 0,
        "no kill left a finished frame to resume from"
    );
    d.ok(&["render", "t.ron", "--quiet"]);
    let finals = frames_in(&d, "out/t");
    assert_eq!(finals.len(), 10);
    for f in &finals {
        assert!(
            d.bytes(&format!("out/t/{f}")) == d.bytes(&format!("clean/{f}")),
            "{f} differs from the uninterrupted render"
        );
    }
    let leftovers: Vec<String> = d
        .files("out/t")
        .into_iter()
        .filter(|f| f.ends_with(".partial"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}

#[test]
fn a_claims_leftover_temporary_does_not_mark_its_frame_in_progress() {
    // A worker on another machine killed while writing its claim leaves
    // the claim's temporary and no claim: nobody holds the frame.
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 6.0));
    std::fs::create_dir_all(d.path().join("out/t")).unwrap();
    d.write("out/t/.frame_00001.claim.node7.42.Ab12Cd.partial", "{");
    let (_, v) = d.status_json(&["t.ron"]);
    assert_eq!(v["states"]["missing"], serde_json::json!([0, 1]), "{v}");
    // A frame's own temporary still says a writer is finishing it.
    d.write("out/t/.frame_00001.png.node7.42.Ab12Cd.partial", "half");
    let (_, v) = d.status_json(&["t.ron"]);
    assert_eq!(v["states"]["in_progress"], serde_json::json!([1]), "{v}");
}

#[test]
fn status_reports_complete_stale_missing_and_in_progress() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(6, 6.0));
    // Nothing rendered yet: everything missing, exit 4.
    let out = d.run(&["status", "t.ron"]);
    assert_eq!(out.status.code(), Some(4), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("0 of 6 frames complete"),
        "{}",
        stdout(&out)
    );
    d.ok(&["render", "t.ron", "--frames", "0..4", "--quiet"]);
    let (code, v) = d.status_json(&["t.ron"]);
    assert_eq!(code, Some(4));
    assert_eq!(v["complete"], 4);
    assert_eq!(v["states"]["missing"], serde_json::json!([4, 5]));
    // A live claim marks a frame in progress.
    d.claim_elsewhere(4);
    let out = stdout(&d.run(&["status", "t.ron"]));
    assert!(
        out.contains("in progress") && out.contains("node7:42"),
        "{out}"
    );
    std::fs::remove_file(d.path().join("out/t/.frame_00004.claim")).unwrap();
    // A file under a checkpoint's name that no render of this frame saved
    // does not make it resumable (a real one does:
    // `a_long_frame_killed_mid_way_resumes_from_its_checkpoint_identically`).
    d.write("out/t/.frame_00005.ckpt", "partial samples");
    let out = stdout(&d.run(&["status", "t.ron"]));
    assert!(!out.contains("resumable"), "{out}");
    std::fs::remove_file(d.path().join("out/t/.frame_00005.ckpt")).unwrap();
    // Everything rendered: exit 0, from the timeline and from the folder alone.
    d.ok(&["render", "t.ron", "--quiet"]);
    assert!(stdout(&d.ok(&["status", "t.ron"])).contains("6 of 6 frames complete"));
    assert!(stdout(&d.ok(&["status", "out/t"])).contains("6 of 6 frames complete"));
    // The timeline changes: frames 1.. are stale against it, and the folder
    // notices that its timeline changed since its render.
    d.write("t.ron", &tiny_timeline(6, 5.0));
    let (code, v) = d.status_json(&["t.ron"]);
    assert_eq!(code, Some(4));
    assert_eq!(v["states"]["stale"], serde_json::json!([1, 2, 3, 4, 5]));
    let folder = stdout(&d.ok(&["status", "out/t"]));
    assert!(folder.contains("has changed since"), "{folder}");
    // The folder's own record is enough even when the timeline file is gone.
    std::fs::remove_file(d.path().join("t.ron")).unwrap();
    assert!(stdout(&d.ok(&["status", "out/t"])).contains("6 of 6 frames complete"));
}

#[test]
fn status_of_a_folder_counts_the_whole_film() {
    // A folder holding 3 of a film's 8 frames is not a finished film: a
    // script waiting on `status OUTDIR` must not stop early.
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(8, 6.0));
    d.ok(&["render", "t.ron", "--frames", "0..3", "--quiet"]);
    let out = d.run(&["status", "out/t"]);
    assert_eq!(out.status.code(), Some(4), "{}", stdout(&out));
    assert!(
        stdout(&out).contains("3 of 8 frames complete"),
        "{}",
        stdout(&out)
    );
    // --frames asks about a part, and says that it does.
    let part = d.ok(&["status", "out/t", "--frames", "0..3"]);
    assert!(
        stdout(&part).contains("3 of 3 frames complete"),
        "{}",
        stdout(&part)
    );
    assert!(
        stdout(&part).contains("t.ron has 8 frames"),
        "{}",
        stdout(&part)
    );
    // Renders in pieces show their gaps, and the frames never rendered.
    d.ok(&["render", "t.ron", "--frames", "5..7", "--quiet"]);
    let (code, v) = d.status_json(&["out/t"]);
    assert_eq!(code, Some(4), "{v}");
    assert_eq!(v["frames"], serde_json::json!([0, 8]));
    assert_eq!(v["states"]["missing"], serde_json::json!([3, 4, 7]));
    assert_eq!(v["timeline_frames"], 8);
    d.ok(&["render", "t.ron", "--quiet"]);
    assert!(stdout(&d.ok(&["status", "out/t"])).contains("8 of 8 frames complete"));
}

#[test]
fn status_of_a_folder_refuses_what_the_folder_records() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(8, 6.0));
    d.ok(&["render", "t.ron", "--frames", "0..2", "--quiet"]);
    d.ok(&["render", "t.ron", "--frames", "4..6", "--quiet"]);
    // --frames narrows a folder's range; what the folder records is not
    // overridden from the command line.
    assert!(stdout(&d.ok(&["status", "out/t", "--frames", "4..6"])).contains("2 of 2"));
    for option in [
        &["--size", "8x6"][..],
        &["--out", "x"],
        &["--preview"],
        &["--samples", "4"],
    ] {
        let out = d.run(&[&["status", "out/t"], option].concat());
        assert_eq!(out.status.code(), Some(2), "{option:?}: {}", stderr(&out));
        says(&out, option[0]);
    }
    // Another timeline rendered over it with --force: status of the first
    // names the other, and does not call the first changed.
    d.write("u.ron", &tiny_timeline(8, 5.0));
    d.ok(&[
        "render", "u.ron", "--out", "out/t", "--frames", "0..1", "--force", "--quiet",
    ]);
    let out = stdout(&d.run(&["status", "t.ron"]));
    assert!(
        out.contains("last rendered from") && out.contains("u.ron"),
        "{out}"
    );
    assert!(!out.contains("has changed"), "{out}");
}

#[test]
fn status_of_a_folder_counts_each_format_rendered_over_the_film() {
    // PNGs and EXRs of the whole film: both are the film, so an EXR
    // missing keeps it incomplete.
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(4, 6.0));
    d.ok(&["render", "t.ron", "--format", "png,exr", "--quiet"]);
    d.ok(&["status", "out/t"]);
    std::fs::remove_file(d.path().join("out/t/frame_00002.exr")).unwrap();
    let (code, v) = d.status_json(&["out/t"]);
    assert_eq!(code, Some(4), "{v}");
    assert_eq!(v["states"]["missing"], serde_json::json!([2]), "{v}");
}

#[test]
fn status_of_a_folder_reports_each_format_it_holds() {
    // A few EXR frames, with their own samples, rendered into a folder of
    // complete PNGs: the film (the PNGs the video is made from) counts
    // over all its frames; the EXRs show their span on a line of their own.
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(6, 6.0));
    d.ok(&["render", "t.ron", "--quiet"]);
    let exr = ["--format", "exr", "--frames", "0..3", "--samples", "2"];
    d.ok(&[&["render", "t.ron", "--quiet"][..], &exr].concat());
    let text = stdout(&d.ok(&["status", "out/t"]));
    assert!(text.contains("6 of 6 frames complete"), "{text}");
    assert!(
        text.contains("exr: 3 of 3 complete and current (frames 0..3)")
            && text.contains("png: 6 of 6 complete and current (frames 0..6)"),
        "{text}"
    );
    // Asked about on their own, the EXRs are a film of 6 frames, 3 there.
    let out = d.run(&["status", "out/t", "--format", "exr"]);
    assert_eq!(out.status.code(), Some(4), "{}", stdout(&out));
    assert!(
        stdout(&out).contains("3 of 6 frames complete"),
        "{}",
        stdout(&out)
    );
    let out = d.run(&["status", "out/t", "--format", "png16"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    says(&out, "holds no png16 frames");
    // An EXR missing from its span shows on its line; the film decides
    // the exit status, so a script waiting on it stops once the PNGs are done.
    std::fs::remove_file(d.path().join("out/t/frame_00001.exr")).unwrap();
    let (code, v) = d.status_json(&["out/t"]);
    assert_eq!(code, Some(0), "{v}");
    assert_eq!(
        v["formats"]["exr"]["states"]["missing"],
        serde_json::json!([1])
    );
    assert_eq!(v["formats"]["png"]["complete"], 6, "{v}");
    assert_eq!(v["formats"]["exr"]["frames"], serde_json::json!([0, 3]));
    // --frames narrows the EXRs' span, never widens it.
    let (code, v) = d.status_json(&["out/t", "--frames", "2..5"]);
    assert_eq!(code, Some(0), "{v}");
    assert_eq!(v["formats"]["exr"]["frames"], serde_json::json!([2, 3]));
    // The PNGs short of the film: not complete, whatever the EXRs hold.
    std::fs::remove_file(d.path().join("out/t/frame_00005.png")).unwrap();
    let (code, v) = d.status_json(&["out/t"]);
    assert_eq!(code, Some(4), "{v}");
    assert_eq!(
        v["formats"]["png"]["states"]["missing"],
        serde_json::json!([5])
    );
    // The timeline's status counts what its options name, format by format.
    let text = stdout(&d.run(&[&["status", "t.ron"][..], &exr].concat()));
    assert!(text.contains("2 of 3 frames complete"), "{text}");
}

#[test]
fn shards_split_frames_by_index_and_from_the_scheduler() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(7, 6.0));
    d.ok(&[
        "render", "t.ron", "--shard", "1/3", "--out", "manual", "--quiet",
    ]);
    assert_eq!(
        frames_in(&d, "manual"),
        ["frame_00001.png", "frame_00004.png"]
    );
    // Slurm: --array=1-3 gives task ids 1..3; task 3 is shard 2 of 3.
    let slurm = [
        ("SLURM_ARRAY_TASK_ID", "3"),
        ("SLURM_ARRAY_TASK_MIN", "1"),
        ("SLURM_ARRAY_TASK_COUNT", "3"),
    ];
    let out = render_shard(&d, "auto", "slurm", &slurm);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        frames_in(&d, "slurm"),
        ["frame_00002.png", "frame_00005.png"]
    );
    // Kubernetes Indexed Job: index 0 of 2.
    let k8s = [
        ("JOB_COMPLETION_INDEX", "0"),
        ("MANDELREEL_SHARD_COUNT", "2"),
    ];
    let out = render_shard(&d, "auto", "k8s", &k8s);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        frames_in(&d, "k8s"),
        [
            "frame_00000.png",
            "frame_00002.png",
            "frame_00004.png",
            "frame_00006.png"
        ]
    );
    // Bad shards are usage errors, before anything is written.
    for bad in ["3/3", "1/0", "x/2", "auto"] {
        let out = render_shard(&d, bad, "bad", &[]);
        assert_eq!(out.status.code(), Some(2), "{bad}: {}", stderr(&out));
        assert!(!d.path().join("bad").exists());
    }
}

/// `render t.ron --shard SHARD --out OUT`, seeing no scheduler's variables
/// but `env` (whatever the environment the tests run in).
fn render_shard(d: &Dir, shard: &str, out: &str, env: &[(&str, &str)]) -> std::process::Output {
    let mut command = d.command(&["render", "t.ron", "--shard", shard, "--out", out, "--quiet"]);
    for var in SCHEDULER_VARS {
        command.env_remove(var);
    }
    command.envs(env.iter().copied()).output().unwrap()
}

/// What `--shard auto` reads.
const SCHEDULER_VARS: [&str; 5] = [
    "SLURM_ARRAY_TASK_ID",
    "SLURM_ARRAY_TASK_MIN",
    "SLURM_ARRAY_TASK_COUNT",
    "JOB_COMPLETION_INDEX",
    "MANDELREEL_SHARD_COUNT",
];

/// The parts of examples/k8s/indexed-job.yaml that decide what its pods run.
struct IndexedJob {
    completions: usize,
    command: Vec<String>,
    env: Vec<(String, String)>,
}

/// Reads the example by indentation, as it is written (block lists of
/// scalars): one YAML file does not warrant a YAML crate.
fn indexed_job() -> IndexedJob {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/k8s/indexed-job.yaml");
    let text = std::fs::read_to_string(path).unwrap();
    let lines: Vec<&str> = text
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .collect();
    let scalar = |s: &str| s.trim().trim_matches('"').to_string();
    let indent = |l: &str| l.len() - l.trim_start().len();
    let only = |key: &str| {
        let found: Vec<usize> = (0..lines.len())
            .filter(|&i| lines[i].trim_start().starts_with(&format!("{key}:")))
            .collect();
        assert_eq!(found.len(), 1, "one {key}: in {path}");
        found[0]
    };
    let value = |key: &str| scalar(lines[only(key)].split_once(':').unwrap().1);
    let block = |key: &str| -> Vec<&str> {
        let at = only(key);
        lines[at + 1..]
            .iter()
            .take_while(|l| indent(l) > indent(lines[at]))
            .map(|l| l.trim().trim_start_matches("- "))
            .collect()
    };
    let env = block("env");
    let env = env
        .chunks(2)
        .map(|pair| match pair {
            [name, value] => (
                scalar(name.strip_prefix("name:").unwrap()),
                scalar(value.strip_prefix("value:").unwrap()),
            ),
            _ => panic!("env entries are name, value pairs: {pair:?}"),
        })
        .collect();
    IndexedJob {
        completions: value("completions").parse().unwrap(),
        command: block("command").into_iter().map(scalar).collect(),
        env,
    }
}

#[test]
fn the_kubernetes_indexed_job_runs_every_frame_once_across_its_pods() {
    let job = indexed_job();
    let d = Dir::new();
    assert_eq!(job.command[0], "mandelreel", "{:?}", job.command);
    // The container's absolute paths, under the test's folder.
    let args: Vec<String> = job.command[1..]
        .iter()
        .map(|a| match a.strip_prefix('/') {
            Some(inside) => d.path().join(inside).display().to_string(),
            None => a.clone(),
        })
        .collect();
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let timeline = std::path::Path::new(args[1]);
    std::fs::create_dir_all(timeline.parent().unwrap()).unwrap();
    std::fs::write(timeline, tiny_timeline(12, 6.0)).unwrap();
    // Kubernetes gives each pod its index, never the count.
    let count = job.env.iter().find(|(n, _)| n == "MANDELREEL_SHARD_COUNT");
    assert_eq!(
        count.map(|(_, v)| v.parse().unwrap()),
        Some(job.completions)
    );
    for index in 0..job.completions {
        let mut pod = d.command(&args);
        for var in SCHEDULER_VARS {
            pod.env_remove(var);
        }
        pod.envs(job.env.iter().map(|(n, v)| (n, v)));
        let out = pod
            .env("JOB_COMPLETION_INDEX", index.to_string())
            .output()
            .unwrap();
        assert!(out.status.success(), "pod {index}: {}", stderr(&out));
        let log = format!("{}{}", stdout(&out), stderr(&out));
        let share: Vec<u32> = (index as u32..12).step_by(job.completions).collect();
        assert_eq!(rendered_frames(&log), share, "pod {index}: {log}");
    }
    let outdir = args[args.iter().position(|a| *a == "--out").unwrap() + 1];
    let status = d.run(&["status", outdir]);
    assert_eq!(status.status.code(), Some(0), "{}", stdout(&status));
}

#[test]
fn four_claim_workers_render_every_frame_exactly_once() {
    let d = Dir::new();
    d.write(
        "t.ron",
        &tiny_timeline(16, 6.0).replace("size: (48, 27)", "size: (64, 36)"),
    );
    let workers: Vec<_> = (0..4)
        .map(|_| {
            d.command(&["render", "t.ron", "--claim", "--threads", "1"])
                .stderr(std::process::Stdio::piped())
                .stdout(std::process::Stdio::null())
                .spawn()
                .unwrap()
        })
        .collect();
    let mut counts: BTreeMap<u32, usize> = BTreeMap::new();
    for w in workers {
        let out = w.wait_with_output().unwrap();
        assert!(out.status.success(), "{}", stderr(&out));
        for f in rendered_frames(&stderr(&out)) {
            *counts.entry(f).or_default() += 1;
        }
    }
    assert_eq!(counts.len(), 16, "{counts:?}");
    assert!(counts.values().all(|&n| n == 1), "{counts:?}");
    for f in frames_in(&d, "out/t") {
        image::open(d.path().join("out/t").join(f)).unwrap();
    }
    d.ok(&["status", "out/t"]);
    assert!(!d.files("out/t").iter().any(|f| f.ends_with(".claim")));
}

#[test]
fn a_killed_workers_claim_is_taken_over_at_once_on_its_machine() {
    let d = Dir::new();
    // Frames slow enough that the kill lands while a claim is held.
    d.write(
        "t.ron",
        &tiny_timeline(3, 6.0).replace("size: (48, 27)", "size: (480, 270)"),
    );
    let mut doomed = d.spawn_until(
        &["render", "t.ron", "--claim", "--threads", "1", "--quiet"],
        "out/t",
        ".claim",
    );
    doomed.kill().unwrap();
    doomed.wait().unwrap();
    let held: Vec<String> = d
        .files("out/t")
        .into_iter()
        .filter(|f| f.ends_with(".claim"))
        .collect();
    assert_eq!(held.len(), 1, "the dead worker's claim stays behind");
    let frame: u32 = held[0][7..12].parse().unwrap();
    // Its heartbeat is fresh, but its process has ended on this machine: a
    // new worker takes the frame at once, not after the 300 s timeout, and
    // status does not call it in progress.
    let status = stdout(&d.run(&["status", "out/t"]));
    assert!(!status.contains("in progress"), "{status}");
    let out = d.ok(&["render", "t.ron", "--claim", "--threads", "2"]);
    let err = stderr(&out);
    assert!(rendered_frames(&err).contains(&frame), "{err}");
    assert!(!err.contains("waiting for frame"), "{err}");
    d.ok(&["status", "out/t"]);
}

#[test]
fn a_worker_says_which_frames_it_waits_for_and_takes_them_after_the_timeout() {
    // A claim on another machine that stopped beating: the worker renders
    // the other frames, says it waits for this one and who holds it, and
    // takes it over once the claim is a timeout old.
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 6.0));
    d.claim_elsewhere(1);
    // Long enough that a loaded machine starts the worker and renders
    // frame 0 before the claim on 1, beating when written, times out.
    let out = d.ok(&["render", "t.ron", "--claim", "--claim-timeout", "6"]);
    let err = stderr(&out);
    assert!(
        err.contains("waiting for frame(s) 1 claimed by node7:42"),
        "{err}"
    );
    assert_eq!(rendered_frames(&err).len(), 2, "{err}");
}

#[test]
fn the_waiting_line_names_only_frames_still_held_at_the_end_of_a_pass() {
    // Frames 0 and 1 are held by a worker elsewhere when this one's pass
    // reaches them; frame 0 is finished there while this worker renders
    // frame 2 (a long path-traced frame). The line it prints at the end of
    // the pass names frame 1 alone; then the claim on 1 times out and it
    // renders that too, never frame 0.
    let d = Dir::new();
    let text = long_frames(3);
    d.write("t.ron", &text);
    d.ok(&[
        "render",
        "t.ron",
        "--frames",
        "0",
        "--out",
        "elsewhere",
        "--quiet",
    ]);
    d.claim_elsewhere(0);
    d.claim_elsewhere(1);
    let args = [
        "render",
        "t.ron",
        "--claim",
        // Room for a loaded machine to reach frames 0 and 1 while held.
        "--claim-timeout",
        "8",
        "--checkpoint-seconds",
        "0",
        "--threads",
        "1",
    ];
    let mut command = d.command(&args);
    command.stderr(std::process::Stdio::piped());
    // Mid-way through frame 2: frames 0 and 1 were found held.
    let worker = d.spawn_command_until(command, "out/t", ".ckpt");
    let done = d.path().join("out/t/finished-elsewhere.png");
    std::fs::copy(d.path().join("elsewhere/frame_00000.png"), &done).unwrap();
    std::fs::rename(&done, d.path().join("out/t/frame_00000.png")).unwrap();
    let out = worker.wait_with_output().unwrap();
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("waiting for frame(s) 1 claimed by node7:42"),
        "{err}"
    );
    assert!(!err.contains("waiting for frame(s) 0"), "{err}");
    let mut rendered = rendered_frames(&err);
    rendered.sort();
    assert_eq!(rendered, [1, 2], "{err}");
}

/// A tiny tmpfs, unmounted when dropped.
struct SmallDisk(std::path::PathBuf);

impl Drop for SmallDisk {
    fn drop(&mut self) {
        let _ = std::process::Command::new("umount").arg(&self.0).status();
    }
}

/// A 48 KB tmpfs mounted on `disk` in `d`, or `None` (with a note) where
/// mounting needs privileges this test does not have.
fn small_disk(d: &Dir) -> Option<SmallDisk> {
    let mount = d.path().join("disk");
    std::fs::create_dir(&mount).unwrap();
    let mounted = std::process::Command::new("mount")
        .args(["-t", "tmpfs", "-o", "size=48k", "tmpfs"])
        .arg(&mount)
        .output()
        .is_ok_and(|o| o.status.success());
    if !mounted {
        // Mounting needs privileges; CI runs as root, where it works.
        assert!(
            std::env::var_os("CI").is_none() || ci_allows_skipping_mount(),
            "cannot mount a tmpfs in CI"
        );
        eprintln!("skipping: cannot mount a small tmpfs here (not root?)");
        return None;
    }
    Some(SmallDisk(mount))
}

#[test]
fn a_full_disk_fails_clearly_and_keeps_earlier_frames() {
    let d = Dir::new();
    let Some(_disk) = small_disk(&d) else {
        return;
    };
    // 40 frames of about 4 KB each cannot fit in 48 KB.
    d.write("t.ron", &tiny_timeline(40, 6.0));
    let out = d.run(&["render", "t.ron", "--out", "disk/seq", "--quiet"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let err = stderr(&out);
    let written = frames_in(&d, "disk/seq");
    // The frame that failed, by its own name: the temporary file is gone.
    let failed = format!(
        "disk/seq/frame_{:05}.png: No space left on device",
        written.len()
    );
    assert!(err.contains(&failed), "{err}");
    assert!(!err.contains(".partial"), "{err}");
    assert!(
        !written.is_empty() && written.len() < 40,
        "{} frames",
        written.len()
    );
    for f in &written {
        image::open(d.path().join("disk/seq").join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
    }
    assert!(!d.files("disk/seq").iter().any(|f| f.ends_with(".partial")));
}

/// CI machines without mount rights would fail the test above for the wrong
/// reason; MANDELREEL_NO_MOUNT=1 lets such a CI skip it explicitly.
fn ci_allows_skipping_mount() -> bool {
    std::env::var_os("MANDELREEL_NO_MOUNT").is_some()
}

#[test]
fn a_disk_full_before_the_first_write_leaves_nothing_behind() {
    // Nothing written: no folder, record or lock left (`status` would call
    // such a folder "not a mandelreel output folder"); a folder that was
    // there stays as it was.
    let d = Dir::new();
    let Some(_disk) = small_disk(&d) else {
        return;
    };
    std::fs::create_dir(d.path().join("disk/empty")).unwrap();
    let filler = vec![0u8; 4096];
    let mut file = std::fs::File::create(d.path().join("disk/filler")).unwrap();
    while std::io::Write::write_all(&mut file, &filler).is_ok() {}
    d.write("t.ron", &tiny_timeline(2, 6.0));
    for out in ["disk/new/seq", "disk/empty"] {
        let run = d.run(&["render", "t.ron", "--out", out, "--quiet"]);
        assert_eq!(run.status.code(), Some(1), "{}", stderr(&run));
        says(&run, "No space left");
    }
    assert!(
        !d.path().join("disk/new").exists(),
        "{:?}",
        d.files("disk/new")
    );
    assert!(
        d.files("disk/empty").is_empty(),
        "{:?}",
        d.files("disk/empty")
    );
}

#[test]
fn a_claim_worker_stopped_by_sigterm_releases_its_frame() {
    // Its claim and run record go, so a worker on any machine takes the
    // frame at once (from its checkpoint), and `status` lists no worker.
    use std::os::unix::process::ExitStatusExt;
    let d = Dir::new();
    d.write("t.ron", &long_frames(1));
    let args = [
        "render",
        "t.ron",
        "--claim",
        "--checkpoint-seconds",
        "0",
        "--threads",
        "1",
    ];
    let mut command = d.command(&args);
    command.stderr(std::process::Stdio::piped());
    let worker = d.spawn_command_until(command, "out/t", ".ckpt");
    let out = crate::resume::interrupt(worker, nix::sys::signal::Signal::SIGTERM);
    assert_eq!(out.status.signal(), Some(15), "{}", stderr(&out));
    says(&out, "interrupted: 0 of 1 frames complete");
    let left = d.files("out/t");
    assert!(
        !left
            .iter()
            .any(|f| f.ends_with(".claim") || f.starts_with(".mandelreel-run-")),
        "claim or run record left: {left:?}"
    );
    let (_, status) = d.status_json(&["out/t"]);
    assert_eq!(status["states"]["resumable"], serde_json::json!([0]));
    assert_eq!(status["workers"], serde_json::json!([]));
    let out = d.ok(&["render", "t.ron", "--claim"]);
    says(&out, "resuming from a checkpoint");
}
