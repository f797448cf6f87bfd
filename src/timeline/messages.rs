//! What a timeline's errors say: RON's parse errors told for a timeline
//! (the field, the missing comma's line, a fraction where a count belongs),
//! values shown readably, and an invalid value placed at its line.

use super::limits::count_message;
use super::schema::KeyValue;
use super::spans;
use crate::error::Error;
use crate::error::Place;
use crate::math::{DVec3, Real, Vec3};
use std::path::Path;

/// The number written at `line`:`column` (1-based), where a parse error
/// stopped, if it stopped at the fraction of a number: a field that counts
/// (iterations, frames, a size) given `10.5`, which RON reports as a
/// missing comma. (`1e3` there gets RON's own "Invalid digit 'e'", at the
/// number's start.)
fn fraction_at(text: &str, line: usize, column: usize) -> Option<String> {
    let row = text.lines().nth(line.checked_sub(1)?)?;
    let at = row.char_indices().nth(column.checked_sub(1)?)?.0;
    let (before, after) = row.split_at(at);
    let number = |c: char| c.is_ascii_digit() || "+-.eE_".contains(c);
    let digits = before.trim_end_matches(|c: char| c.is_ascii_digit() || c == '_');
    let whole = &before[digits.len()..];
    if whole.is_empty() || !after.starts_with(['.', 'e', 'E']) {
        return None;
    }
    let sign = if digits.ends_with('-') { "-" } else { "" };
    let rest: String = after.chars().take_while(|&c| number(c)).collect();
    Some(format!("{sign}{whole}{rest}"))
}

/// The number written around `column` (1-based) of `row`, sign and all,
/// as written: `-6`, `5_000_000_000`, `0xFFFFFFFFFF`.
fn number_around(row: &str, column: usize) -> String {
    let chars: Vec<char> = row.chars().collect();
    let part = |c: char| c.is_ascii_alphanumeric() || "_+-".contains(c);
    let at = column.saturating_sub(1).min(chars.len());
    let start = chars[..at]
        .iter()
        .rposition(|&c| !part(c))
        .map_or(0, |i| i + 1);
    let end = chars[at..]
        .iter()
        .position(|&c| !part(c))
        .map_or(chars.len(), |i| at + i);
    chars[start..end].iter().collect()
}

/// For each line of `text`, the columns (1-based, in characters) of its
/// code: every character that is not white space and not in a comment
/// (`// …` to the end of the line, `/* … */` across lines; a string's
/// characters, `//` included, are code).
fn code_columns(text: &str) -> Vec<Vec<usize>> {
    let (mut in_string, mut in_block) = (false, false);
    text.lines()
        .map(|row| {
            let chars: Vec<char> = row.chars().collect();
            let mut code = Vec::new();
            let mut i = 0;
            while i < chars.len() {
                let (c, next) = (chars[i], chars.get(i + 1).copied());
                if in_block {
                    if c == '*' && next == Some('/') {
                        in_block = false;
                        i += 1;
                    }
                } else if in_string {
                    code.push(i + 1);
                    match c {
                        '\\' => {
                            code.extend(next.map(|_| i + 2));
                            i += 1;
                        }
                        '"' => in_string = false,
                        _ => {}
                    }
                } else if c == '/' && next == Some('/') {
                    break;
                } else if c == '/' && next == Some('*') {
                    in_block = true;
                    i += 1;
                } else {
                    in_string = c == '"';
                    if !c.is_whitespace() {
                        code.push(i + 1);
                    }
                }
                i += 1;
            }
            code
        })
        .collect()
}

