//! Claim files: how any number of `render --claim` workers on a shared output
//! folder take frames one at a time, with no server between them.
//!
//! A worker claims frame N by creating `.frame_0000N.claim` exclusively (the
//! file system decides the one winner), whole from its first instant where
//! the file system can rename without replacing or link, holding its host,
//! pid, a unique token and a heartbeat time, which a background thread
//! refreshes while the frame renders. A claim whose heartbeat is older than
//! the timeout belongs to a dead worker; taking it over first needs
//! `.frame_0000N.takeover-<its token>.0`, again created exclusively, so each dead claim is taken over exactly once.
//! A marker older than the timeout was left by a taker that died before
//! writing its claim; the next generation's marker (`.1`, …) decides then.
//! Markers are never deleted while a takeover may be deciding, so no two
//! workers can win one generation.
//! Claims are named after the frame's files (`--frame-name shot_####`:
//! `.shot_0042.claim`), so workers on frames of other names never meet.
//! Heartbeats compare clocks across machines: cluster nodes must keep them in
//! step (NTP), to well within the timeout.

use crate::error::{Error, Result};
use crate::interrupt::Registered;
use serde::{Deserialize, Serialize};
use std::fs::OpenOptions;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{channel, RecvTimeoutError, Sender};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

/// What a claim file holds.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ClaimRecord {
    pub host: String,
    pub pid: u32,
    /// Unique per claim: names the takeover marker of this claim.
    pub token: String,
    /// Last sign of life, milliseconds since the Unix epoch.
    pub heartbeat_ms: u64,
    /// Where `pid` means this process (`host::pid_space`); a claim
    /// without it is only ever taken over after its timeout.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pid_space: Option<String>,
}

impl ClaimRecord {
    /// A record for this process, with a fresh token and heartbeat.
    fn mine() -> ClaimRecord {
        let (host, pid) = (crate::host::host_name(), std::process::id());
        let nanos = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map(|d| d.as_nanos())
            .unwrap_or(0);
        ClaimRecord {
            token: format!("{host}-{pid}-{nanos}"),
            host,
            pid,
            heartbeat_ms: now_ms(),
            pid_space: crate::host::pid_space(),
        }
    }

    /// `host:pid`, as messages and `status` name a worker.
    pub fn who(&self) -> String {
        format!("{}:{}", self.host, self.pid)
    }
}

/// The prefix of run records' file names (`announce_run`).
const RUN_PREFIX: &str = ".mandelreel-run-";

/// Says that a render runs in `dir`, until the guard is dropped: a record
/// like a claim's (`.mandelreel-run-<token>`), its heartbeat refreshed every
/// quarter `timeout`, so `status` can tell a running render from a dead
/// one whatever its kind (plain, shard or claim worker). Records of renders
/// that are gone (`is_live`) are removed first.
pub fn announce_run(dir: &Path, timeout: Duration) -> Result<Claim> {
    for (path, record) in runs(dir) {
        if !is_live(&record, timeout) {
            let _ = std::fs::remove_file(path);
        }
    }
    let record = ClaimRecord::mine();
    let path = dir.join(format!("{RUN_PREFIX}{}", record.token));
    // Registered first: an interrupt then removes it however far this got.
    let release = released_on_interrupt(&path, &record.token, &[]);
    write_record(&path, &record)?;
    Ok(Claim::start(
        path,
        record,
        timeout / 4,
        Vec::new(),
        false,
        release,
    ))
}

/// The renders running in `dir` (`announce_run`), by their records.
pub fn live_runs(dir: &Path, timeout: Duration) -> Vec<ClaimRecord> {
    runs(dir)
        .into_iter()
        .map(|(_, record)| record)
        .filter(|record| is_live(record, timeout))
        .collect()
}

/// Every run record in `dir`, live or not, that can be read.
fn runs(dir: &Path) -> Vec<(PathBuf, ClaimRecord)> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    entries
        .filter_map(|e| e.ok())
        .filter(|e| {
            // Not the temporaries a record is written through.
            let name = e.file_name().to_string_lossy().into_owned();
            name.starts_with(RUN_PREFIX) && !name.ends_with(".partial")
        })
        .filter_map(|e| Some((e.path(), read_claim(&e.path())?)))
        .collect()
}

/// The marker that decides who takes over the claim at `claim` held by
/// `token`: `.frame_00042.takeover-<token>.0` beside `.frame_00042.claim`.
fn takeover_path(claim: &Path, token: &str, generation: u32) -> PathBuf {
    let name = claim.file_name().unwrap_or_default().to_string_lossy();
    let stem = name.strip_suffix(".claim").unwrap_or(&name);
    claim.with_file_name(format!("{stem}.takeover-{token}.{generation}"))
}

fn now_ms() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_millis() as u64)
        .unwrap_or(0)
}

