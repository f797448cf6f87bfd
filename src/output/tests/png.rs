use super::{film, write_plain};
use crate::output::frames::file_state;
use crate::output::FileState;
use crate::output::Format;

#[test]
fn a_png_cut_after_its_header_is_not_current() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("frame_00000.png");
    write_plain(&path, Format::Png, &film(), "abc");
    assert_eq!(
        file_state(&path, Format::Png, "abc", false),
        FileState::Current
    );
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() - 20]).unwrap();
    for thorough in [false, true] {
        let state = file_state(&path, Format::Png, "abc", thorough);
        assert_eq!(state, FileState::Damaged);
    }
}

#[test]
fn a_truncated_file_is_not_current() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("frame_00000.png");
    std::fs::write(&path, b"\x89PNG\r\n\x1a\n").unwrap();
    assert_eq!(
        file_state(&path, Format::Png, "abc", false),
        FileState::Damaged
    );
}
