//! The library's one error type, grouped by kind. Every variant says where:
//! the file with line and column, the field path inside a timeline, or the
//! path on disk.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The timeline is not valid RON or does not fit the schema.
    #[error("{file}:{line}:{column}: {message}")]
    Syntax {
        file: PathBuf,
        line: usize,
        column: usize,
        message: String,
    },
    /// The timeline parses but a value is unusable.
    #[error("{file}{}: {path}: {message}", place.map(|p| format!(":{}:{}", p.line, p.column)).unwrap_or_default())]
    Invalid {
        file: PathBuf,
        /// Where the offending value is written, or the block that would
        /// hold it where a default is at fault.
        place: Option<Place>,
        /// Field path, e.g. `tracks["camera.position"].keys[3].time`.
        path: String,
        message: String,
    },
    /// A command-line value is unusable (frame range, size, pixel).
    #[error("{option}: {message}")]
    Usage { option: String, message: String },
    /// Reading or writing a file failed. The system's message is part of
    /// this one, not a source of its own, so an error chain printed whole
    /// (`{:#}`) says it once.
    #[error("{}: {cause}", path.display())]
    Io {
        path: PathBuf,
        cause: std::io::Error,
    },
    /// Encoding or decoding an image failed.
    #[error("{}: {message}", path.display())]
    Image { path: PathBuf, message: String },
    /// A frame does not match what it is measured against (another size,
    /// no reference frame of its number).
    #[error("frame {frame}: {message}")]
    Frame { frame: u32, message: String },
}

impl Error {
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            cause: source,
        }
    }

    pub fn usage(option: &str, message: impl Into<String>) -> Self {
        Error::Usage {
            option: option.to_string(),
            message: message.into(),
        }
    }

    /// True where a file that had to be new was already there.
    pub fn is_already_exists(&self) -> bool {
        matches!(self, Error::Io { cause, .. } if cause.kind() == std::io::ErrorKind::AlreadyExists)
    }

    /// True for errors in the user's input (timeline or flags) rather than the machine.
    pub fn is_input_error(&self) -> bool {
        matches!(
            self,
            Error::Syntax { .. } | Error::Invalid { .. } | Error::Usage { .. }
        )
    }
}

/// A place in a text file: 1-based line and column (columns count characters,
/// as RON's do).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Place {
    pub line: usize,
    pub column: usize,
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