/// Reads a claim file; `None` if it is missing or unreadable (a claim being
/// replaced is renamed into place whole, so a reader never sees half of one).
pub fn read_claim(path: &Path) -> Option<ClaimRecord> {
    // A claim is a line of JSON; a FIFO or a huge file in its place is none.
    let file = crate::input::open_regular(path).ok()?;
    let text = crate::input::read_at_most(file, 1 << 16).ok()?;
    serde_json::from_slice(&text).ok()
}

/// Whether a claim's worker may still be at work: its heartbeat is younger
/// than `timeout`, and it is not a process of this machine known to have
/// ended (a worker stopped by Ctrl-C or `kill -9` leaves its claim behind;
/// one whose pids this process sees, the same host, boot and pid
/// namespace, is taken over at once, any other after the timeout).
pub fn is_live(record: &ClaimRecord, timeout: Duration) -> bool {
    let beating = now_ms().saturating_sub(record.heartbeat_ms) < timeout.as_millis() as u64;
    beating
        && !(record.host == crate::host::host_name()
            && record.pid_space.is_some()
            && record.pid_space == crate::host::pid_space()
            && crate::host::gone_here(record.pid))
}

/// Replaces `path` with `record`, atomically (temporary file, then rename).
fn write_record(path: &Path, record: &ClaimRecord) -> Result<()> {
    let json = serde_json::to_string(record).expect("a claim record always serialises");
    crate::output::atomic::write_atomic(path, |w, temp| {
        w.write_all(json.as_bytes()).map_err(|e| Error::io(temp, e))
    })
}

/// Outcome of trying to claim a frame.
pub enum Attempt {
    /// The frame is ours until the guard is released or dropped.
    Claimed(Claim),
    /// Another live worker holds it.
    Held(ClaimRecord),
}

/// The shortest time between heartbeats: a tiny `--claim-timeout` must
/// not turn the thread into a loop of writes.
const HEARTBEAT_FLOOR: Duration = Duration::from_millis(50);

/// A held claim; a thread keeps its heartbeat fresh until it is dropped,
/// which also removes the claim file, as an interrupt (Ctrl-C) does: so
/// another worker can take the frame at once.
pub struct Claim {
    path: PathBuf,
    /// If it took a dead claim over: the marker it created, and the stale
    /// ones of earlier generations before it.
    markers: Vec<PathBuf>,
    token: String,
    /// Dropped (or sent on) to stop the heartbeat: its thread wakes at once,
    /// so a render's end waits for no tick.
    stop: Option<Sender<()>>,
    heartbeat: Option<std::thread::JoinHandle<()>>,
    _released_on_interrupt: crate::interrupt::Registered,
}

/// Removes the claim at `path` if it still holds `token` (another worker
/// may have taken it over), and the takeover `markers` it was won with.
fn release(path: &Path, token: &str, markers: &[PathBuf]) {
    if read_claim(path).is_some_and(|r| r.token == token) {
        let _ = std::fs::remove_file(path);
    }
    // The markers of the dead claim this one replaced have served their
    // purpose. (Only those: another may guard a takeover still going on.)
    for marker in markers {
        let _ = std::fs::remove_file(marker);
    }
}

/// `release` of this claim, run on an interrupt (`interrupt::on_interrupt`).
fn released_on_interrupt(path: &Path, token: &str, markers: &[PathBuf]) -> Registered {
    crate::interrupt::hold().on_interrupt(releaser(path, token, markers))
}

/// A closure that runs `release` on copies of its arguments.
fn releaser(path: &Path, token: &str, markers: &[PathBuf]) -> impl FnOnce() + Send + 'static {
    let (path, token, markers) = (path.to_path_buf(), token.to_string(), markers.to_vec());
    move || release(&path, &token, &markers)
}

impl Claim {
    /// The token of the record this guard keeps (`ClaimRecord::token`).
    pub fn token(&self) -> &str {
        &self.token
    }

    /// A claim on `path` whose heartbeat a thread refreshes every
    /// `interval`. A `contested` path (a frame's claim, which a worker may
    /// take over) is refreshed only while it still holds this record; a
    /// path only this process writes (a run record) is written again
    /// even if another render removed it as dead while this one was
    /// stopped (SIGSTOP, a stalled file system).
    fn start(
        path: PathBuf,
        record: ClaimRecord,
        interval: Duration,
        markers: Vec<PathBuf>,
        contested: bool,
        released_on_interrupt: Registered,
    ) -> Claim {
        let interval = interval.max(HEARTBEAT_FLOOR);
        let (stop, stopped) = channel::<()>();
        let heartbeat = {
            let (path, mut record) = (path.clone(), record.clone());
            std::thread::spawn(move || {
                while let Err(RecvTimeoutError::Timeout) = stopped.recv_timeout(interval) {
                    let ours = || read_claim(&path).is_some_and(|r| r.token == record.token);
                    if !contested || ours() {
                        record.heartbeat_ms = now_ms();
                        let _ = write_record(&path, &record);
                    }
                }
            })
        };
        Claim {
            path,
            markers,
            token: record.token,
            stop: Some(stop),
            heartbeat: Some(heartbeat),
            _released_on_interrupt: released_on_interrupt,
        }
    }
}

