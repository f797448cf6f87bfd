//! A temporary folder with timelines in it and a way to run the binary there.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub struct Dir {
    pub root: tempfile::TempDir,
}

/// A small timeline: `frames` frames of 48×27 looking at the whole bulb, with
/// the power animated so that every frame differs.
pub fn tiny_timeline(frames: u32, power_end: f64) -> String {
    format!(
        "(
    fps: 24,
    frames: {frames},
    size: (48, 27),
    scene: (camera: (position: (0, 0.5, 3.0)), fractal: (iterations: 8)),
    tracks: {{
        \"fractal.power\": (interpolation: Linear, keys: [(time: 0, value: 8), (time: 1, value: {power_end})]),
    }},
)"
    )
}

/// `timeline` (a `tiny_timeline`) with `fields` added to its scene, after
/// the fractal: `with_scene(&tiny_timeline(1, 8.0), "samples_per_pixel: 4")`.
pub fn with_scene(timeline: &str, fields: &str) -> String {
    let fractal = "fractal: (iterations: 8)";
    assert!(timeline.contains(fractal), "not a tiny_timeline");
    timeline.replace(fractal, &format!("{fractal}, {fields}"))
}

/// `frames` path-traced frames of 120×68 at 64 samples a pixel: 16 waves
/// of 4 each, long enough on one thread to be caught mid-way.
pub fn long_frames(frames: u32) -> String {
    with_scene(
        &tiny_timeline(frames, 8.0).replace("size: (48, 27)", "size: (120, 68)"),
        "samples_per_pixel: 64, effects: (path_tracing: ())",
    )
}

impl Dir {
    pub fn new() -> Dir {
        Dir {
            root: tempfile::tempdir().expect("temporary folder"),
        }
    }

    pub fn path(&self) -> &Path {
        self.root.path()
    }

    pub fn write_bytes(&self, name: &str, bytes: &[u8]) {
        std::fs::write(self.path().join(name), bytes).unwrap();
    }

    pub fn write(&self, name: &str, text: &str) -> PathBuf {
        let p = self.path().join(name);
        std::fs::write(&p, text).expect("write test file");
        p
    }

    pub fn command(&self, args: &[&str]) -> Command {
        let mut c = Command::new(env!("CARGO_BIN_EXE_mandelreel"));
        c.current_dir(self.path()).args(args);
        c
    }

    /// Runs the binary and returns its output, whatever the exit status.
    pub fn run(&self, args: &[&str]) -> Output {
        self.command(args).output().expect("run mandelreel")
    }

