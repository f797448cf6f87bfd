//! Input that could hang a program or fill the memory: FIFOs and devices
//! where files belong, huge maps, counts no film needs, frames too costly
//! to measure. Each is answered at once, or refused naming the limit.

use crate::util::{says, stderr, stdout, tiny_timeline, with_scene, Dir};
use std::process::Output;

/// Far longer than any of these takes: only a hang reaches it.
const GUARD_SECONDS: u64 = 60;

fn guarded(d: &Dir, args: &[&str]) -> Output {
    d.run_guarded(d.command(args), GUARD_SECONDS)
}

/// A path-traced timeline lit by the environment map at `path`.
fn lit_by(path: &str) -> String {
    with_scene(
        &tiny_timeline(1, 8.0),
        &format!("effects: (path_tracing: (sky: Environment(path: \"{path}\")))"),
    )
}

#[cfg(unix)]
fn mkfifo(d: &Dir, name: &str) {
    let path = d.path().join(name);
    nix::unistd::mkfifo(&path, nix::sys::stat::Mode::S_IRWXU).expect("a FIFO");
}

#[cfg(unix)]
#[test]
fn a_fifo_as_the_timeline_or_the_map_is_refused_at_once() {
    // Opened to be read, a FIFO waits for a writer that never comes.
    let d = Dir::new();
    mkfifo(&d, "t.ron");
    let out = guarded(&d, &["info", "t.ron"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    says(&out, "t.ron: a named pipe (FIFO), not a regular file");
    mkfifo(&d, "sky.exr");
    d.write("lit.ron", &lit_by("sky.exr"));
    let out = guarded(&d, &["render", "lit.ron"]);
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    says(
        &out,
        "lit.ron:5:122: scene.effects.path_tracing.sky.path: cannot read sky.exr: a named pipe (FIFO)",
    );
    assert!(!d.path().join("out").exists());
}

#[cfg(target_os = "linux")]
#[test]
fn dev_zero_as_the_map_is_refused_before_a_byte_is_read() {
    // Read whole, it filled the memory at about 0.8 GB/s: the address
    // space is capped here, so that would fail rather than take the machine.
    let d = Dir::new();
    d.write("lit.ron", &lit_by("/dev/zero"));
    let mut shell = std::process::Command::new("sh");
    shell.current_dir(d.path()).args([
        "-c",
        "ulimit -v 4000000 && exec \"$0\" \"$@\"",
        env!("CARGO_BIN_EXE_mandelreel"),
        "info",
        "lit.ron",
    ]);
    let out = d.run_guarded(shell, GUARD_SECONDS);
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    says(
        &out,
        "scene.effects.path_tracing.sky.path: cannot read /dev/zero: a device, not a regular file",
    );
}

#[test]
fn a_map_file_past_256_mib_is_refused_unread() {
    // A sparse file: 300 MiB long, nothing on the disk.
    let d = Dir::new();
    let sky = std::fs::File::create(d.path().join("sky.exr")).unwrap();
    sky.set_len(300 << 20).unwrap();
    d.write("lit.ron", &lit_by("sky.exr"));
    let out = guarded(&d, &["info", "lit.ron"]);
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    says(
        &out,
        "cannot read sky.exr: 314572800 bytes, more than the 256 MiB an environment map may have",
    );
}

#[test]
fn four_billion_frames_are_refused_with_the_limit() {
    // Checking every frame's scene would take hours.
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(4_000_000_000, 8.0));
    let out = guarded(&d, &["render", "t.ron"]);
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    says(&out, "t.ron:3:13: frames: at most 1000000, got 4000000000");
    assert!(!d.path().join("out").exists());
    let long = tiny_timeline(1, 8.0).replace("frames: 1,", "duration_seconds: 1e9,");
    d.write("long.ron", &long);
    let out = guarded(&d, &["info", "long.ron"]);
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    says(
        &out,
        "long.ron:3:23: duration_seconds: gives 2.4e10 frames at 24 fps, more than the 1000000",
    );
}

#[test]
fn samples_given_for_a_motion_blurred_film_count_as_its_instants() {
    // --samples makes each frame's samples instants of their own.
    let d = Dir::new();
    let blurred = with_scene(
        &tiny_timeline(1000, 8.0),
        "samples_per_pixel: 8, effects: (motion_blur: ())",
    );
    d.write("t.ron", &blurred);
    let out = guarded(&d, &["status", "t.ron", "--samples", "4096"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    says(
        &out,
        "--samples: with motion blur each of a frame's samples sees the timeline at its own \
         instant: 1000 frames × 4096 motion-blurred samples = 4096000 instants, more than the \
         2000000",
    );
}

#[test]
fn info_measures_tall_narrow_frames_on_a_thumbnail_of_their_shape() {
    // The thumbnail was 64 pixels wide whatever the shape: 64×2097152 for
    // a 1×32768 frame, minutes of rendering.
    let d = Dir::new();
    let tall = tiny_timeline(1, 8.0).replace("size: (48, 27)", "size: (1, 32768)");
    d.write("tall.ron", &tall);
    let out = guarded(&d, &["info", "tall.ron"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("cost:     frame 0 at 1x64: "),
        "{}",
        stdout(&out)
    );
    let traced = with_scene(
        &tiny_timeline(1, 8.0).replace("size: (48, 27)", "size: (1, 135)"),
        "samples_per_pixel: 16, effects: (path_tracing: ())",
    );
    d.write("traced.ron", &traced);
    let out = guarded(&d, &["info", "traced.ron"]);
    assert!(
        stdout(&out).contains("cost:     frame 0 at 1x64: "),
        "{}",
        stdout(&out)
    );
}

/// A frame of 4096 motion-blurred samples a pixel: `info` measures 16.
fn blurred_4096() -> String {
    with_scene(
        &tiny_timeline(1, 8.0),
        "samples_per_pixel: 4096, effects: (motion_blur: ())",
    )
}

#[test]
fn info_measures_a_costly_frame_within_bounds_or_says_it_did_not() {
    let d = Dir::new();
    d.write("blurred.ron", &blurred_4096());
    let out = guarded(&d, &["info", "blurred.ron"]);
    let text = stdout(&out);
    assert!(
        text.contains("cost:     frame 0 at 64x36 with 16 of its 4096 samples per pixel: "),
        "{text}"
    );
    // A sample that could march a million steps on each of 1024 bounces.
    let deep = with_scene(
        &tiny_timeline(1, 8.0),
        "quality: (max_steps: 1000000), effects: (path_tracing: (max_bounces: 1024))",
    );
    d.write("deep.ron", &deep);
    let out = guarded(&d, &["info", "deep.ron"]);
    let text = stdout(&out);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        text.contains("cost:     not measured: one sample of frame 0 could compute "),
        "{text}"
    );
}

#[test]
fn info_sizes_its_thumbnail_alike_on_a_busy_machine() {
    // The thumbnail grew while each stage took under a tenth of a second
    // of wall-clock time: with the processors shared, `info` measured a
    // quarter of the pixels. Processor time per thread does not grow so.
    let d = Dir::new();
    d.write("blurred.ron", &blurred_4096());
    let cores = std::thread::available_parallelism().map_or(2, |n| n.get());
    let busy = std::sync::atomic::AtomicBool::new(true);
    let out = std::thread::scope(|s| {
        for _ in 0..3 * cores {
            s.spawn(|| {
                while busy.load(std::sync::atomic::Ordering::Relaxed) {
                    std::hint::spin_loop();
                }
            });
        }
        // One thread: on many cores a pool with room to spare hid the load.
        let mut info = d.command(&["info", "blurred.ron"]);
        info.env("RAYON_NUM_THREADS", "1");
        let out = d.run_guarded(info, GUARD_SECONDS);
        busy.store(false, std::sync::atomic::Ordering::Relaxed);
        out
    });
    let text = stdout(&out);
    assert!(
        text.contains("cost:     frame 0 at 64x36 with 16 "),
        "{text}"
    );
}

#[test]
fn info_looks_for_the_camera_inside_a_long_film_on_frames_spread_over_it() {
    // Inside the set every check takes all 10 000 iterations: a hundred
    // thousand frames were 1e9 iterations, tens of seconds. One frame in
    // a hundred is checked, and the warning says so.
    let d = Dir::new();
    let inside = tiny_timeline(100_000, 8.0)
        .replace(
            "position: (0, 0.5, 3.0)",
            "position: (0, 0.1, 0), target: (0, 0, 1)",
        )
        .replace("(iterations: 8)", "(iterations: 10000)");
    d.write("inside.ron", &inside);
    let out = guarded(&d, &["info", "inside.ron"]);
    let text = stdout(&out);
    assert!(
        text.contains(
            "the camera is inside the fractal in 1000 of the 1000 frames checked, one in 100 of \
             100000 (0-99900)"
        ),
        "{text}{}",
        stderr(&out)
    );
}

#[cfg(unix)]
#[test]
fn fifos_in_the_output_folder_neither_block_nor_stay() {
    // A FIFO under a frame's name and as the folder's lock: the frame is
    // rendered over it; a FIFO as the folder's record is refused.
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(1, 8.0));
    std::fs::create_dir_all(d.path().join("out/t")).unwrap();
    mkfifo(&d, "out/t/frame_00000.png");
    mkfifo(&d, "out/t/.mandelreel-job.lock");
    let out = guarded(&d, &["render", "t.ron"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let frame = std::fs::metadata(d.path().join("out/t/frame_00000.png")).unwrap();
    assert!(frame.is_file());
    std::fs::remove_file(d.path().join("out/t/mandelreel-job.json")).unwrap();
    mkfifo(&d, "out/t/mandelreel-job.json");
    let out = guarded(&d, &["status", "out/t"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    says(
        &out,
        "mandelreel-job.json: a named pipe (FIFO), not a regular file",
    );
}
