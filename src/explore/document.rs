//! The timeline being explored: its text as edited, what its file held
//! when last read or written, and the files this session may write (the
//! one it opened, and new ones the user names in the same folder).

use super::Event;
use crate::timeline::edit::Edit;
use crate::timeline::Timeline;
use std::path::{Path, PathBuf};

/// A new timeline's text, where `explore` starts without one.
const STARTER: &str = include_str!("starter.ron");

/// Edits in one request: enough for any key the page makes.
pub const MAX_EDITS: usize = 64;

pub struct Document {
    folder: PathBuf,
    /// The file as the user named it; none until a new timeline is named.
    path: Option<PathBuf>,
    /// The file Save writes: through a link, the file it names, whose own
    /// permissions are kept.
    target: Option<(PathBuf, Option<std::fs::Permissions>)>,
    pub text: String,
    /// The file's text when last read or written (none for a new timeline).
    saved: Option<String>,
    /// Edited here since then.
    edited: bool,
    /// The file's text at the last look, taken in only once two looks
    /// agree: an editor that writes in place is seen half-way through.
    last_look: Option<String>,
    /// The file holds text this session has neither taken in nor written.
    disk_changed: bool,
    pub timeline: Timeline,
}

impl Document {
    /// The timeline at `path`, read and checked as `render` would; or, with
    /// none, a new one in the current folder.
    pub fn open(path: Option<&Path>) -> anyhow::Result<Document> {
        let Some(path) = path else {
            let timeline = Timeline::parse(STARTER, Path::new("untitled.ron"))?;
            return Ok(Document::new(
                std::env::current_dir()?,
                None,
                None,
                timeline,
                STARTER,
            ));
        };
        let text = crate::timeline::read_text(path)?;
        let timeline = Timeline::parse(&text, path)?;
        let folder = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let real = std::fs::canonicalize(path).map_err(|e| crate::error::Error::io(path, e))?;
        let mode = std::fs::metadata(&real).ok().map(|m| m.permissions());
        let mut document = Document::new(folder, Some(path), Some((real, mode)), timeline, &text);
        document.saved = Some(text);
        Ok(document)
    }

    fn new(
        folder: PathBuf,
        path: Option<&Path>,
        target: Option<(PathBuf, Option<std::fs::Permissions>)>,
        timeline: Timeline,
        text: &str,
    ) -> Document {
        Document {
            folder,
            path: path.map(Path::to_path_buf),
            target,
            text: text.to_string(),
            saved: None,
            edited: false,
            last_look: None,
            disk_changed: false,
            timeline,
        }
    }

    /// The file's name, or `untitled.ron` before it has one.
    pub fn name(&self) -> String {
        let path = self.path.as_deref().unwrap_or(Path::new("untitled.ron"));
        path.file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
    }

    pub fn path(&self) -> Option<&Path> {
        self.path.as_deref()
    }

    /// Edits not yet saved, or a new timeline never saved.
    pub fn dirty(&self) -> bool {
        self.edited || self.saved.is_none()
    }

    /// The text, and the name its messages give: what an edit starts from.
    pub fn snapshot(&self) -> (String, PathBuf) {
        (self.text.clone(), self.shown())
    }

    fn shown(&self) -> PathBuf {
        self.path.clone().unwrap_or_else(|| self.name().into())
    }

    /// An edit's result (`edited`) in place of `base`, unless the text
    /// changed meanwhile.
    pub fn put_edited(&mut self, base: &str, made: (String, Timeline)) -> Result<(), String> {
        if self.text != base {
            return Err("the timeline changed while the edit was checked: try again".into());
        }
        (self.text, self.timeline) = made;
        self.edited = true;
        Ok(())
    }

    /// `text` in place of the document's, where it is a valid timeline
    /// that `render` would read.
    fn take(&mut self, text: String) -> Result<(), String> {
        (self.text, self.timeline) = checked(text, &self.shown())?;
        Ok(())
    }

    /// Whether the file holds other text than this session last read or
    /// wrote, now or at the last look.
    pub fn changed_on_disk(&self) -> bool {
        let Some((target, _)) = &self.target else {
            return false;
        };
        let now = crate::timeline::read_text(target).ok();
        self.disk_changed || now != self.saved
    }

