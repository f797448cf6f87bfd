use crate::host::writer_tag;
use crate::output::atomic::{remove_stale_partials, write_atomic, write_new_text};

/// The names of the files in `dir`.
fn names_in(dir: &std::path::Path) -> Vec<String> {
    let entries = std::fs::read_dir(dir).unwrap();
    entries
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect()
}

#[test]
fn temporaries_are_hidden_beside_the_final_file() {
    // While it is written, a file is a hidden temporary beside the final one.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("frame_00042.png");
    write_atomic(&path, |_, named| {
        assert_eq!(named, path);
        let names = names_in(dir.path());
        assert_eq!(names.len(), 1, "{names:?}");
        assert!(names[0].starts_with(&format!(".frame_00042.png.{}", writer_tag())));
        assert!(names[0].ends_with(".partial"));
        Ok(())
    })
    .unwrap();
    assert!(path.exists());
}

#[test]
fn a_failed_write_names_the_final_file_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("frame_00007.exr");
    let full = || std::io::Error::from_raw_os_error(28);
    let e = write_atomic(&path, |_, named| {
        Err(crate::error::Error::io(named, full()))
    });
    let e = e.unwrap_err().to_string();
    let expected = format!("{}: No space left on device", path.display());
    assert!(e.starts_with(&expected), "{e}");
    assert!(names_in(dir.path()).is_empty());
}

#[test]
fn temporaries_of_dead_local_writers_go_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let host = writer_tag().split('.').next().unwrap().to_string();
    // pid 4194304 is above Linux's pid_max: never alive.
    let dead = format!(".frame_00003.png.{host}.4194304.Ab12Cd.partial");
    let alive = format!(".frame_00004.png.{}Zz99Yy.partial", writer_tag());
    let elsewhere = ".frame_00005.png.other-host.17.Qq11Ww.partial";
    for name in [dead.as_str(), alive.as_str(), elsewhere] {
        std::fs::write(dir.path().join(name), b"x").unwrap();
    }
    assert_eq!(remove_stale_partials(dir.path()).unwrap(), 1);
    assert!(!dir.path().join(&dead).exists());
    assert!(dir.path().join(&alive).exists());
    assert!(dir.path().join(elsewhere).exists());
}

#[test]
fn a_new_file_is_written_whole_and_never_over_another() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("new.ron");
    write_new_text(&path, "(fps: 1)").unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "(fps: 1)");
    let refused = write_new_text(&path, "(fps: 2)").unwrap_err();
    assert!(
        matches!(&refused, crate::error::Error::Io { cause, .. } if cause.kind() == std::io::ErrorKind::AlreadyExists),
        "{refused}"
    );
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "(fps: 1)");
    assert_eq!(names_in(dir.path()), ["new.ron"], "a temporary is left");
}
