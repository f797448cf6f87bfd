//! Frame names: the `--frame-name` pattern (`shot_####`), checked, and the
//! names it gives a frame's file, the hidden files kept beside it (claim,
//! checkpoint, temporaries) and ffmpeg's input; and reading a frame's
//! number back from any of them.

use super::Format;
use std::fmt;

/// A frame-name pattern: text around one run of `#`, which the frame
/// number fills, zero-padded to the run's length and longer where the
/// number needs it (`shot_####`: `shot_0042`, `shot_12345`). The format
/// adds the extension.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct FrameName {
    prefix: String,
    digits: usize,
    suffix: String,
}

/// What follows a frame's stem in the names of the files kept for it:
/// its formats' extensions, and its checkpoint's and claim's kinds.
const KINDS: [&str; 4] = ["png", "exr", "ckpt", "claim"];

/// Room for the extension and a temporary file's tags within the 255
/// bytes a file name may have.
const MAX_PATTERN_BYTES: usize = 100;

impl Default for FrameName {
    /// `frame_#####`: `frame_00042.png`.
    fn default() -> FrameName {
        FrameName {
            prefix: "frame_".into(),
            digits: 5,
            suffix: String::new(),
        }
    }
}

impl FrameName {
    /// Reads and checks a pattern; the error says what is wrong with it.
    pub fn parse(text: &str) -> Result<FrameName, String> {
        check_characters(text)?;
        let start = text
            .find('#')
            .ok_or("needs a run of # for the frame number, such as shot_####")?;
        let digits = text[start..].bytes().take_while(|&b| b == b'#').count();
        let (prefix, suffix) = (&text[..start], &text[start + digits..]);
        if suffix.contains('#') {
            return Err(format!("{text:?} has more than one run of #: use one"));
        }
        if digits > 10 {
            return Err(format!(
                "{digits} # are more digits than any frame number has (10)"
            ));
        }
        // v2# frame 5 and v# frame 25 would both be v25.
        let digit = |c: char| c.is_ascii_digit();
        if suffix.starts_with(digit) || prefix.ends_with(digit) {
            return Err(format!(
                "a digit right beside the #s would read as part of the frame number in {text:?}"
            ));
        }
        check_parts(text)?;
        Ok(FrameName {
            prefix: prefix.into(),
            digits,
            suffix: suffix.into(),
        })
    }

    /// The name of frame `frame_index` without an extension: `shot_0042`.
    pub fn stem(&self, frame_index: u32) -> String {
        let (prefix, suffix, width) = (&self.prefix, &self.suffix, self.digits);
        format!("{prefix}{frame_index:0width$}{suffix}")
    }

    /// The file of frame `frame_index` in `format`: `shot_0042.png`.
    pub fn file_name(&self, frame_index: u32, format: Format) -> String {
        format!("{}.{}", self.stem(frame_index), format.extension())
    }

    /// A hidden file kept for frame `frame_index`, named after its frame
    /// so that frames of two patterns in one folder keep theirs apart:
    /// `.shot_0042.claim` for `kind` `claim`.
    pub fn hidden(&self, frame_index: u32, kind: &str) -> String {
        format!(".{}.{kind}", self.stem(frame_index))
    }

    /// ffmpeg's image-sequence input for these frames: `shot_%04d.png`.
    /// (`%` is refused in a pattern, so nothing else needs escaping.)
    pub fn ffmpeg_input(&self, format: Format) -> String {
        let (prefix, digits, suffix) = (&self.prefix, self.digits, &self.suffix);
        format!("{prefix}%0{digits}d{suffix}.{}", format.extension())
    }

    /// The frame whose `format` file is `name`, if it is one of these
    /// frames': only the name this pattern gives that number counts, so
    /// `frame_05.png` is not frame 5 of `frame_#####`.
    pub fn frame_of(&self, name: &str, format: Format) -> Option<u32> {
        let stem = name.strip_suffix(&format!(".{}", format.extension()))?;
        let number = stem
            .strip_prefix(&self.prefix)?
            .strip_suffix(&self.suffix)?;
        self.number(stem, number)
    }

    /// The frame a hidden file or temporary of these frames is for
    /// (`.shot_0042.png.<writer>.partial`, `.shot_0042.ckpt`, …).
    pub fn frame_of_hidden(&self, name: &str) -> Option<u32> {
        self.hidden_kind(name).map(|(frame, _)| frame)
    }

