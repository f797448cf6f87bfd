//! Opening the files a user names (a timeline, an environment map, an
//! output folder's record): regular files only, opened without waiting on a
//! FIFO, and read up to a size cap, so no path can hang mandelreel or fill
//! the memory (`/dev/zero`, a named pipe, a device).

use std::fs::{File, FileType, OpenOptions};
use std::io::{self, Read};
use std::path::Path;

/// What a file that is not a regular file is, for messages.
fn kind(file_type: FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if file_type.is_fifo() {
            return "a named pipe (FIFO)";
        }
        if file_type.is_char_device() || file_type.is_block_device() {
            return "a device";
        }
        if file_type.is_socket() {
            return "a socket";
        }
    }
    if file_type.is_dir() {
        "a folder"
    } else {
        "not a regular file"
    }
}

/// The error for a path that is not a regular file.
fn not_regular(file_type: FileType) -> io::Error {
    let what = kind(file_type);
    io::Error::new(
        io::ErrorKind::InvalidInput,
        format!("{what}, not a regular file: only regular files are read"),
    )
}

/// Opens `path` (links followed) for reading if it is a regular file. Its
/// type is checked before opening (opening a device can act on it) and
/// again on the open file (it may have been swapped in between); the open
/// does not block, since opening a FIFO for reading waits for a writer.
pub fn open_regular(path: &Path) -> io::Result<File> {
    let before = std::fs::metadata(path)?.file_type();
    if !before.is_file() {
        return Err(not_regular(before));
    }
    let mut options = OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        // Reads of a regular file ignore the flag.
        options.custom_flags(nix::fcntl::OFlag::O_NONBLOCK.bits());
    }
    let file = options.open(path)?;
    let after = file.metadata()?.file_type();
    if !after.is_file() {
        return Err(not_regular(after));
    }
    Ok(file)
}

/// Every byte of `file`, or an error of kind `FileTooLarge` once it holds
/// more than `limit` bytes: the read stops there, whatever the file's
/// length says (a file under /proc says 0 and is not).
pub fn read_at_most(file: File, limit: u64) -> io::Result<Vec<u8>> {
    let mut bytes = Vec::new();
    file.take(limit.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(limit));
    }
    Ok(bytes)
}

/// The error of a file longer than `limit` bytes.
pub fn too_large(limit: u64) -> io::Error {
    io::Error::new(
        io::ErrorKind::FileTooLarge,
        format!("larger than {}, the most read", bytes_shown(limit)),
    )
}

/// A byte count as messages show it: in MiB or GiB when whole.
pub fn bytes_shown(bytes: u64) -> String {
    match bytes {
        b if b >= 1 << 30 && b % (1 << 30) == 0 => format!("{} GiB", b >> 30),
        b if b >= 1 << 20 && b % (1 << 20) == 0 => format!("{} MiB", b >> 20),
        b => format!("{b} bytes"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_regular_files_open_and_reads_stop_at_the_cap() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.ron");
        std::fs::write(&path, b"0123456789").unwrap();
        let read = |limit| read_at_most(open_regular(&path).unwrap(), limit);
        assert_eq!(read(10).unwrap(), b"0123456789");
        let e = read(9).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::FileTooLarge);
        assert!(e.to_string().contains("larger than 9 bytes"), "{e}");
        let e = open_regular(dir.path()).unwrap_err();
        assert!(
            e.to_string().starts_with("a folder, not a regular file"),
            "{e}"
        );
        #[cfg(unix)]
        {
            let e = open_regular(Path::new("/dev/zero")).unwrap_err();
            assert!(e.to_string().starts_with("a device"), "{e}");
        }
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_is_refused_at_once_without_a_writer() {
        // Opened plainly, a FIFO with no writer blocks this test forever.
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe.ron");
        nix::unistd::mkfifo(&fifo, nix::sys::stat::Mode::S_IRWXU).unwrap();
        let e = open_regular(&fifo).unwrap_err();
        assert!(e.to_string().starts_with("a named pipe (FIFO)"), "{e}");
    }

    #[test]
    fn byte_counts_read_in_whole_units() {
        assert_eq!(bytes_shown(16 << 20), "16 MiB");
        assert_eq!(bytes_shown(2 << 30), "2 GiB");
        assert_eq!(bytes_shown(1000), "1000 bytes");
    }
}