/// Where RON's parse error `e` points and what it says, told for a timeline
/// (`line`, `column`, 1-based): the field a wrong value was given to, a
/// missing comma at the end of the line that lacks it, trailing text where
/// it starts, and our own types by what they are rather than their names.
pub(super) fn syntax_message(text: &str, e: &ron::error::SpannedError) -> ((usize, usize), String) {
    use ron::error::Error as Ron;
    let (line, column) = (e.span.start.line, e.span.start.col);
    let row = |line: usize| text.lines().nth(line.wrapping_sub(1)).unwrap_or("");
    // The field the error is in and the value at fault: as RON reads the
    // text where it can (a value of the wrong shape, a field too many or
    // missing), else from the brackets and names before the error.
    let typed =
        spans::path_at(text, line, column).or_else(|| super::scan::path_at(text, line, column));
    let typed = match (&e.code, typed) {
        (Ron::Message(m), Some(typed)) => Some(field_named(text, typed, m)),
        (_, typed) => typed,
    };
    let shown = typed
        .as_ref()
        .map_or((line, column), |(_, at)| (at.line, at.column));
    let path = typed.map(|(path, _)| path).filter(|path| !path.is_empty());
    let field = path.as_ref().map(|path| format!("`{path}`: "));
    let in_field = field.clone().unwrap_or_default();
    let named = |message: String| {
        // Our types as a timeline's author knows them.
        [
            ("struct `DVec3`", "a triple (x, y, z)"),
            ("struct `Vec3`", "a triple (x, y, z)"),
            ("`DVec3`", "a triple (x, y, z)"),
            ("`Vec3`", "a triple (x, y, z)"),
            ("struct `TimelineFile`", "the timeline"),
            ("`TimelineFile`", "the timeline"),
            ("struct `TrackSpec`", "a track"),
            ("`TrackSpec`", "a track"),
            ("struct `KeySpec`", "a key"),
            ("`KeySpec`", "a key"),
        ]
        .iter()
        .fold(message, |m, (ours, theirs)| m.replace(ours, theirs))
    };
    if let Some(number) = fraction_at(text, line, column) {
        let whole = number.parse::<Real>().ok().filter(|v| v.fract() == 0.0);
        let message = match whole {
            Some(v) if v.abs() < 1e15 => format!(
                "{in_field}expected a whole number, written without a decimal point: {v}, not {number}"
            ),
            _ => format!("{in_field}expected a whole number here, got {number}"),
        };
        return (shown, message);
    }
    let code = code_columns(text);
    match &e.code {
        // RON stops at the next field; the comma belongs after the value
        // before it, at the end of the last line with anything on it.
        Ron::ExpectedComma
            if code
                .get(line - 1)
                .is_some_and(|columns| columns.iter().all(|&c| c >= column)) =>
        {
            let previous = (1..line)
                .rev()
                .find_map(|l| code[l - 1].last().map(|&c| (l, c + 1)));
            match previous {
                Some(at) => (at, "expected a comma after this value".into()),
                None => ((line, column), "expected a comma".into()),
            }
        }
        // RON points at the end of the timeline; show where the extra text starts.
        Ron::TrailingCharacters => {
            let at = (line..=code.len())
                .find_map(|l| {
                    let first = code[l - 1].iter().find(|&&c| l > line || c >= column);
                    first.map(|&c| (l, c))
                })
                .unwrap_or((line, column));
            (
                at,
                "text after the timeline's closing `)`: a timeline is one `( … )`".into(),
            )
        }
        Ron::IntegerOutOfBounds => {
            let written = number_around(row(line), column);
            let limit = path.as_deref().and_then(|p| count_message(p, &written));
            let message = limit.unwrap_or_else(|| {
                if written.starts_with('-') {
                    "must be 0 or more: counts, sizes and seeds are never negative".into()
                } else {
                    format!("too large: at most {}", u32::MAX)
                }
            });
            (shown, format!("{in_field}{message}"))
        }
        // A count's own visitor (`fractal::form`) saw the number as read,
        // not as written: show it as written.
        Ron::Message(m) if m.starts_with("must be 1..=") => {
            let written = number_around(row(shown.0), shown.1);
            let told = m.split(", got ").next().unwrap_or(m);
            (shown, format!("{in_field}{told}, got {written}"))
        }
        Ron::SuggestRawIdentifier(found) => (
            (line, column),
            format!("{in_field}expected a field name here (`name: value`), got `{found}`"),
        ),
        code => (shown, named(format!("{in_field}{code}"))),
    }
}

/// A visitor's message about one field of the value it read whole (`margin
/// must be 0..=100` in `Auto(margin: -1)`), which RON places at the value's
/// end: that field's path and place, where the value has a field so named.
fn field_named(text: &str, (path, place): (String, Place), message: &str) -> (String, Place) {
    let name = message.split_whitespace().next().unwrap_or_default();
    let inner = format!("{path}.{name}");
    let plain = !name.is_empty() && name.chars().all(|c| c.is_alphanumeric() || c == '_');
    match plain.then(|| spans::place_of(text, &inner)).flatten() {
        Some(at) => (inner, at),
        None => (path, place),
    }
}

/// A value as messages show it: numbers as written at ordinary
/// magnitudes, in e-notation from a million up and below 1e-4 (not 309
/// digits of 1e308), and an infinity said to be what a number too large
/// for its field became when read (an f32 field given 1e300).
pub(super) trait Shown {
    fn shown(&self) -> String;
}

macro_rules! shown_number {
    ($t:ty) => {
        impl Shown for $t {
            fn shown(&self) -> String {
                let x = *self;
                if x.is_infinite() {
                    format!("{x} (or a number too large to hold)")
                } else if x != 0.0 && (x.abs() >= 1e6 || x.abs() < 1e-4) {
                    format!("{x:e}")
                } else {
                    format!("{x}")
                }
            }
        }
    };
}
shown_number!(f64);
shown_number!(f32);

macro_rules! shown_vector {
    ($t:ty) => {
        impl Shown for $t {
            fn shown(&self) -> String {
                let [x, y, z] = [self.x.shown(), self.y.shown(), self.z.shown()];
                format!("({x}, {y}, {z})")
            }
        }
    };
}
shown_vector!(DVec3);
shown_vector!(Vec3);

impl Shown for KeyValue {
    fn shown(&self) -> String {
        match *self {
            KeyValue::Number(v) => v.shown(),
            KeyValue::Triple(x, y, z) => DVec3::new(x, y, z).shown(),
            KeyValue::Digits(ref c) => match &c.digits {
                Some(d) => format!("({:?}, {:?}, {:?})", d[0], d[1], d[2]),
                None => c.value.shown(),
            },
        }
    }
}

/// The error for the value at `field`, a path into the file: at the
/// value's line and column, or, where the file leaves the field to its
/// default, at the block that would hold it, saying so.
pub(super) fn invalid_value(text: &str, file: &Path, field: &str, message: String) -> Error {
    let steps = spans::steps(field);
    let (place, message) = match spans::nearest(text, field) {
        // A missing key or item is not a default: only a field has one.
        Some((found, place)) if matches!(steps.get(found), Some(spans::Step::Field(_))) => {
            let name = spans::path_of(&steps[found..]);
            let note = format!(" (`{name}` is not given here, so it takes its default)");
            (Some(place), message + &note)
        }
        found => (found.map(|(_, place)| place), message),
    };
    Error::Invalid {
        file: file.to_path_buf(),
        place,
        path: field.to_string(),
        message,
    }
}