    /// Writes the text to its file, or to `new_name`: a new file in the
    /// same folder, which becomes the document's file.
    pub fn save(&mut self, new_name: Option<&str>) -> Result<PathBuf, String> {
        let (path, target) = match (new_name, &self.path, &self.target) {
            // `create` writes the text.
            (Some(name), _, _) => {
                let path = self.create(name)?;
                (path.clone(), (path, None))
            }
            (None, Some(path), Some(target)) => {
                write(&target.0, &self.text)?;
                if let Some(mode) = &target.1 {
                    let _ = std::fs::set_permissions(&target.0, mode.clone());
                }
                (path.clone(), target.clone())
            }
            _ => return Err("a new timeline needs a file name to be saved under".into()),
        };
        (self.path, self.target) = (Some(path.clone()), Some(target));
        (self.saved, self.edited) = (Some(self.text.clone()), false);
        self.disk_changed = false;
        Ok(path)
    }

    /// A new file `name` in the document's folder holding the text, written
    /// whole or not at all and never over another file.
    fn create(&self, name: &str) -> Result<PathBuf, String> {
        if !plain_name(name) {
            return Err(format!(
                "{name:?}: a new file's name must be a plain file name ending in .ron (no spaces at either end, no invisible or direction-changing characters), in {}",
                self.folder.display()
            ));
        }
        let path = self.folder.join(name);
        crate::output::atomic::write_new_text(&path, &self.text).map_err(|e| {
            match e.is_already_exists() {
                true => format!(
                    "{} already exists: explore writes only its own timeline and new files",
                    path.display()
                ),
                false => format!("cannot create {}: {e}", path.display()),
            }
        })?;
        Ok(path)
    }

    /// Reads the file again, dropping edits not saved.
    pub fn reload(&mut self) -> Result<(), String> {
        let Some(path) = self.path.clone() else {
            return Err("a new timeline has no file to reload".into());
        };
        let text = crate::timeline::read_text(&path).map_err(|e| format!("{e:#}"))?;
        self.take(text.clone())?;
        (self.saved, self.edited, self.disk_changed) = (Some(text), false, false);
        Ok(())
    }

    /// What to tell the page when the file's text is no longer what this
    /// session last read or wrote: without edits of its own, the document
    /// takes the file's text in.
    pub fn check_disk(&mut self) -> Option<Event> {
        let path = self.path.clone()?;
        let text = crate::timeline::read_text(&path).ok()?;
        let settled = self.last_look.as_ref() == Some(&text);
        self.last_look = Some(text.clone());
        if !settled || Some(&text) == self.saved.as_ref() {
            return None;
        }
        self.saved = Some(text.clone());
        if self.edited {
            self.disk_changed = true;
            return Some(Event::File {
                dirty: true,
                error: None,
            });
        }
        // An invalid file is shown as its error, and the last valid text
        // stays what the page renders until the file is mended.
        let error = self.take(text).err();
        self.disk_changed = error.is_some();
        Some(Event::File {
            dirty: false,
            error,
        })
    }
}

/// `edits` made in turn to `text`: all of them take, or none (the first
/// that fails, or a result that is not a valid timeline, is the error,
/// placed at its line as the command line places it).
pub fn edited(text: &str, shown: &Path, edits: &[Edit]) -> Result<(String, Timeline), String> {
    if edits.len() > MAX_EDITS {
        return Err(format!(
            "at most {MAX_EDITS} edits at once, got {}",
            edits.len()
        ));
    }
    // What the page's numbers came from: where they are a point's digits
    // rounded, the digits are written.
    let before = std::cell::OnceCell::new();
    let mut made = text.to_string();
    for edit in edits {
        let timeline = match edit.may_round_digits() {
            true => before.get_or_init(|| Timeline::parse(text, shown).ok()),
            false => &None,
        };
        let kept = match timeline {
            Some(timeline) => crate::timeline::edit::keeping_digits(timeline, edit.clone()),
            None => edit.clone(),
        };
        made = crate::timeline::edit::apply(&made, &kept)?;
    }
    checked(made, shown)
}

