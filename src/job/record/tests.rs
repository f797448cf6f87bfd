use super::*;
use crate::output::names::FrameName;
use crate::output::Aov;
use std::fs::File;

/// An 8×8 PNG job of `zoom.ron` over `frames`.
fn record(frames: (u32, u32)) -> JobRecord {
    JobRecord {
        renderer: "test".into(),
        timeline_path: "zoom.ron".into(),
        timeline_text: String::new(),
        width: 8,
        height: 8,
        formats: vec!["png".into()],
        frames,
        preview: false,
        aovs: Vec::new(),
        samples: None,
        outputs: Vec::new(),
    }
}

#[test]
fn each_format_keeps_its_own_range_layers_and_samples() {
    let dir = tempfile::tempdir().unwrap();
    // A record written before formats had their own: PNGs of 0..120.
    record((0, 120)).write(dir.path()).unwrap();
    let exr = OutputRecord {
        format: "exr".into(),
        frames: (0, 3),
        aovs: vec![Aov::Normal],
        samples: Some(2),
        exr_compression: Default::default(),
        frame_name: FrameName::default(),
    };
    let few_exrs = JobRecord {
        formats: vec!["exr".into()],
        frames: (0, 3),
        aovs: vec![Aov::Normal],
        samples: Some(2),
        outputs: vec![exr.clone()],
        ..record((0, 3))
    };
    few_exrs.record_in(dir.path(), |_| Ok(())).unwrap();
    let png = OutputRecord {
        format: "png".into(),
        frames: (0, 120),
        aovs: Vec::new(),
        samples: None,
        exr_compression: Default::default(),
        frame_name: FrameName::default(),
    };
    let merged = JobRecord::read(dir.path()).unwrap();
    assert_eq!(merged.outputs(), [exr.clone(), png.clone()]);
    assert_eq!((merged.frames, merged.formats.len()), ((0, 120), 2));
    // More EXRs widen the EXRs' span alone, and take the new samples.
    let more = OutputRecord {
        frames: (5, 8),
        samples: None,
        ..exr
    };
    JobRecord {
        outputs: vec![more.clone()],
        ..record((5, 8))
    }
    .record_in(dir.path(), |_| Ok(()))
    .unwrap();
    let merged = JobRecord::read(dir.path()).unwrap();
    let widened = OutputRecord {
        frames: (0, 8),
        ..more
    };
    assert_eq!(merged.outputs(), [widened, png]);
}

#[test]
fn frames_named_otherwise_replace_the_formats_range_not_widen_it() {
    let dir = tempfile::tempdir().unwrap();
    record((0, 120)).write(dir.path()).unwrap();
    let shots = OutputRecord {
        format: "png".into(),
        frames: (5, 8),
        aovs: Vec::new(),
        samples: None,
        exr_compression: Default::default(),
        frame_name: FrameName::parse("shot_####").unwrap(),
    };
    JobRecord {
        outputs: vec![shots.clone()],
        ..record((5, 8))
    }
    .record_in(dir.path(), |_| Ok(()))
    .unwrap();
    let merged = JobRecord::read(dir.path()).unwrap();
    assert_eq!(merged.outputs(), [shots]);
    let text = std::fs::read_to_string(dir.path().join(JOB_FILE)).unwrap();
    assert!(text.contains(r#""frame_name": "shot_####""#), "{text}");
}

#[test]
fn renders_started_together_each_add_their_range_to_the_record() {
    const WORKERS: u32 = 8;
    for _ in 0..20 {
        let dir = tempfile::tempdir().unwrap();
        // Another size is another sequence: its range is not kept.
        JobRecord {
            width: 9,
            ..record((100, 200))
        }
        .write(dir.path())
        .unwrap();
        let start = std::sync::Barrier::new(WORKERS as usize);
        std::thread::scope(|s| {
            for worker in 0..WORKERS {
                let (start, dir) = (&start, dir.path());
                s.spawn(move || {
                    start.wait();
                    record((worker * 10 + 5, worker * 10 + 10))
                        .record_in(dir, |_| Ok(()))
                        .unwrap();
                });
            }
        });
        let merged = JobRecord::read(dir.path()).unwrap();
        assert_eq!(
            merged.frames,
            (5, WORKERS * 10),
            "every worker's range is kept"
        );
        assert_eq!(merged.width, 8);
    }
    // A lock file this render cannot open for writing (another user's,
    // here a folder, which only opens for reading) does not stop it.
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join(JOB_LOCK)).unwrap();
    record((0, 3)).record_in(dir.path(), |_| Ok(())).unwrap();
    assert_eq!(JobRecord::read(dir.path()).unwrap().frames, (0, 3));
}

#[test]
fn the_check_of_the_record_there_runs_under_the_lock_and_can_stop_the_write() {
    let dir = tempfile::tempdir().unwrap();
    record((0, 3)).write(dir.path()).unwrap();
    let refused = JobRecord {
        width: 9,
        ..record((5, 6))
    }
    .record_in(dir.path(), |old| {
        assert_eq!(old.frames, (0, 3), "the check sees the record there");
        // Another render cannot take the lock while the check runs.
        let other = File::open(dir.path().join(JOB_LOCK)).unwrap();
        assert!(
            matches!(other.try_lock(), Err(std::fs::TryLockError::WouldBlock)),
            "the check runs under the folder's lock"
        );
        Err(Error::usage("--out", "another sequence"))
    });
    assert!(refused.is_err());
    let kept = JobRecord::read(dir.path()).unwrap();
    assert_eq!((kept.width, kept.frames), (8, (0, 3)), "nothing written");
}
