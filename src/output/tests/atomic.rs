use crate::host::writer_tag;
use crate::output::atomic::{remove_stale_partials, write_atomic};

#[test]
fn temporaries_are_hidden_beside_the_final_file() {
    // While it is written, a file is a hidden temporary beside the final one.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("frame_00042.png");
    write_atomic(&path, |_, t| {
        let name = t.file_name().unwrap().to_string_lossy().into_owned();
        assert_eq!(t.parent(), Some(dir.path()));
        assert!(name.starts_with(&format!(".frame_00042.png.{}", writer_tag())));
        assert!(name.ends_with(".partial"));
        Ok(())
    })
    .unwrap();
    assert!(path.exists());
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