/// `text` and its timeline, where it is valid and `render` would read it.
fn checked(text: String, shown: &Path) -> Result<(String, Timeline), String> {
    let most = crate::timeline::MAX_TIMELINE_BYTES;
    if text.len() as u64 > most {
        let mib = most >> 20;
        return Err(format!(
            "the timeline would be longer than {mib} MiB, which render refuses"
        ));
    }
    let timeline = Timeline::parse(&text, shown).map_err(|e| format!("{e:#}"))?;
    Ok((text, timeline))
}

/// `text` written over `path` whole, through a temporary file.
fn write(path: &Path, text: &str) -> Result<(), String> {
    crate::output::atomic::write_text(path, text).map_err(|e| format!("{e:#}"))
}

/// A name a user can read as it is: a `.ron` file in the folder itself, its
/// stem with no space at either end, no control character and none of the
/// invisible or direction-changing ones (`\u{202E}gnp.ron` shows as
/// `ron.png`).
fn plain_name(name: &str) -> bool {
    let ranges = [
        ('\u{200B}', '\u{200F}'),
        ('\u{2028}', '\u{202E}'),
        ('\u{2060}', '\u{206F}'),
        ('\u{FFF9}', '\u{FFFB}'),
        ('\u{FE00}', '\u{FE0F}'),
        ('\u{180B}', '\u{180E}'),
        ('\u{0600}', '\u{0605}'),
        ('\u{1D173}', '\u{1D17A}'),
        ('\u{E0000}', '\u{E0FFF}'),
    ];
    let invisible = |c: char| {
        c.is_control()
            || matches!(
                c,
                '\u{00AD}'
                    | '\u{061C}'
                    | '\u{06DD}'
                    | '\u{070F}'
                    | '\u{FEFF}'
                    | '\u{115F}'
                    | '\u{1160}'
                    | '\u{2800}'
                    | '\u{3164}'
                    | '\u{FFA0}'
            )
            || ranges.iter().any(|&(a, b)| (a..=b).contains(&c))
    };
    let stem = name.strip_suffix(".ron").unwrap_or_default();
    let chars: Vec<char> = name.chars().collect();
    let hidden = (0..chars.len()).any(|i| invisible(chars[i]) && !joiner_in_a_word(&chars, i));
    // Room in a file name's 255 bytes for the temporary it is written as.
    !stem.is_empty()
        && name.len() <= 150
        && !name.starts_with('.')
        && stem.trim() == stem
        && !name.contains(['/', '\\'])
        && !hidden
}

/// Whether `chars[i]` is a zero-width joiner or non-joiner where a word
/// needs it to be spelt right, as Unicode's identifier rules (UAX #31)
/// allow: after an Indic virama, or a non-joiner between two letters of
/// the Arabic script (Persian writes one in "the films"). Anywhere else
/// it hides: `rep\u{200D}ort.ron` looks like `report.ron`.
fn joiner_in_a_word(chars: &[char], i: usize) -> bool {
    const VIRAMAS: [char; 13] = [
        '\u{094D}', '\u{09CD}', '\u{0A4D}', '\u{0ACD}', '\u{0B4D}', '\u{0BCD}', '\u{0C4D}',
        '\u{0CCD}', '\u{0D4D}', '\u{0DCA}', '\u{1039}', '\u{17D2}', '\u{1B44}',
    ];
    let arabic = |c: &char| {
        let ranges = [
            ('\u{0620}', '\u{06FF}'),
            ('\u{0750}', '\u{077F}'),
            ('\u{08A0}', '\u{08FF}'),
        ];
        c.is_alphabetic() && ranges.iter().any(|&(a, b)| (a..=b).contains(c))
    };
    let before = i.checked_sub(1).and_then(|j| chars.get(j));
    match chars[i] {
        '\u{200D}' => before.is_some_and(|c| VIRAMAS.contains(c)),
        '\u{200C}' => {
            before.is_some_and(|c| VIRAMAS.contains(c))
                || (before.is_some_and(arabic) && chars.get(i + 1).is_some_and(arabic))
        }
        _ => false,
    }
}
