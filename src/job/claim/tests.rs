use super::*;

/// Frame `frame_index`'s claim in `dir`, named as frames are by default.
fn claim_path(dir: &Path, frame_index: u32) -> PathBuf {
    let name = crate::output::names::FrameName::default().hidden(frame_index, "claim");
    dir.join(name)
}

#[test]
fn a_run_record_comes_back_after_another_render_removed_it() {
    // A render stopped past the timeout (SIGSTOP) has its record removed
    // as dead by the next render; once it beats again, it is back.
    let dir = tempfile::tempdir().unwrap();
    let timeout = Duration::from_millis(200);
    let run = announce_run(dir.path(), timeout).unwrap();
    let records = || runs(dir.path());
    assert_eq!(records().len(), 1);
    std::fs::remove_file(&records()[0].0).unwrap();
    let removed = now_ms();
    // A busy machine may hold the heartbeat back: wait for it, not a time.
    let back = poll_for(|| records().pop().filter(|(_, r)| r.heartbeat_ms >= removed));
    assert!(back.is_some(), "the heartbeat wrote it again");
    assert_eq!(live_runs(dir.path(), Duration::from_secs(60)).len(), 1);
    drop(run);
    assert!(records().is_empty(), "removed when the render ends");
}

/// `found` tried every 10 ms until it gives something, for at most 20 s.
fn poll_for<T>(mut found: impl FnMut() -> Option<T>) -> Option<T> {
    let start = std::time::Instant::now();
    while start.elapsed() < Duration::from_secs(20) {
        if let Some(t) = found() {
            return Some(t);
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    None
}

#[test]
fn one_claim_at_a_time_released_on_drop() {
    let dir = tempfile::tempdir().unwrap();
    let timeout = Duration::from_secs(60);
    let Attempt::Claimed(claim) = try_claim(&claim_path(dir.path(), 3), timeout).unwrap() else {
        panic!("a free frame can be claimed");
    };
    assert!(claim_path(dir.path(), 3).exists());
    assert!(matches!(
        try_claim(&claim_path(dir.path(), 3), timeout).unwrap(),
        Attempt::Held(_)
    ));
    drop(claim);
    assert!(!claim_path(dir.path(), 3).exists());
    assert!(matches!(
        try_claim(&claim_path(dir.path(), 3), timeout).unwrap(),
        Attempt::Claimed(_)
    ));
}

/// The claim of a worker that stopped beating two minutes ago, under the
/// token "dead-token".
fn write_dead_claim(dir: &Path, frame_index: u32) -> ClaimRecord {
    let dead = ClaimRecord {
        host: "gone".into(),
        pid: 1,
        token: "dead-token".into(),
        heartbeat_ms: now_ms() - 120_000,
        pid_space: None,
    };
    write_record(&claim_path(dir, frame_index), &dead).unwrap();
    dead
}

#[test]
fn a_takeover_marker_blocks_until_it_is_older_than_the_timeout() {
    let dir = tempfile::tempdir().unwrap();
    let dead = write_dead_claim(dir.path(), 5);
    let timeout = Duration::from_secs(60);
    // Another worker has just begun taking the dead claim over.
    let marker = takeover_path(&claim_path(dir.path(), 5), "dead-token", 0);
    let file = std::fs::File::create(&marker).unwrap();
    assert!(matches!(
        try_claim(&claim_path(dir.path(), 5), timeout).unwrap(),
        Attempt::Held(_)
    ));
    assert_eq!(read_claim(&claim_path(dir.path(), 5)).unwrap(), dead);
    // That worker died before writing its claim: once its marker is older
    // than the timeout, the frame is taken over instead of blocked forever.
    file.set_modified(std::time::SystemTime::now() - Duration::from_secs(120))
        .unwrap();
    drop(file);
    let Attempt::Claimed(ours) = try_claim(&claim_path(dir.path(), 5), timeout).unwrap() else {
        panic!("a stale marker does not block the frame");
    };
    assert_eq!(
        read_claim(&claim_path(dir.path(), 5)).unwrap().pid,
        std::process::id()
    );
    // The stale marker stays (deleting it could let a second taker win
    // it too): this takeover won the next generation's, which blocks a
    // worker that still sees the dead claim (put back here for it).
    let next = takeover_path(&claim_path(dir.path(), 5), "dead-token", 1);
    assert!(marker.exists() && next.exists());
    let ours_record = read_claim(&claim_path(dir.path(), 5)).unwrap();
    let seen = write_dead_claim(dir.path(), 5);
    assert!(matches!(
        try_claim(&claim_path(dir.path(), 5), timeout).unwrap(),
        Attempt::Held(held) if held == seen
    ));
    write_record(&claim_path(dir.path(), 5), &ours_record).unwrap();
    // Done: the claim and both markers go.
    drop(ours);
    assert!(!claim_path(dir.path(), 5).exists());
    assert!(!marker.exists() && !next.exists());
}

#[test]
fn a_dead_claim_is_taken_over_exactly_once() {
    let dir = tempfile::tempdir().unwrap();
    write_dead_claim(dir.path(), 7);
    let timeout = Duration::from_secs(60);
    let first = try_claim(&claim_path(dir.path(), 7), timeout).unwrap();
    let Attempt::Claimed(ours) = first else {
        panic!("a claim two minutes old is taken over");
    };
    // A second worker that read the dead claim before ours replaced it
    // (put back here, to be what it sees) loses the takeover: our marker
    // for that dead claim stands, and it is told the frame is held.
    let ours_record = read_claim(&claim_path(dir.path(), 7)).unwrap();
    let dead = write_dead_claim(dir.path(), 7);
    assert!(takeover_path(&claim_path(dir.path(), 7), &dead.token, 0).exists());
    assert!(matches!(
        try_claim(&claim_path(dir.path(), 7), timeout).unwrap(),
        Attempt::Held(held) if held == dead
    ));
    write_record(&claim_path(dir.path(), 7), &ours_record).unwrap();
    let now = read_claim(&claim_path(dir.path(), 7)).unwrap();
    assert_eq!(now.pid, std::process::id());
    drop(ours);
    assert!(!claim_path(dir.path(), 7).exists());
}

#[test]
fn an_empty_claim_left_by_a_crash_is_taken_over_once_it_is_old() {
    let dir = tempfile::tempdir().unwrap();
    let path = claim_path(dir.path(), 2);
    std::fs::write(&path, b"").unwrap();
    let timeout = Duration::from_secs(60);
    // Fresh: it may be being written; leave it.
    assert!(matches!(
        try_claim(&claim_path(dir.path(), 2), timeout).unwrap(),
        Attempt::Held(_)
    ));
    // Two minutes old: dead; taken over.
    let old = SystemTime::now() - Duration::from_secs(120);
    std::fs::File::options()
        .write(true)
        .open(&path)
        .unwrap()
        .set_modified(old)
        .unwrap();
    let Attempt::Claimed(claim) = try_claim(&claim_path(dir.path(), 2), timeout).unwrap() else {
        panic!("an old empty claim is taken over");
    };
    assert_eq!(read_claim(&path).unwrap().pid, std::process::id());
    drop(claim);
    assert!(
        std::fs::read_dir(dir.path()).unwrap().next().is_none(),
        "nothing left behind"
    );
}

#[test]
fn a_claim_of_an_ended_process_on_this_machine_is_taken_over_at_once() {
    // A worker stopped by Ctrl-C leaves a claim with a fresh heartbeat:
    // on this machine its ended process shows, and the frame is free;
    // while the process lives, and on any other machine, it is held.
    if crate::host::pid_space().is_none() || !Path::new("/proc/1").exists() {
        return; // nothing tells an ended process without /proc
    }
    let dir = tempfile::tempdir().unwrap();
    let timeout = Duration::from_secs(300);
    let mut worker = std::process::Command::new("sleep")
        .arg("30")
        .spawn()
        .unwrap();
    let pid = worker.id();
    let fresh = |host: String, pid_space: Option<String>| ClaimRecord {
        host,
        pid,
        token: format!("token-{pid}"),
        heartbeat_ms: now_ms(),
        pid_space,
    };
    let here = fresh(crate::host::host_name(), crate::host::pid_space());
    write_record(&claim_path(dir.path(), 4), &here).unwrap();
    assert!(matches!(
        try_claim(&claim_path(dir.path(), 4), timeout).unwrap(),
        Attempt::Held(_)
    ));
    worker.kill().unwrap();
    worker.wait().unwrap();
    assert!(!is_live(&here, timeout));
    // Another machine; this host name in another pid namespace (a
    // container sharing it), or a claim that does not say: alive.
    let space = crate::host::pid_space();
    assert!(is_live(&fresh("another-machine".into(), space), timeout));
    let elsewhere = Some("another-boot/pid:[1]".to_string());
    assert!(is_live(
        &fresh(crate::host::host_name(), elsewhere),
        timeout
    ));
    assert!(is_live(&fresh(crate::host::host_name(), None), timeout));
    let Attempt::Claimed(claim) = try_claim(&claim_path(dir.path(), 4), timeout).unwrap() else {
        panic!("the ended worker's claim is taken over");
    };
    let ours = read_claim(&claim_path(dir.path(), 4)).unwrap();
    assert_eq!(ours.pid, std::process::id());
    drop(claim);
}

#[test]
fn heartbeat_keeps_a_long_claim_alive() {
    let dir = tempfile::tempdir().unwrap();
    let timeout = Duration::from_millis(400);
    let Attempt::Claimed(_claim) = try_claim(&claim_path(dir.path(), 1), timeout).unwrap() else {
        panic!("free frame");
    };
    let first = read_claim(&claim_path(dir.path(), 1)).unwrap();
    // Still the same claim, beating, longer than its timeout after it began.
    let later = poll_for(|| {
        read_claim(&claim_path(dir.path(), 1))
            .filter(|r| r.heartbeat_ms > first.heartbeat_ms + 2 * timeout.as_millis() as u64)
    });
    assert_eq!(later.map(|r| r.token), Some(first.token));
}

#[test]
fn a_claim_appears_whole_never_empty() {
    // A worker killed between creating its claim and filling it would
    // leave an empty claim no one can name or see die: frames then wait
    // out the whole timeout. A reader spinning on the path never sees one.
    let dir = tempfile::tempdir().unwrap();
    let timeout = Duration::from_secs(60);
    let done = std::sync::atomic::AtomicBool::new(false);
    let rounds = 400;
    let empty_seen = std::thread::scope(|s| {
        let watcher = s.spawn(|| {
            let mut empty = 0;
            while !done.load(std::sync::atomic::Ordering::Relaxed) {
                for frame in 0..rounds {
                    let path = claim_path(dir.path(), frame);
                    if std::fs::metadata(&path).is_ok_and(|m| m.len() == 0) {
                        empty += 1;
                    }
                }
            }
            empty
        });
        // Each released at once: one heartbeat thread at a time, not 400.
        let claimed: Vec<bool> = (0..rounds)
            .map(|frame| {
                let attempt = try_claim(&claim_path(dir.path(), frame), timeout).unwrap();
                matches!(attempt, Attempt::Claimed(_))
            })
            .collect();
        done.store(true, std::sync::atomic::Ordering::Relaxed);
        assert!(claimed.iter().all(|&c| c));
        watcher.join().unwrap()
    });
    assert_eq!(empty_seen, 0, "claims seen empty");
}
