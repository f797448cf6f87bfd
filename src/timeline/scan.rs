//! The field path at a place in a timeline that RON cannot read as a whole
//! (a mistyped number, brackets nested past RON's depth limit, a list
//! where a map belongs), found from the brackets, names and commas before
//! the place, without a parser: a broken file's error still names its
//! field, as `spans::path_at` names it in a file that is RON. Paths are
//! written as `spans` writes them: `Some(…)` and a struct's name add no
//! step, an unnamed item is an index.

use super::spans::{self, Step};
use crate::error::Place;

/// What opened a level: `Some(` holds one value and adds no step.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Bracket {
    Round,
    Square,
    Curly,
    Some,
}

/// One open level, and the item of it the scan is in.
#[derive(Debug)]
struct Level {
    bracket: Bracket,
    /// The item's index: commas read at this level.
    index: usize,
    /// The item's field name or map key, once its `:` is read.
    name: Option<Step>,
    /// Where the item's value starts, once it has.
    value: Option<usize>,
}

impl Level {
    fn new(bracket: Bracket) -> Level {
        Level {
            bracket,
            index: 0,
            name: None,
            value: None,
        }
    }

    /// The step from this level to its item's value, if it has one: a
    /// map's key still being written has none.
    fn step(&self) -> Option<Step> {
        match (self.bracket, &self.name) {
            (Bracket::Some, _) | (Bracket::Curly, None) => None,
            (_, Some(name)) => Some(name.clone()),
            (_, None) => Some(Step::Index(self.index)),
        }
    }

    /// Whether the item's field name or key may stand here.
    fn takes_name(&self) -> bool {
        matches!(self.bracket, Bracket::Round | Bracket::Curly)
            && self.name.is_none()
            && self.value.is_none()
    }
}

/// The field path of the innermost value at `line`:`column` (1-based) and
/// the place to show: the start of the value, where the place is inside it
/// or in the white space and comments before it, else the place itself
/// (past a value, where its comma is missing). `None` outside the
/// document's outermost brackets.
pub(super) fn path_at(text: &str, line: usize, column: usize) -> Option<(String, Place)> {
    let offset = spans::offset_of(text, line, column)?;
    let (levels, scanned) = scan(text, offset);
    let (last, outer) = levels.split_last()?;
    let mut steps: Vec<Step> = outer.iter().filter_map(Level::step).collect();
    // White space that runs to the end is no value's: the place stays.
    let next = Some(spans::skip_blank(text, offset))
        .filter(|&next| next < text.len())
        .unwrap_or(offset);
    let in_value = last.name.is_some()
        || last.value.is_some()
        || (last.bracket != Bracket::Curly && starts_value(text, next));
    if in_value {
        steps.extend(last.step());
    }
    let inside = in_value && offset < scanned;
    let shown = last.value.filter(|_| inside).unwrap_or(next);
    Some((spans::path_of(&steps), spans::place(text, shown)))
}

/// The levels open at byte `offset`, outermost first, each at the item
/// `offset` is in, and where the token read last ends: past `offset`
/// where `offset` is inside it.
fn scan(text: &str, offset: usize) -> (Vec<Level>, usize) {
    let mut levels: Vec<Level> = Vec::new();
    let mut at = spans::skip_blank(text, 0);
    let mut scanned = at;
    while at < offset {
        let Some(c) = text[at..].chars().next() else {
            break;
        };
        at = match c {
            '(' | '[' | '{' => open(&mut levels, at, c),
            ')' | ']' | '}' => {
                levels.pop();
                at + 1
            }
            ',' => {
                if let Some(level) = levels.last_mut() {
                    *level = Level {
                        index: level.index + 1,
                        ..Level::new(level.bracket)
                    };
                }
                at + 1
            }
            ':' => at + 1,
            _ => token(text, &mut levels, at),
        };
        scanned = at;
        at = spans::skip_blank(text, at);
    }
    (levels, scanned)
}

/// Opens a level at the bracket `c` at `at`, a value of the item it is in;
/// returns where the scan goes on.
fn open(levels: &mut Vec<Level>, at: usize, c: char) -> usize {
    mark_value(levels, at);
    let bracket = match c {
        '(' => Bracket::Round,
        '[' => Bracket::Square,
        _ => Bracket::Curly,
    };
    levels.push(Level::new(bracket));
    at + 1
}

/// Notes that the current item's value starts at `at`, if it has not yet.
fn mark_value(levels: &mut [Level], at: usize) {
    if let Some(level) = levels.last_mut() {
        level.value.get_or_insert(at);
    }
}

/// Reads the word, number or string at `at`: a field name or key where a
/// `:` follows, `Some(` or a struct's `Name(`, else a value. Returns where
/// the scan goes on.
fn token(text: &str, levels: &mut Vec<Level>, at: usize) -> usize {
    let (end, string) = token_end(text, at);
    let next = spans::skip_blank(text, end);
    let rest = &text[next.min(text.len())..];
    let word = &text[at..end];
    if let Some(level) = levels.last_mut() {
        let colon = rest.starts_with(':') && !rest.starts_with("::");
        if colon && level.takes_name() {
            level.name = Some(match (level.bracket, string) {
                (Bracket::Round, None) => Step::Field(word.to_string()),
                (_, Some(key)) => Step::Key(key),
                _ => Step::Key(word.to_string()),
            });
            return next + 1;
        }
    }
    mark_value(levels, at);
    if string.is_none() && rest.starts_with('(') {
        let bracket = if word == "Some" {
            Bracket::Some
        } else {
            Bracket::Round
        };
        levels.push(Level::new(bracket));
        return next + 1;
    }
    end
}

