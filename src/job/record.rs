//! The job record: what an output folder was rendered from (`JOB_FILE`),
//! merged under the folder's lock by every render into it, and the
//! `Scaffold` that undoes a render's folders when it wrote nothing.

use crate::error::{Error, Result};
use crate::output::atomic::write_atomic;
use crate::output::names::FrameName;
use crate::output::Aov;
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The file in an output folder that records what it holds, so `status` can
/// work from the folder alone.
pub const JOB_FILE: &str = "mandelreel-job.json";

/// The empty file renders lock while they update `JOB_FILE`
/// (`JobRecord::record_in`).
pub const JOB_LOCK: &str = ".mandelreel-job.lock";

/// What an output folder was rendered from: enough to recompute every
/// frame's hash without the original timeline file.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct JobRecord {
    pub renderer: String,
    /// The timeline file as given, and its text when the render started.
    pub timeline_path: PathBuf,
    pub timeline_text: String,
    pub width: u32,
    pub height: u32,
    pub formats: Vec<String>,
    /// Half-open frame range the folder is meant to hold.
    pub frames: (u32, u32),
    pub preview: bool,
    #[serde(default)]
    pub aovs: Vec<Aov>,
    /// `--samples`, where given: the samples per pixel that replaced the
    /// timeline's.
    #[serde(default)]
    pub samples: Option<u32>,
    /// Each format's own range, layers and samples (`outputs`); the fields
    /// above are their union, and the last render's, for older readers.
    #[serde(default)]
    pub outputs: Vec<OutputRecord>,
}

/// What one format's frames in a folder were rendered with: a folder may
/// hold PNGs of the whole film and EXRs of three frames, with other layers
/// or samples, each complete on its own terms.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct OutputRecord {
    /// `png`, `png16`, `png16alpha` or `exr`.
    pub format: String,
    /// Half-open span of every range rendered in this format.
    pub frames: (u32, u32),
    #[serde(default)]
    pub aovs: Vec<Aov>,
    #[serde(default)]
    pub samples: Option<u32>,
    /// The EXR compression (an EXR's key records it).
    #[serde(default)]
    pub exr_compression: crate::output::exr::ExrCompression,
    /// `--frame-name`: how its frames are named (`frame_#####` in a
    /// record written before it was recorded, as frames then were).
    #[serde(default)]
    pub frame_name: FrameName,
}

impl OutputRecord {
    /// Whether this format's frames are files of the same kind as
    /// `format`'s (every PNG kind writes `.png`).
    pub fn files_like(&self, format: crate::output::Format) -> bool {
        let mine = crate::output::Format::named(&self.format).map(|f| f.extension());
        mine == Some(format.extension())
    }

    /// Whether `other`'s frames are files of the same kind as these.
    pub fn same_files(&self, other: &OutputRecord) -> bool {
        crate::output::Format::named(&other.format).is_some_and(|f| self.files_like(f))
    }
}

impl JobRecord {
    /// Writes the record into `dir` atomically (concurrent workers of one job
    /// write the same record; the last rename wins whole).
    pub fn write(&self, dir: &Path) -> Result<()> {
        let json = serde_json::to_string_pretty(self).expect("a job record serialises");
        write_atomic(&dir.join(JOB_FILE), |w, temp| {
            w.write_all(json.as_bytes()).map_err(|e| Error::io(temp, e))
        })
    }

    /// Whether the folder was rendered from the timeline at `path`, by file
    /// name (its text may have been edited since, and the folder mounted
    /// at another path).
    pub fn of_timeline(&self, path: &Path) -> bool {
        self.timeline_path.file_name() == path.file_name()
    }

    /// Whether `other` renders the same sequence: the same timeline
    /// (`of_timeline`) at the same size.
    pub fn same_sequence(&self, other: &JobRecord) -> bool {
        self.of_timeline(&other.timeline_path)
            && (self.width, self.height) == (other.width, other.height)
    }

    /// Writes this record into `dir`, spanning the frames of the one there
    /// too if that renders the same sequence (`same_sequence`): a folder is
    /// meant to hold every range rendered into it, so renders in pieces
    /// (`--frames 0..60`, then `60..120`, or both at once on a farm) leave
    /// a record of 0..120 and `status OUTDIR` counts the gaps. An exclusive
    /// lock on the folder's `JOB_LOCK` is held from the read to the write,
    /// so renders started at the same moment each merge into the record the
    /// one before wrote, and none loses another's range. Where the lock
    /// cannot be had (a file system without locks, a lock file this user
    /// cannot open), it goes on without: the record is bookkeeping, not
    /// worth a render. `check` sees the record already there, if any,
    /// under the same lock, and its error stops the write: so a render
    /// refused over another sequence's frames cannot slip in between
    /// another render's check and its write.
    ///
    /// Each format is merged on its own (`merge_outputs`): a render of a
    /// few EXR frames into a folder of PNGs leaves the PNGs' range as it
    /// was, and adds the EXRs'.
    pub fn record_in(self, dir: &Path, check: impl FnOnce(&JobRecord) -> Result<()>) -> Result<()> {
        // Read-only where another user made it (a lock needs no write
        // access), and none at all where it cannot be had.
        // A lock file that is not a regular file (a FIFO would block the
        // open) is none.
        let lock_path = dir.join(JOB_LOCK);
        // Under the interrupt lock: a render stopped before it wrote
        // anything removes the lock file it made (`Scaffold`).
        let held = crate::interrupt::hold();
        let lock = std::fs::OpenOptions::new()
            .create_new(true)
            .write(true)
            .open(&lock_path)
            .or_else(|_| crate::input::open_regular(&lock_path));
        drop(held);
        if let Ok(lock) = &lock {
            let _ = lock.lock();
        }
        let old = JobRecord::read(dir);
        if let Ok(old) = &old {
            check(old)?;
        }
        let record = match old {
            Ok(old) if old.same_sequence(&self) => self.merge_outputs(&old),
            _ => self,
        };
        record.write(dir)
    }