impl Drop for Claim {
    fn drop(&mut self) {
        drop(self.stop.take());
        if let Some(h) = self.heartbeat.take() {
            let _ = h.join();
        }
        release(&self.path, &self.token, &self.markers);
    }
}

/// Creates the claim `path` holding `record`, with its release registered
/// first (an interrupt then removes it however far this got); `None` where
/// a claim is there. It is written whole through a temporary, so a worker
/// killed here leaves no empty claim to wait out; where one is there
/// already nothing is written, as workers look at held frames every second.
fn create(path: &Path, record: &ClaimRecord) -> Result<Option<Registered>> {
    if std::fs::symlink_metadata(path).is_ok() {
        return Ok(None);
    }
    let release = released_on_interrupt(path, &record.token, &[]);
    let json = serde_json::to_string(record).expect("a claim record always serialises");
    match crate::output::atomic::write_new_text(path, &json) {
        Ok(()) => Ok(Some(release)),
        Err(e) if e.is_already_exists() => Ok(None),
        Err(e) => Err(e),
    }
}

/// Tries to claim a frame by its claim file, `path` (`Plan::claim_path`).
/// A claim older than `timeout` is taken over; the heartbeat is refreshed
/// every quarter timeout.
pub fn try_claim(path: &Path, timeout: Duration) -> Result<Attempt> {
    let path = path.to_path_buf();
    let record = ClaimRecord::mine();
    let interval = timeout / 4;
    let claimed = |release| {
        let (path, record) = (path.clone(), record.clone());
        Attempt::Claimed(Claim::start(
            path,
            record,
            interval,
            Vec::new(),
            true,
            release,
        ))
    };
    for _ in 0..3 {
        if let Some(release) = create(&path, &record)? {
            return Ok(claimed(release));
        }
        let held = match read_claim(&path) {
            Some(held) => held,
            None => {
                // Unreadable: being written this instant, or left empty by a
                // worker that died between creating and filling it. Judge the
                // latter by the file's age, under a token naming that age.
                let age_ms = std::fs::metadata(&path)
                    .and_then(|m| m.modified())
                    .ok()
                    .and_then(|t| t.duration_since(UNIX_EPOCH).ok())
                    .map(|d| d.as_millis() as u64);
                match age_ms {
                    Some(modified) => ClaimRecord {
                        host: "unknown".into(),
                        pid: 0,
                        token: format!("unreadable-{modified}"),
                        heartbeat_ms: modified,
                        pid_space: None,
                    },
                    None => {
                        // Vanished: look again.
                        std::thread::sleep(Duration::from_millis(20));
                        continue;
                    }
                }
            }
        };
        if held.token == record.token {
            // Ours after all: NFS may answer a link retried after it was
            // made with "exists".
            return Ok(claimed(released_on_interrupt(&path, &record.token, &[])));
        }
        if is_live(&held, timeout) {
            return Ok(Attempt::Held(held));
        }
        // A dead worker's claim: one takeover per dead claim, decided by who
        // creates its marker first; a stale marker hands the decision to the
        // next generation's.
        let mut generation = 0;
        let (marker, release) = loop {
            let marker = takeover_path(&path, &held.token, generation);
            let mut lock = crate::interrupt::hold();
            match OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&marker)
            {
                Ok(_) => {
                    let markers: Vec<PathBuf> = (0..=generation)
                        .map(|g| takeover_path(&path, &held.token, g))
                        .collect();
                    let release = releaser(&path, &record.token, &markers);
                    break (marker, lock.on_interrupt(release));
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    // Someone else is taking it over; their claim will show
                    // up live. Unless the marker is older than the timeout:
                    // its maker died before writing its claim.
                    if crate::host::file_age(&marker).is_some_and(|age| age > timeout) {
                        generation += 1;
                        continue;
                    }
                    return Ok(Attempt::Held(held));
                }
                Err(e) => return Err(Error::io(&marker, e)),
            }
        };
        if let Err(e) = write_record(&path, &record) {
            // A marker left behind would block this frame for good.
            let _ = std::fs::remove_file(&marker);
            return Err(e);
        }
        let markers = (0..=generation)
            .map(|g| takeover_path(&path, &held.token, g))
            .collect();
        return Ok(Attempt::Claimed(Claim::start(
            path, record, interval, markers, true, release,
        )));
    }
    // The claim kept vanishing and reappearing: treat it as held this round.
    Ok(Attempt::Held(read_claim(&path).unwrap_or(record)))
}

#[cfg(test)]
mod tests;