    /// `frame_of_hidden`, with the kind of file it is or stands in for
    /// (`png`, `exr`, `ckpt` or `claim`).
    pub fn hidden_kind(&self, name: &str) -> Option<(u32, &'static str)> {
        let name = name.strip_prefix('.')?;
        let rest = name.strip_prefix(&self.prefix)?;
        let end = rest
            .find(|c: char| !c.is_ascii_digit())
            .unwrap_or(rest.len());
        let stem_end = self.prefix.len() + end + self.suffix.len();
        let frame = self.number(name.get(..stem_end)?, &rest[..end])?;
        let kind = name[stem_end..].strip_prefix('.')?;
        let ours = |k: &str| {
            kind.strip_prefix(k)
                .is_some_and(|t| t.is_empty() || t.starts_with('.'))
        };
        KINDS.into_iter().find(|&k| ours(k)).map(|k| (frame, k))
    }

    /// `number` as a frame, if this pattern names that frame `stem`.
    fn number(&self, stem: &str, number: &str) -> Option<u32> {
        if number.is_empty() || !number.bytes().all(|b| b.is_ascii_digit()) {
            return None;
        }
        let frame: u32 = number.parse().ok()?;
        (self.stem(frame) == stem).then_some(frame)
    }
}

/// Refuses what no file name of a frame should hold.
fn check_characters(text: &str) -> Result<(), String> {
    if text.is_empty() {
        return Err("is empty: give a name such as shot_####".into());
    }
    if text.len() > MAX_PATTERN_BYTES {
        return Err(format!("is longer than {MAX_PATTERN_BYTES} bytes"));
    }
    if let Some(c) = text.chars().find(|c| ['/', '\\'].contains(c)) {
        return Err(format!(
            "holds {c:?}: a frame name names a file, not a folder (give that with --out)"
        ));
    }
    let allowed = |c: char| c.is_ascii_alphanumeric() || "_-.#".contains(c);
    if let Some(c) = text.chars().find(|&c| !allowed(c)) {
        let why = if c == '%' {
            " (ffmpeg reads it as a pattern of its own)"
        } else {
            ""
        };
        return Err(format!(
            "holds {c:?}{why}: use letters, digits, '_', '-', '.' and one run of # for the number"
        ));
    }
    Ok(())
}

/// Refuses names that would pass for other files: hidden ones (every
/// temporary starts with '.'), options, mandelreel's own, and a
/// `.png`-like part, which would read as another pattern's extension.
fn check_parts(text: &str) -> Result<(), String> {
    if text.starts_with('.') {
        return Err("starts with '.', which marks hidden and temporary files".into());
    }
    if text.starts_with('-') {
        return Err("starts with '-', which other tools would take for an option".into());
    }
    if text.starts_with("mandelreel-") {
        return Err("starts with mandelreel-, as mandelreel's own files do".into());
    }
    if text.ends_with('.') {
        return Err("ends with '.': the format adds the extension (.png, .exr)".into());
    }
    let extension = |part: &&str| KINDS.iter().any(|k| part.eq_ignore_ascii_case(k));
    if let Some(part) = text.split('.').skip(1).find(extension) {
        return Err(format!(
            "holds .{part}: the format adds the extension, and a name with one inside \
             would read as another frame's"
        ));
    }
    Ok(())
}

impl fmt::Display for FrameName {
    /// The pattern as written: `shot_####`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let run = "#".repeat(self.digits);
        write!(f, "{}{run}{}", self.prefix, self.suffix)
    }
}

impl std::str::FromStr for FrameName {
    type Err = String;
    fn from_str(text: &str) -> Result<FrameName, String> {
        FrameName::parse(text)
    }
}

impl TryFrom<String> for FrameName {
    type Error = String;
    fn try_from(text: String) -> Result<FrameName, String> {
        FrameName::parse(&text)
    }
}