    /// Each format's record: `outputs`, or for a record written before
    /// them, one per format from the shared fields.
    pub fn outputs(&self) -> Vec<OutputRecord> {
        if !self.outputs.is_empty() {
            return self.outputs.clone();
        }
        let output = |format: &String| OutputRecord {
            format: format.clone(),
            frames: self.frames,
            aovs: if format == "exr" {
                self.aovs.clone()
            } else {
                Vec::new()
            },
            samples: self.samples,
            exr_compression: Default::default(),
            frame_name: FrameName::default(),
        };
        self.formats.iter().map(output).collect()
    }

    /// This record, keeping the formats of `old` (the same sequence) that
    /// it does not render, and the span of its own formats' ranges there
    /// (not where it names its frames otherwise: the old span's frames
    /// are not the ones it names).
    fn merge_outputs(self, old: &JobRecord) -> JobRecord {
        let mut outputs = old.outputs();
        for new in self.outputs() {
            // PNG kinds share their files: another kind takes the old one's
            // place, keeping its span, whose frames are then stale.
            match outputs.iter_mut().find(|o| o.same_files(&new)) {
                Some(o) if o.frame_name != new.frame_name => *o = new,
                Some(o) => {
                    *o = OutputRecord {
                        frames: (o.frames.0.min(new.frames.0), o.frames.1.max(new.frames.1)),
                        ..new
                    }
                }
                None => outputs.push(new),
            }
        }
        outputs.sort_by(|a, b| a.format.cmp(&b.format));
        let span = |f: fn(&OutputRecord) -> u32| outputs.iter().map(f);
        JobRecord {
            formats: outputs.iter().map(|o| o.format.clone()).collect(),
            frames: (
                span(|o| o.frames.0).min().unwrap_or(self.frames.0),
                span(|o| o.frames.1).max().unwrap_or(self.frames.1),
            ),
            outputs,
            ..self
        }
    }

    /// The record in `dir`: a regular file of at most `MAX_JOB_BYTES`.
    pub fn read(dir: &Path) -> Result<JobRecord> {
        let path = dir.join(JOB_FILE);
        let text = crate::input::open_regular(&path)
            .and_then(|file| crate::input::read_at_most(file, MAX_JOB_BYTES))
            .map_err(|e| Error::io(&path, e))?;
        serde_json::from_slice(&text).map_err(|e| Error::Image {
            path,
            message: format!("not a mandelreel job record: {e}"),
        })
    }
}

/// An output folder as a render set it up: the folders it created
/// (outermost first) and the bookkeeping files that were not there yet
/// (`JOB_LOCK`, `JOB_FILE`). A render that ends having written nothing
/// (a disk full from the start, Ctrl-C during its first frame) removes
/// them when this is dropped, or on an interrupt, unless `keep` was
/// called: it leaves the disk as it found it.
pub struct Scaffold {
    made: Option<Made>,
    _undone_on_interrupt: crate::interrupt::Registered,
}

#[derive(Clone)]
struct Made {
    dir: PathBuf,
    dirs: Vec<PathBuf>,
    files: Vec<&'static str>,
}

impl Scaffold {
    /// Creates `dir` and its missing parents, noting what it made.
    pub fn make(dir: &Path) -> Result<Scaffold> {
        let mut dirs: Vec<PathBuf> = dir
            .ancestors()
            .take_while(|d| !d.as_os_str().is_empty() && !d.exists())
            .map(Path::to_path_buf)
            .collect();
        dirs.reverse();
        let mut held = crate::interrupt::hold();
        let mut made = Made {
            dir: dir.to_path_buf(),
            dirs,
            files: Vec::new(),
        };
        if let Err(e) = std::fs::create_dir_all(dir) {
            made.undo();
            return Err(Error::io(dir, e));
        }
        made.files = [JOB_LOCK, JOB_FILE]
            .into_iter()
            .filter(|f| !dir.join(f).exists())
            .collect();
        let undo = made.clone();
        let registered = held.on_interrupt(move || undo.undo());
        drop(held);
        Ok(Scaffold {
            made: Some(made),
            _undone_on_interrupt: registered,
        })
    }

    /// The render wrote what it meant to: nothing is undone.
    pub fn keep(mut self) {
        self.made = None;
    }
}

impl Drop for Scaffold {
    fn drop(&mut self) {
        if let Some(made) = &self.made {
            made.undo();
        }
    }
}

impl Made {
    /// Removes what was made, if the folder holds nothing else: no frame,
    /// checkpoint, claim, or another render's record or files.
    fn undo(&self) {
        let Ok(entries) = std::fs::read_dir(&self.dir) else {
            return self.remove_dirs();
        };
        let only_ours = entries
            .map(|e| e.map(|e| e.file_name()))
            .all(|name| name.is_ok_and(|n| self.files.iter().any(|f| n == *f)));
        if only_ours {
            for f in &self.files {
                let _ = std::fs::remove_file(self.dir.join(f));
            }
            self.remove_dirs();
        }
    }

    /// Removes the folders made, innermost first, while they are empty
    /// (or were never made: `create_dir_all` may stop part-way).
    fn remove_dirs(&self) {
        for dir in self.dirs.iter().rev() {
            match std::fs::remove_dir(dir) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => return,
                _ => {}
            }
        }
    }
}

/// The longest job record read: it holds the timeline's text (at most
/// 1 MiB), which JSON may write up to six bytes a byte.
const MAX_JOB_BYTES: u64 = 8 << 20;

#[cfg(test)]
mod tests;