/// Where the token at `at` ends, and a string's contents if it is one:
/// as RON reads them, so a key is named as in a file that is RON.
fn token_end(text: &str, at: usize) -> (usize, Option<String>) {
    let rest = &text[at..];
    let quote = |c: char| rest.starts_with(c);
    if quote('"') || quote('\'') {
        let close = rest.chars().next().unwrap_or('"');
        let mut escaped = false;
        for (i, c) in rest.char_indices().skip(1) {
            if c == close && !escaped {
                return (at + i + 1, Some(unescaped(&rest[..=i])));
            }
            escaped = c == '\\' && !escaped;
        }
        return (text.len(), None);
    }
    if let Some(raw) = raw_string_end(rest) {
        return (at + raw, Some(unescaped(&rest[..raw])));
    }
    // Numbers, names and `inf`; any other character is a token of its own.
    let word = |c: char| c.is_alphanumeric() || "_.+-".contains(c);
    let end = rest.find(|c| !word(c)).unwrap_or(rest.len());
    (
        at + end.max(rest.chars().next().map_or(1, char::len_utf8)),
        None,
    )
}

/// The contents of the string literal `literal`, escapes read by RON
/// itself; one RON cannot read (a bad escape, a char) as written inside
/// its quotes.
fn unescaped(literal: &str) -> String {
    ron::from_str::<String>(literal).unwrap_or_else(|_| {
        let inside = literal.trim_start_matches('r').trim_matches('#');
        inside
            .get(1..inside.len().saturating_sub(1))
            .unwrap_or(inside)
            .to_string()
    })
}

/// The length of the raw string `r#"…"#` that `rest` starts with.
fn raw_string_end(rest: &str) -> Option<usize> {
    let hashes = rest
        .strip_prefix('r')?
        .chars()
        .take_while(|&c| c == '#')
        .count();
    let body = rest[1 + hashes..].strip_prefix('"')?;
    let close = format!("\"{}", "#".repeat(hashes));
    let end = body.find(&close).map_or(body.len(), |i| i + close.len());
    Some(2 + hashes + end)
}

/// Whether a value starts at `at`, rather than a field's name, a
/// separator, a closing bracket or the end.
fn starts_value(text: &str, at: usize) -> bool {
    let rest = &text[at..];
    let Some(c) = rest.chars().next() else {
        return false;
    };
    if ")]},:".contains(c) {
        return false;
    }
    let name = rest
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(rest.len());
    let after = &text[spans::skip_blank(text, at + name)..];
    !(name > 0 && after.starts_with(':') && !after.starts_with("::"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(text: &str, line: usize, column: usize) -> Option<(String, (usize, usize))> {
        path_at(text, line, column).map(|(path, p)| (path, (p.line, p.column)))
    }

    fn named(path: &str, line: usize, column: usize) -> Option<(String, (usize, usize))> {
        Some((path.to_string(), (line, column)))
    }

    #[test]
    fn a_broken_value_is_named_and_shown_from_its_start() {
        let text = "(\n  size: (8, 6),\n  fps:   2.4.0,\n)";
        // At the space before it (where RON points), and inside it.
        assert_eq!(at(text, 3, 7), named("fps", 3, 10));
        assert_eq!(at(text, 3, 12), named("fps", 3, 10));
        assert_eq!(at(text, 2, 13), named("size[1]", 2, 13));
        // Past a value, where a comma is missing: there.
        assert_eq!(at("(size: (8; 6))", 1, 10), named("size[0]", 1, 10));
        // Between fields: the block's.
        assert_eq!(at(text, 3, 3), named("", 3, 3));
        // Outside the document: none.
        assert_eq!(at("(fps: 1) x", 1, 10), None);
    }

    #[test]
    fn wrappers_names_keys_lists_and_depth_take_their_steps() {
        let deep = format!("(scene: {}", "(".repeat(500));
        assert_eq!(at(&deep, 1, 10), named("scene[0]", 1, 10));
        let text = "(scene: (effects: (shadows: Some(Some(Camera(softness: 1.2.3))))))";
        let path = "scene.effects.shadows.softness";
        assert_eq!(at(text, 1, 56), named(path, 1, 56));
        let text = "(tracks: { \"a.b\": (keys: [(time: 0, value: 1.2.3)]) }, x: \"(\")";
        let key = "tracks[\"a.b\"].keys[0].value";
        assert_eq!(at(text, 1, 44), named(key, 1, 44));
        assert_eq!(at(text, 1, 62), named("x", 1, 62));
        let list = "(tracks: [ \"a.b\": (keys: [1.2.3]) ])";
        assert_eq!(at(list, 1, 28), named("tracks[0].keys[0]", 1, 27));
        // Comments and strings hold no brackets.
        let text = "(a: /* ( */ \"// (\", // (\n b: 1.2.3)";
        assert_eq!(at(text, 2, 5), named("b", 2, 5));
    }

    #[test]
    fn a_keys_escapes_are_read_as_ron_reads_them() {
        for (key, read) in [
            (r#""fractal.\"power""#, "fractal.\"power"),
            (r#""fractal.\u{70}ower""#, "fractal.power"),
            (r#""a\\b\n\t\x41""#, "a\\b\n\tA"),
            (r##"r#"a"b"#"##, "a\"b"),
        ] {
            let text = format!("(tracks: {{ {key}: (keys: [1.2.3]) }})");
            let column = text.find("1.2").expect("the broken value is there") + 1;
            let path = spans::path_of(&[
                Step::Field("tracks".into()),
                Step::Key(read.into()),
                Step::Field("keys".into()),
                Step::Index(0),
            ]);
            assert_eq!(at(&text, 1, column), named(&path, 1, column), "{key}");
        }
    }
}
