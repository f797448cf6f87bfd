//! This machine and its processes: its name, the tag a writer puts in its
//! temporary files' names, whether a process here has ended, and how old a
//! file is. Depends on nothing else in the crate.

use std::path::Path;

/// This machine's name, for temporary-file tags, claims and `status`.
pub fn host_name() -> String {
    // Read once a process: claims ask for it for every frame they look at.
    static NAME: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    NAME.get_or_init(|| {
        std::fs::read_to_string("/proc/sys/kernel/hostname")
            .ok()
            .map(|s| s.trim().to_string())
            .filter(|s| !s.is_empty())
            .or_else(|| std::env::var("HOSTNAME").ok())
            .unwrap_or_else(|| "unknown-host".into())
    })
    .clone()
}

/// `host.pid.`: written into every temporary file's name so a later run on
/// the same machine can tell whether its writer is still alive.
pub fn writer_tag() -> String {
    let host: String = host_name()
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '-'
            }
        })
        .collect();
    format!("{host}.{}.", std::process::id())
}

/// Whether the writer of `tagged` (a name ending in `writer_tag` and one
/// more part) is a dead process on this machine (Linux's /proc says who
/// lives).
pub fn writer_is_dead_here(tagged: &str) -> bool {
    let mut parts = tagged.rsplit('.');
    let (_random, pid, host) = (parts.next(), parts.next(), parts.next());
    let ours = writer_tag();
    let our_host = ours.split('.').next().unwrap_or_default();
    match (host, pid.and_then(|p| p.parse::<u32>().ok())) {
        (Some(h), Some(pid)) if h == our_host => gone_here(pid),
        _ => false,
    }
}

/// Whether process `pid` of this machine is known to have ended: Linux's
/// /proc has no such process (without /proc, nothing is known; nor where
/// /proc hides other users' processes, `hidepid`, which shows as no
/// process 1). A process that reused the pid is taken for alive.
pub fn gone_here(pid: u32) -> bool {
    pid != std::process::id()
        && Path::new("/proc/self").exists()
        && Path::new("/proc/1").exists()
        && !Path::new(&format!("/proc/{pid}")).exists()
}

/// This boot of this machine's kernel and this process's pid namespace
/// (`<boot id>/<namespace>`), where Linux tells: two processes with the same
/// host name see each other's pids only if these match (containers that
/// share a host name, cloned machines that kept one, do not).
pub fn pid_space() -> Option<String> {
    // Fixed for the life of a process: read once.
    static SPACE: std::sync::OnceLock<Option<String>> = std::sync::OnceLock::new();
    SPACE
        .get_or_init(|| {
            let boot = std::fs::read_to_string("/proc/sys/kernel/random/boot_id").ok()?;
            let namespace = std::fs::read_link("/proc/self/ns/pid").ok()?;
            Some(format!("{}/{}", boot.trim(), namespace.display()))
        })
        .clone()
}

/// How long ago `path` was last modified (`None` if that cannot be told).
pub fn file_age(path: &Path) -> Option<std::time::Duration> {
    std::fs::metadata(path)
        .ok()?
        .modified()
        .ok()?
        .elapsed()
        .ok()
}

/// Processor time this process has used, all threads, user and system, in
/// seconds; `None` where the system does not say. Unlike the wall clock,
/// it does not grow while other programs have the processors.
pub fn cpu_seconds() -> Option<f64> {
    #[cfg(unix)]
    {
        use nix::sys::resource::{getrusage, UsageWho};
        let usage = getrusage(UsageWho::RUSAGE_SELF).ok()?;
        let seconds = |t: nix::sys::time::TimeVal| t.tv_sec() as f64 + t.tv_usec() as f64 * 1e-6;
        Some(seconds(usage.user_time()) + seconds(usage.system_time()))
    }
    #[cfg(not(unix))]
    None
}
