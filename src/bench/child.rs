//! Renders as child processes: their arguments, and their wall time and peak
//! resident memory measured through the `measure` wrapper.

use crate::error::Error;
use crate::error::Result;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::process::Command;
use std::time::Instant;

/// One timed process: wall seconds and peak resident memory.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct Measurement {
    pub wall_s: f64,
    pub peak_rss_kib: u64,
    pub exit_code: i32,
}

/// Runs `program args…` as the only child of this process and measures it:
/// the body of the hidden `measure` subcommand.
pub fn measure_child(program: &Path, args: &[String]) -> Result<Measurement> {
    let start = Instant::now();
    let status = Command::new(program)
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .map_err(|e| Error::io(program, e))?;
    let wall_s = start.elapsed().as_secs_f64();
    Ok(Measurement {
        wall_s,
        peak_rss_kib: children_peak_rss_kib(),
        exit_code: status.code().unwrap_or(-1),
    })
}

#[cfg(unix)]
fn children_peak_rss_kib() -> u64 {
    use nix::sys::resource::{getrusage, UsageWho};
    // Linux reports ru_maxrss in KiB.
    getrusage(UsageWho::RUSAGE_CHILDREN).map_or(0, |u| u.max_rss().max(0) as u64)
}

#[cfg(not(unix))]
fn children_peak_rss_kib() -> u64 {
    0
}

/// Times `program args…` through the `measure` wrapper (this executable).
pub(super) fn timed(program: &Path, args: &[String]) -> Result<Measurement> {
    let exe = std::env::current_exe().map_err(|e| Error::io(Path::new("mandelreel"), e))?;
    let output = Command::new(&exe)
        .arg("measure")
        .arg("--")
        .arg(program)
        .args(args)
        .output()
        .map_err(|e| Error::io(&exe, e))?;
    let text = String::from_utf8_lossy(&output.stdout);
    let m: Measurement = serde_json::from_str(text.trim()).map_err(|e| {
        Error::io(
            &exe,
            std::io::Error::other(format!("measure wrapper: {e}: {text}")),
        )
    })?;
    if m.exit_code != 0 {
        return Err(Error::io(
            program,
            std::io::Error::other(format!(
                "exited with status {} running {}",
                m.exit_code,
                args.join(" ")
            )),
        ));
    }
    Ok(m)
}

/// The arguments of a mandelreel render of `scene` into `out`.
pub(super) fn render_args(
    timeline: &Path,
    out: &Path,
    threads: usize,
    extra: &[&str],
) -> Vec<String> {
    let mut args: Vec<String> = vec![
        "render".into(),
        timeline.display().to_string(),
        "--out".into(),
        out.display().to_string(),
        "--force".into(),
        "--quiet".into(),
        "--threads".into(),
        threads.to_string(),
    ];
    args.extend(extra.iter().map(|s| s.to_string()));
    args
}

/// The arguments of a Mandelbulber2 render of `fract` into `out` (a folder).
pub(super) fn mandelbulber_args(fract: &Path, out: &Path, keyframed: bool) -> Vec<String> {
    let mut args: Vec<String> = vec!["-n".into(), "-C".into()];
    if keyframed {
        args.push("-K".into());
    }
    let target = if keyframed {
        format!("{}/", out.display())
    } else {
        out.join("frame.png").display().to_string()
    };
    args.extend([
        "-f".into(),
        "png".into(),
        "-o".into(),
        target,
        "-O".into(),
        "opencl_enabled=0".into(),
        fract.display().to_string(),
    ]);
    args
}
