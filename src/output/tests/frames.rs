use super::{film, write_plain};
use crate::output::frames::*;
use crate::output::{Aov, Format};
use crate::scene::Scene;
use std::path::Path;

#[test]
fn hash_changes_with_any_input() {
    let s = Scene::default();
    let h = frame_hash(std::slice::from_ref(&s), 0, 4, 3);
    assert_eq!(h.len(), 64);
    assert_eq!(h, frame_hash(std::slice::from_ref(&s), 0, 4, 3));
    assert_ne!(h, frame_hash(std::slice::from_ref(&s), 1, 4, 3));
    assert_ne!(h, frame_hash(std::slice::from_ref(&s), 0, 5, 3));
    assert_ne!(h, frame_hash(&[s.clone(), s.clone()], 0, 4, 3));
    let mut t = s.clone();
    t.fractal.power = 8.000001;
    assert_ne!(h, frame_hash(&[t], 0, 4, 3));
    // Extra layers are the EXR's alone: its key names them, in order.
    let layers = [Aov::Normal, Aov::Steps];
    assert_eq!(stored_key(Format::Png, &h, &layers), h);
    assert_eq!(stored_key(Format::Exr, &h, &[]), h);
    assert_eq!(
        stored_key(Format::Exr, &h, &layers),
        format!("{h}+normal,steps")
    );
    // A grade other than the default follows the light's hash in the
    // PNG's key alone: the EXR's and the checkpoint's are the light's.
    let mut g = s.clone();
    g.look.exposure = 2.0;
    g.look.tone_map = crate::color::ToneMap::Filmic;
    let graded = frame_hash(std::slice::from_ref(&g), 0, 4, 3);
    assert_eq!(graded, format!("{h}~exposure=2,Filmic"));
    assert_eq!(light_hash(&graded), h);
    assert_eq!(stored_key(Format::Exr, &graded, &[]), h);
    assert_eq!(stored_key(Format::Png, &graded, &[]), graded);
}

#[test]
fn written_frames_carry_their_hash_and_leave_no_temporary() {
    let dir = tempfile::tempdir().unwrap();
    for format in [Format::Png, Format::Exr] {
        let path = dir.path().join(frame_file_name(0, format));
        write_plain(&path, format, &film(), "abc123");
        assert!(path.exists());
        let leftovers: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().ends_with(".partial"))
            .collect();
        assert!(leftovers.is_empty(), "temporary files left behind");
        for thorough in [false, true] {
            let state = |path: &Path, key| file_state(path, format, key, thorough);
            assert_eq!(state(&path, "abc123"), FileState::Current);
            assert_eq!(state(&path, "other"), FileState::Stale);
            let missing = dir.path().join(frame_file_name(1, format));
            assert_eq!(state(&missing, "abc123"), FileState::Missing);
        }
    }
}

#[test]
fn frame_files_ignore_temporaries_and_other_names() {
    let dir = tempfile::tempdir().unwrap();
    for name in [
        "frame_00001.png",
        "frame_00000.png",
        ".frame_00002.png.partial",
        "frame_x.png",
        "sheet.png",
    ] {
        std::fs::write(dir.path().join(name), b"").unwrap();
    }
    let names: Vec<_> = frame_files(dir.path(), Format::Png)
        .unwrap()
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["frame_00000.png", "frame_00001.png"]);
}

#[test]
fn a_frame_number_is_the_last_digit_run_before_the_extension() {
    let number = |name: &str| frame_number(Path::new(name));
    assert_eq!(number("out/frame_00042.png"), Some(42));
    assert_eq!(number("shot_v2_0007.exr"), Some(7));
    assert_eq!(number("0119"), Some(119));
    assert_eq!(number("frame_00042_v2b.png"), None);
    assert_eq!(number("sheet.png"), None);
}