    /// Runs `command` (the binary, or a shell around it) as `run` does, but
    /// fails the test, killing it, if it is still running after `seconds`:
    /// for input that could make it hang, so a regression fails rather
    /// than hangs. A guard against hanging, far above the time it takes.
    pub fn run_guarded(&self, mut command: Command, seconds: u64) -> Output {
        let (out, err) = (self.path().join(".stdout"), self.path().join(".stderr"));
        let file = |p: &Path| std::fs::File::create(p).expect("output file");
        let mut child = command
            .stdout(file(&out))
            .stderr(file(&err))
            .spawn()
            .expect("run mandelreel");
        let start = std::time::Instant::now();
        let status = loop {
            if let Some(status) = child.try_wait().unwrap() {
                break status;
            }
            if start.elapsed() > std::time::Duration::from_secs(seconds) {
                let _ = child.kill();
                let _ = child.wait();
                let said = std::fs::read_to_string(&err).unwrap_or_default();
                panic!("{command:?} still ran after {seconds} s: {said}");
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        };
        let read = |p: &Path| std::fs::read(p).unwrap_or_default();
        Output {
            status,
            stdout: read(&out),
            stderr: read(&err),
        }
    }

    /// Runs the binary and panics with its stderr unless it succeeds.
    pub fn ok(&self, args: &[&str]) -> Output {
        let out = self.run(args);
        assert!(
            out.status.success(),
            "mandelreel {args:?} failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        out
    }

    /// Names of the files in `sub`, sorted; empty if it does not exist.
    pub fn files(&self, sub: &str) -> Vec<String> {
        let Ok(entries) = std::fs::read_dir(self.path().join(sub)) else {
            return Vec::new();
        };
        let mut v: Vec<String> = entries
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    /// Renders `timeline` with 1 and with 2 threads (into `one` and `two`,
    /// with `extra` arguments) and asserts each of `files` came out
    /// byte-identical.
    pub fn same_on_one_and_two_threads(&self, timeline: &str, extra: &[&str], files: &[&str]) {
        for (threads, out) in [("1", "one"), ("2", "two")] {
            let mut args = vec!["render", timeline, "--threads", threads, "--out", out];
            args.extend_from_slice(extra);
            self.ok(&args);
        }
        for f in files {
            assert!(
                self.bytes(&format!("one/{f}")) == self.bytes(&format!("two/{f}")),
                "{f} differs between 1 and 2 threads"
            );
        }
    }

    /// Starts the binary and waits until a file in `sub` ends with
    /// `suffix`, asserting that it is still running then; returns it running.
    pub fn spawn_until(&self, args: &[&str], sub: &str, suffix: &str) -> std::process::Child {
        self.spawn_command_until(self.command(args), sub, suffix)
    }

    /// `spawn_until` for a command set up by the caller (its output piped).
    pub fn spawn_command_until(
        &self,
        mut command: Command,
        sub: &str,
        suffix: &str,
    ) -> std::process::Child {
        let mut child = command.spawn().expect("start mandelreel");
        let start = std::time::Instant::now();
        while !self.files(sub).iter().any(|f| f.ends_with(suffix)) {
            assert!(
                start.elapsed() < std::time::Duration::from_secs(120),
                "no {suffix} file appeared in {sub}"
            );
            assert!(
                child.try_wait().unwrap().is_none(),
                "finished before a {suffix} file appeared"
            );
            std::thread::sleep(std::time::Duration::from_millis(2));
        }
        child
    }

    pub fn bytes(&self, rel: &str) -> Vec<u8> {
        std::fs::read(self.path().join(rel)).unwrap_or_else(|e| panic!("read {rel}: {e}"))
    }
}

/// An EXR frame's channels, in file (alphabetical) order, as f32.
pub struct ExrFrame {
    pub size: (usize, usize),
    pub channels: Vec<(String, Vec<f32>)>,
}

impl ExrFrame {
    pub fn names(&self) -> Vec<&str> {
        self.channels.iter().map(|(n, _)| n.as_str()).collect()
    }

    /// The samples of channel `name`; panics if it is missing.
    pub fn channel(&self, name: &str) -> &[f32] {
        &self
            .channels
            .iter()
            .find(|(n, _)| n == name)
            .unwrap_or_else(|| panic!("no channel {name} in {:?}", self.names()))
            .1
    }
}

impl Dir {
    /// Runs `status ARGS --json`: its exit code and its report.
    pub fn status_json(&self, args: &[&str]) -> (Option<i32>, serde_json::Value) {
        let out = self.run(&[&["status"][..], args, &["--json"]].concat());
        let report =
            serde_json::from_str(&stdout(&out)).unwrap_or_else(|e| panic!("{e}: {}", stderr(&out)));
        (out.status.code(), report)
    }

    /// Writes a fresh claim on `frame` in out/t, held by a worker on
    /// another machine (node7:42).
    pub fn claim_elsewhere(&self, frame: u32) {
        self.claim_named_elsewhere(&format!(".frame_{frame:05}.claim"), frame);
    }

    /// `claim_elsewhere` for frames of another name: `name` is the claim's.
    pub fn claim_named_elsewhere(&self, name: &str, frame: u32) {
        let now_ms = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .unwrap()
            .as_millis();
        let claim = format!(
            "{{\"host\":\"node7\",\"pid\":42,\"token\":\"t{frame}\",\"heartbeat_ms\":{now_ms}}}"
        );
        std::fs::create_dir_all(self.path().join("out/t")).unwrap();
        self.write(&format!("out/t/{name}"), &claim);
    }

    /// Reads the EXR file at `rel`.
    pub fn exr(&self, rel: &str) -> ExrFrame {
        let image = exr::prelude::read_all_flat_layers_from_file(self.path().join(rel))
            .unwrap_or_else(|e| panic!("read {rel}: {e}"));
        let layer = &image.layer_data[0];
        ExrFrame {
            size: (layer.size.0, layer.size.1),
            channels: layer
                .channel_data
                .list
                .iter()
                .map(|c| (c.name.to_string(), c.sample_data.values_as_f32().collect()))
                .collect(),
        }
    }
}

impl Dir {
    /// `link.ron`, a link to `real/t.ron` (`text`), a file only its owner
    /// may read: for what writes a timeline through a link.
    pub fn linked_private_timeline(&self, text: &str) -> PathBuf {
        use std::os::unix::fs::PermissionsExt;
        std::fs::create_dir(self.path().join("real")).unwrap();
        let real = self.write("real/t.ron", text);
        std::fs::set_permissions(&real, std::fs::Permissions::from_mode(0o600)).unwrap();
        std::os::unix::fs::symlink("real/t.ron", self.path().join("link.ron")).unwrap();
        real
    }

    /// Asserts that `link.ron` is still a link and that `real`, the file it
    /// names, holds `written` and is still its owner's alone.
    pub fn assert_written_through_the_link(&self, real: &Path, written: &str) {
        use std::os::unix::fs::PermissionsExt;
        let link = std::fs::symlink_metadata(self.path().join("link.ron")).unwrap();
        assert!(
            link.file_type().is_symlink(),
            "the link was replaced by a file"
        );
        let text = std::fs::read_to_string(real).unwrap();
        assert!(text.contains(written), "{text}");
        let mode = std::fs::metadata(real).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o600);
    }
}

/// Whether ffmpeg and ffprobe run here; in CI they must (.ci/run installs
/// them), elsewhere a test that needs them skips with a note.
pub fn ffmpeg_installed() -> bool {
    tool("ffmpeg", "-version") && tool("ffprobe", "-version")
}

impl Dir {
    /// Runs an ffmpeg `command` as mandelreel printed it, through the shell,
    /// quietly, and panics with what it said unless it succeeds.
    pub fn run_printed(&self, command: &str) {
        let quiet = command
            .trim()
            .replacen("ffmpeg ", "ffmpeg -loglevel error ", 1);
        let out = Command::new("sh")
            .arg("-c")
            .arg(&quiet)
            .current_dir(self.path())
            .output()
            .expect("run sh");
        assert!(out.status.success(), "{quiet}: {}", stderr(&out));
    }
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Asserts that the run's stderr contains `what`, showing it if not.
pub fn says(out: &Output, what: &str) {
    let err = stderr(out);
    assert!(err.contains(what), "missing {what:?} in: {err}");
}

/// Whether the real tool `program` runs here (`probe` is an argument it
/// answers at once). `.ci/run` installs every tool the tests use, so in CI
/// a missing one fails the test; elsewhere the test says so and passes.
pub fn tool(program: &str, probe: &str) -> bool {
    let found = Command::new(program).arg(probe).output().is_ok();
    if !found {
        assert!(
            std::env::var_os("CI").is_none(),
            "{program} is missing in CI"
        );
        eprintln!("{program} not installed: skipping (.ci/run installs it)");
    }
    found
}

/// Starts rendering `t.ron` into out/t on one thread, saving a checkpoint
/// after every wave, and returns once the first is saved: mid-frame.
pub fn render_until_a_checkpoint(d: &Dir) -> std::process::Child {
    let args = [
        "render",
        "t.ron",
        "--checkpoint-seconds",
        "0",
        "--threads",
        "1",
        "--quiet",
    ];
    d.spawn_until(&args, "out/t", ".ckpt")
}