impl From<FrameName> for String {
    fn from(name: FrameName) -> String {
        name.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shot() -> FrameName {
        FrameName::parse("shot_####").unwrap()
    }

    #[test]
    fn a_pattern_names_frames_padded_to_its_run_of_hashes() {
        assert_eq!(shot().file_name(42, Format::Png), "shot_0042.png");
        assert_eq!(shot().file_name(12345, Format::Exr), "shot_12345.exr");
        let dotted = FrameName::parse("a.#.left").unwrap();
        assert_eq!(dotted.file_name(7, Format::Png), "a.7.left.png");
        assert_eq!(shot().ffmpeg_input(Format::Exr), "shot_%04d.exr");
        assert_eq!(shot().hidden(3, "claim"), ".shot_0003.claim");
        assert_eq!(shot().to_string(), "shot_####");
        // The default names frames as mandelreel always has.
        let default = FrameName::default();
        assert_eq!(default.to_string(), "frame_#####");
        assert_eq!(default.file_name(42, Format::Png), "frame_00042.png");
        assert_eq!(default.ffmpeg_input(Format::Png), "frame_%05d.png");
        assert_eq!(FrameName::parse("frame_#####").unwrap(), default);
    }

    #[test]
    fn only_the_name_a_pattern_gives_a_frame_reads_back_as_that_frame() {
        let (default, png) = (FrameName::default(), Format::Png);
        assert_eq!(shot().frame_of("shot_0042.png", png), Some(42));
        assert_eq!(shot().frame_of("shot_12345.png", png), Some(12345));
        assert_eq!(shot().frame_of("shot_0042.exr", png), None);
        assert_eq!(default.frame_of("frame_05.png", png), None);
        assert_eq!(default.frame_of("frame_000005.png", png), None);
        assert_eq!(default.frame_of("frame_x.png", png), None);
        assert_eq!(default.frame_of("frame_.png", png), None);
        assert_eq!(default.frame_of("frame_99999999999.png", png), None);
        let two = FrameName::parse("frame_##").unwrap();
        assert_eq!(two.frame_of("frame_05.png", png), Some(5));
        assert_eq!(two.frame_of("frame_00005.png", png), None);
    }

    #[test]
    fn hidden_files_read_back_only_for_their_own_pattern() {
        let tagged = ".shot_0042.png.host.17.Ab12Cd.partial";
        assert_eq!(shot().frame_of_hidden(tagged), Some(42));
        assert_eq!(shot().frame_of_hidden(".shot_0042.claim"), Some(42));
        assert_eq!(
            shot().frame_of_hidden(".shot_0042.ckpt.h.1.x.partial"),
            Some(42)
        );
        assert_eq!(
            shot().frame_of_hidden(".shot_0042.exr.old.partial"),
            Some(42)
        );
        assert_eq!(shot().frame_of_hidden("shot_0042.png"), None);
        assert_eq!(
            shot().frame_of_hidden(".shot_0042.json.h.1.x.partial"),
            None
        );
        let left = FrameName::parse("shot_####.left").unwrap();
        let lefts = ".shot_0042.left.png.h.1.x.partial";
        assert_eq!(left.frame_of_hidden(lefts), Some(42));
        assert_eq!(shot().frame_of_hidden(lefts), None);
        assert_eq!(left.frame_of_hidden(tagged), None);
        let default = FrameName::default();
        assert_eq!(
            default.frame_of_hidden(".frame_00001.png.a1b2c3.partial"),
            Some(1)
        );
        assert_eq!(default.frame_of_hidden(".frame_01.png.a1.partial"), None);
        assert_eq!(default.frame_of_hidden(tagged), None);
    }

    #[test]
    fn bad_patterns_are_refused_with_the_reason() {
        let refused = |text: &str, why: &str| {
            let e = FrameName::parse(text).unwrap_err();
            assert!(e.contains(why), "{text:?}: {e}");
        };
        refused("", "is empty");
        refused("shot", "needs a run of #");
        refused("shot_##_v##", "more than one run");
        refused("a/b_####", "names a file, not a folder");
        refused("a\\b_####", "names a file, not a folder");
        refused("shot_%04d", "'%' (ffmpeg reads it");
        refused("shot ####", "' '");
        refused("shöt_####", "'ö'");
        refused(".shot_####", "starts with '.'");
        refused("-shot_####", "starts with '-'");
        refused("mandelreel-run-####", "mandelreel's own");
        refused("shot_####.", "ends with '.'");
        refused("shot_####.png", "holds .png");
        refused("shot.CLAIM.####", "holds .CLAIM");
        refused("shot_####1", "a digit right beside");
        refused("v2#", "a digit right beside");
        refused("###########", "11 # are more");
        refused(&format!("{}#", "a".repeat(100)), "longer than 100");
        for good in ["####", "shot_####", "v2_#", "a.####.b-c", "##########"] {
            assert!(FrameName::parse(good).is_ok(), "{good}");
        }
    }

    #[test]
    fn a_pattern_is_recorded_as_written() {
        let json = serde_json::to_string(&shot()).unwrap();
        assert_eq!(json, "\"shot_####\"");
        assert_eq!(serde_json::from_str::<FrameName>(&json).unwrap(), shot());
        assert!(serde_json::from_str::<FrameName>("\"shot\"").is_err());
    }
}
