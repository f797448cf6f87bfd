use super::{film, write_plain};
use crate::output::exr::ExrCompression::{Dwaa, Piz, Zip};
use crate::output::frames::*;
use crate::output::names::FrameName;
use crate::output::{Aov, FileState, Format};
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
    let key = |format, hash: &str, aovs: &[Aov]| stored_key(format, hash, aovs, Zip);
    assert_eq!(key(Format::Png, &h, &layers), h);
    assert_eq!(key(Format::Exr, &h, &[]), h);
    assert_eq!(key(Format::Exr, &h, &layers), format!("{h}+normal,steps"));
    // So are a lossy compression (lossless ones hold the same samples),
    // and a PNG's kind where not the 8-bit one.
    assert_eq!(stored_key(Format::Exr, &h, &[], Piz), h);
    assert_eq!(
        stored_key(Format::Exr, &h, &layers, Dwaa),
        format!("{h}+dwaa+normal,steps")
    );
    assert_eq!(key(Format::Png16, &h, &[]), format!("{h}+png16"));
    assert_eq!(key(Format::Png16Alpha, &h, &[]), format!("{h}+png16alpha"));
    // A grade other than the default follows the light's hash in the
    // PNG's key alone: the EXR's and the checkpoint's are the light's.
    let mut g = s.clone();
    g.look.exposure = 2.0;
    g.look.tone_map = crate::color::ToneMap::Filmic;
    let graded = frame_hash(std::slice::from_ref(&g), 0, 4, 3);
    assert_eq!(graded, format!("{h}~exposure=2,Filmic"));
    assert_eq!(light_hash(&graded), h);
    assert_eq!(key(Format::Exr, &graded, &[]), h);
    assert_eq!(key(Format::Png, &graded, &[]), graded);
}

/// The digest of the inputs as `frame_hash` writes them for `s` at 4×3
/// (or `width`×`height`), with `extra` fields after the scenes.
fn inputs_digest(s: &Scene, [width, height]: [u32; 2], extra: &str) -> String {
    use sha2::{Digest, Sha256};
    let json = format!(
        r#"{{"renderer":"{}","revision":{},"frame_index":0,"width":{width},"height":{height},"scenes":{}{extra}}}"#,
        env!("CARGO_PKG_VERSION"),
        crate::RENDERER_REVISION,
        serde_json::to_string(std::slice::from_ref(s)).unwrap()
    );
    let digest = Sha256::digest(json.as_bytes());
    digest
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect::<String>()
}

#[test]
fn checking_hits_adds_its_revision_to_the_hash_and_other_frames_keep_theirs() {
    let off = Scene::default();
    assert_eq!(
        frame_hash(std::slice::from_ref(&off), 0, 4, 3),
        inputs_digest(&off, [4, 3], "")
    );
    let mut on = off.clone();
    on.quality.confirm_hits = true;
    let revision = format!(r#","confirm":{}"#, crate::march::CONFIRM_REVISION);
    assert_eq!(
        frame_hash(std::slice::from_ref(&on), 0, 4, 3),
        inputs_digest(&on, [4, 3], &revision)
    );
}

#[test]
fn rendering_in_f32_adds_its_revision_to_the_hash_and_other_frames_keep_theirs() {
    // A frame in f32 names the f32 revision; one asked in f32 but too fine
    // for it names only that it renders in f64.
    let mut s = Scene::default();
    s.fractal.precision = crate::fractal::Precision::F32;
    s.camera.target = crate::math::DVec3::new(0.5, 0.4, 0.4);
    let revision = format!(r#","f32":{}"#, crate::fractal::F32_REVISION);
    assert_eq!(
        frame_hash(std::slice::from_ref(&s), 0, 4, 3),
        inputs_digest(&s, [4, 3], &revision)
    );
    let fine = [1 << 20, 1 << 19];
    assert!(crate::deep::f32_too_coarse(&s, fine));
    assert_eq!(
        frame_hash(std::slice::from_ref(&s), 0, fine[0], fine[1]),
        inputs_digest(&s, fine, r#","f32_in_f64":true"#)
    );
}

#[test]
fn written_frames_carry_their_hash_and_leave_no_temporary() {
    let dir = tempfile::tempdir().unwrap();
    for format in [Format::Png, Format::Exr] {
        let path = dir.path().join(FrameName::default().file_name(0, format));
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
            let key = stored_key(format, "abc123", &[], Default::default());
            assert_eq!(state(&path, &key), FileState::Current);
            assert_eq!(state(&path, "other"), FileState::Stale);
            let missing = dir.path().join(FrameName::default().file_name(1, format));
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
        "frame_100000.png",
        ".frame_00002.png.partial",
        "frame_x.png",
        "frame_01.png",
        "shot_0003.png",
        "sheet.png",
    ] {
        std::fs::write(dir.path().join(name), b"").unwrap();
    }
    let names = |pattern: &str| -> Vec<String> {
        let pattern = FrameName::parse(pattern).unwrap();
        frame_files(dir.path(), Format::Png, &pattern)
            .unwrap()
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect()
    };
    // In frame order, not name order; each pattern's own names only.
    assert_eq!(
        names("frame_#####"),
        ["frame_00000.png", "frame_00001.png", "frame_100000.png"]
    );
    assert_eq!(names("frame_##"), ["frame_01.png", "frame_100000.png"]);
    assert_eq!(names("shot_####"), ["shot_0003.png"]);
}

#[test]
fn under_adaptive_sampling_the_grade_is_part_of_the_light() {
    // Adaptive sampling judges the graded image, so a checkpoint or an EXR
    // made under one exposure must not be taken for another's.
    let hashed = |adaptive: bool, exposure: f32| {
        let mut s = Scene::default();
        s.look.exposure = exposure;
        s.adaptive = adaptive.then(Default::default);
        frame_hash(&[s], 0, 8, 8)
    };
    let light = |adaptive, exposure| light_hash(&hashed(adaptive, exposure)).to_string();
    assert_eq!(light(false, 1.0), light(false, 2.0));
    assert_ne!(light(true, 1.0), light(true, 2.0));
    assert_ne!(hashed(true, 1.0), hashed(true, 2.0));
}
