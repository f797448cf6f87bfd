//! Edits that break a timeline, at three levels: the tree of a generated
//! timeline (a value of the wrong shape, a field dropped, doubled or
//! unknown, deep nesting, a very long list), the tokens of an example
//! timeline (a number or a name swapped, a token dropped), and the bytes
//! of either (truncation, deletion, copies, comments, strings and unicode
//! in odd places, any byte anywhere). Positions are taken modulo what is
//! there, so every edit applies to every input and shrinks to a simpler one.

use super::grammar::Ron;
use proptest::prelude::*;

/// Numbers at and past every limit, in every spelling RON might take.
pub const SPECIAL_NUMBERS: &[&str] = &[
    "0",
    "-0",
    "0.0",
    "-0.0",
    "1e308",
    "-1e308",
    "1e309",
    "1e-320",
    "5e-324",
    "1.7976931348623157e308",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "+inf",
    "infinity",
    "-Infinity",
    "4294967295",
    "4294967296",
    "4000000000",
    "18446744073709551615",
    "18446744073709551616",
    "-9223372036854775808",
    "-1",
    "-4294967296",
    "99999999999999999999999999999999999999",
    "1e999999999",
    "1e-999999999",
    "0x7fffffff",
    "0b101",
    "0o777",
    "1_000_000",
    ".5",
    "5.",
    "1e",
    "--1",
    "+1",
    "1000000",
    "100000",
    "1000.000001",
    "1e15",
    "1e6",
    "9007199254740993",
];

/// Values of the wrong shape for wherever they land.
const WRONG_SHAPES: &[&str] = &[
    "\"text\"",
    "\"\"",
    "(1, 2)",
    "(1, 2, 3, 4)",
    "(1)",
    "()",
    "[]",
    "[1, 2, 3]",
    "{}",
    "{\"camera.position\": ()}",
    "true",
    "Some(1)",
    "Some(Some((1, 2, 3)))",
    "None",
    "'c'",
    "Identifier",
    "(time: 0, value: 1)",
    "(fps: 24)",
    "r#\"raw\"#",
    "b\"bytes\"",
];

/// Text dropped in anywhere: comments, strings, brackets, unicode, control
/// characters, RON's extension attributes, pieces of a timeline.
const SNIPPETS: &[&str] = &[
    "//",
    "// comment\n",
    "/*",
    "*/",
    "/* block */",
    "/* /* nested */ */",
    "\"",
    "\"text\"",
    "\"\\u{1F980}\"",
    "\"\\",
    "r#\"raw\"#",
    "b\"bytes\"",
    "'c'",
    "(",
    ")",
    "[",
    "]",
    "{",
    "}",
    ",",
    ",,",
    ":",
    "Some(",
    "None",
    "\n",
    "\r\n",
    "\r",
    "\t",
    "é",
    "🦀",
    "\u{feff}",
    "\u{0}",
    "\u{202e}",
    "\u{10ffff}",
    "ｆｐｓ",
    "#![enable(implicit_some)]\n",
    "#![enable(unwrap_newtypes, unwrap_variant_newtypes)]\n",
    "fps: 24,",
    "frames: 4000000000,",
    "tracks: {},",
    "scene: (),",
    "\"camera.position\": (keys: []),",
];

/// Names that are not fields, or are fields given twice.
const STRAY_NAMES: &[&str] = &[
    "fsp", "fps", "Frames", "sceen", "r#fps", "time", "camera", "fpś", "_", "a0",
];

/// An edit of a generated timeline's tree. The first number picks the node
/// (or the struct) in pre-order.
#[derive(Clone, Debug)]
pub enum TreeEdit {
    /// A value swapped for a `SPECIAL_NUMBERS` one.
    Special(usize, usize),
    /// A value swapped for a `WRONG_SHAPES` one.
    Shape(usize, usize),
    /// A value wrapped in this many brackets of a kind.
    Nest(usize, usize, usize),
    /// A list's (or tuple's, or map's) first item repeated this many
    /// times; a key at increasing times.
    Repeat(usize, usize),
    DropField(usize, usize),
    DoubleField(usize, usize),
    /// A field of a `STRAY_NAMES` name added.
    StrayField(usize, usize),
}

pub fn tree_edit() -> impl Strategy<Value = TreeEdit> {
    let n = any::<usize>;
    prop_oneof![
        4 => (n(), 0..SPECIAL_NUMBERS.len()).prop_map(|(a, b)| TreeEdit::Special(a, b)),
        2 => (n(), 0..WRONG_SHAPES.len()).prop_map(|(a, b)| TreeEdit::Shape(a, b)),
        1 => (n(), depth(), 0..3usize).prop_map(|(a, d, k)| TreeEdit::Nest(a, d, k)),
        1 => (n(), list_length()).prop_map(|(a, l)| TreeEdit::Repeat(a, l)),
        2 => (n(), n()).prop_map(|(a, b)| TreeEdit::DropField(a, b)),
        1 => (n(), n()).prop_map(|(a, b)| TreeEdit::DoubleField(a, b)),
        1 => (n(), 0..STRAY_NAMES.len()).prop_map(|(a, b)| TreeEdit::StrayField(a, b)),
    ]
}

/// Around RON's recursion limit (128), and well past it.
fn depth() -> impl Strategy<Value = usize> {
    prop_oneof![1usize..140, Just(1000), Just(100_000)]
}

/// Long lists: hundreds of items often, tens of thousands now and then.
fn list_length() -> impl Strategy<Value = usize> {
    prop_oneof![8 => 0usize..500, 1 => 500usize..20_000, 1 => Just(100_000)]
}

impl TreeEdit {
    pub fn apply(&self, tree: &mut Ron) {
        match *self {
            TreeEdit::Special(at, i) => replace(tree, at, SPECIAL_NUMBERS[i]),
            TreeEdit::Shape(at, i) => replace(tree, at, WRONG_SHAPES[i]),
            TreeEdit::Nest(at, d, kind) => {
                let Some(node) = nth(tree, &mut (at % count(tree, &any_node)), &any_node) else {
                    return;
                };
                let (open, close) = [("(", ")"), ("[", "]"), ("Some(", ")")][kind];
                let inner = node.text();
                *node = Ron::Atom(format!(
                    "{}{}{}",
                    open.repeat(d),
                    inner.trim_end(),
                    close.repeat(d)
                ));
            }
            TreeEdit::Repeat(at, length) => {
                if let Some(node) = nth(tree, &mut (at % count(tree, &is_list).max(1)), &is_list) {
                    repeat(node, length);
                }
            }
            TreeEdit::DropField(at, f) => edit_struct(tree, at, |fields| {
                if !fields.is_empty() {
                    fields.remove(f % fields.len());
                }
            }),
            TreeEdit::DoubleField(at, f) => edit_struct(tree, at, |fields| {
                if !fields.is_empty() {
                    let copy = fields[f % fields.len()].clone();
                    fields.push(copy);
                }
            }),
            TreeEdit::StrayField(at, i) => edit_struct(tree, at, |fields| {
                fields.insert(0, (STRAY_NAMES[i].into(), Ron::Atom("1".into())));
            }),
        }
    }
}

fn any_node(_: &Ron) -> bool {
    true
}

fn is_list(node: &Ron) -> bool {
    matches!(node, Ron::List(_) | Ron::Tuple(..) | Ron::Map(_))
}

fn is_struct(node: &Ron) -> bool {
    matches!(node, Ron::Struct(..))
}

/// Nodes in `node` (itself included) for which `pick` holds.
fn count(node: &Ron, pick: &dyn Fn(&Ron) -> bool) -> usize {
    let own = usize::from(pick(node));
    own + children(node).map(|c| count(c, pick)).sum::<usize>()
}

fn children(node: &Ron) -> Box<dyn Iterator<Item = &Ron> + '_> {
    match node {
        Ron::Atom(_) => Box::new(std::iter::empty()),
        Ron::Tuple(_, items) | Ron::List(items) => Box::new(items.iter()),
        Ron::Struct(_, fields) => Box::new(fields.iter().map(|(_, v)| v)),
        Ron::Map(entries) => Box::new(entries.iter().flat_map(|(k, v)| [k, v])),
    }
}

/// The `n`-th node (0-based, pre-order) for which `pick` holds.
fn nth<'a>(node: &'a mut Ron, n: &mut usize, pick: &dyn Fn(&Ron) -> bool) -> Option<&'a mut Ron> {
    if pick(node) {
        if *n == 0 {
            return Some(node);
        }
        *n -= 1;
    }
    let kids: Vec<&'a mut Ron> = match node {
        Ron::Atom(_) => Vec::new(),
        Ron::Tuple(_, items) | Ron::List(items) => items.iter_mut().collect(),
        Ron::Struct(_, fields) => fields.iter_mut().map(|(_, v)| v).collect(),
        Ron::Map(entries) => entries.iter_mut().flat_map(|(k, v)| [k, v]).collect(),
    };
    kids.into_iter().find_map(|kid| nth(kid, n, pick))
}

fn replace(tree: &mut Ron, at: usize, text: &str) {
    let total = count(tree, &any_node);
    if let Some(node) = nth(tree, &mut (at % total), &any_node) {
        *node = Ron::Atom(text.into());
    }
}

fn edit_struct(tree: &mut Ron, at: usize, edit: impl FnOnce(&mut Vec<(String, Ron)>)) {
    let total = count(tree, &is_struct).max(1);
    if let Some(Ron::Struct(_, fields)) = nth(tree, &mut (at % total), &is_struct) {
        edit(fields);
    }
}

/// The first item `length` times; a key (a struct with a `time`) at
/// increasing times, so a track of many keys stays valid.
fn repeat(node: &mut Ron, length: usize) {
    let timed = |i: usize, item: &Ron| match item {
        Ron::Struct(name, fields) => {
            let fields = fields.iter().map(|(f, v)| match f.as_str() {
                "time" => (f.clone(), Ron::Atom(format!("{}", i as f64 * 0.01))),
                _ => (f.clone(), v.clone()),
            });
            Ron::Struct(name.clone(), fields.collect())
        }
        other => other.clone(),
    };
    match node {
        Ron::Tuple(_, items) | Ron::List(items) => {
            if let Some(first) = items.first().cloned() {
                *items = (0..length).map(|i| timed(i, &first)).collect();
            }
        }
        Ron::Map(entries) => {
            if let Some(first) = entries.first().cloned() {
                // A name given twice is refused at the second: no need for more.
                *entries = vec![first; length.min(1000)];
            }
        }
        _ => {}
    }
}

/// An edit of an example timeline's tokens; the first number picks the
/// token among those of its kind.
#[derive(Clone, Debug)]
pub enum TokenEdit {
    /// A number swapped for a `SPECIAL_NUMBERS` one.
    Number(usize, usize),
    /// A name swapped for another of the schema's (or a stray one).
    Name(usize, usize),
    Drop(usize),
}

pub fn token_edit(words: usize) -> impl Strategy<Value = TokenEdit> {
    let n = any::<usize>;
    prop_oneof![
        4 => (n(), 0..SPECIAL_NUMBERS.len()).prop_map(|(a, b)| TokenEdit::Number(a, b)),
        2 => (n(), 0..words + STRAY_NAMES.len()).prop_map(|(a, b)| TokenEdit::Name(a, b)),
        1 => n().prop_map(TokenEdit::Drop),
    ]
}

#[derive(Clone, Copy, PartialEq)]
enum Token {
    Number,
    Name,
    Other,
}

impl TokenEdit {
    /// `words` are the schema's names (`grammar::schema_words`).
    pub fn apply(&self, text: &mut String, words: &[&str]) {
        let tokens = tokens(text);
        let pick = |kind: Option<Token>, at: usize| {
            let of_kind: Vec<_> = tokens
                .iter()
                .filter(|(k, _)| kind.is_none_or(|kind| *k == kind))
                .collect();
            (!of_kind.is_empty()).then(|| of_kind[at % of_kind.len()].1.clone())
        };
        let (range, with) = match *self {
            TokenEdit::Number(at, i) => (pick(Some(Token::Number), at), SPECIAL_NUMBERS[i]),
            TokenEdit::Name(at, i) => {
                let word = words.get(i).copied();
                (
                    pick(Some(Token::Name), at),
                    word.unwrap_or_else(|| STRAY_NAMES[i - words.len()]),
                )
            }
            TokenEdit::Drop(at) => (pick(None, at), ""),
        };
        if let Some(range) = range {
            text.replace_range(range, with);
        }
    }
}

/// RON's tokens outside comments and strings, by byte range: numbers
/// (with a sign or a leading point), names, and single punctuation.
fn tokens(text: &str) -> Vec<(Token, std::ops::Range<usize>)> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let start = i;
        let b = bytes[i];
        let next = bytes.get(i + 1).copied().unwrap_or(0);
        let word = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
        if b == b'/' && next == b'/' {
            i = text[i..].find('\n').map_or(bytes.len(), |n| i + n);
            continue;
        } else if b == b'/' && next == b'*' {
            i = text[i + 2..].find("*/").map_or(bytes.len(), |n| i + n + 4);
            continue;
        } else if b == b'"' {
            i += 1;
            while i < bytes.len() && bytes[i] != b'"' {
                i += if bytes[i] == b'\\' { 2 } else { 1 };
            }
            i = (i + 1).min(bytes.len());
            continue;
        }
        let numeric = b.is_ascii_digit() || (b"+-.".contains(&b) && next.is_ascii_digit());
        let kind = if numeric {
            i += 1;
            while i < bytes.len()
                && (word(bytes[i])
                    || bytes[i] == b'.'
                    || (b"+-".contains(&bytes[i]) && b"eE".contains(&bytes[i - 1])))
            {
                i += 1;
            }
            Token::Number
        } else if word(b) {
            while i < bytes.len() && word(bytes[i]) {
                i += 1;
            }
            Token::Name
        } else {
            // One character, whole (it may take several bytes).
            i += text[i..].chars().next().map_or(1, char::len_utf8);
            if b.is_ascii_whitespace() {
                continue;
            }
            Token::Other
        };
        out.push((kind, start..i));
    }
    out
}

/// An edit of the bytes; positions are taken modulo the length.
#[derive(Clone, Debug)]
pub enum ByteEdit {
    Truncate(usize),
    Delete(usize, usize),
    /// A range copied to another place.
    Copy(usize, usize, usize),
    /// A `SNIPPETS` piece inserted.
    Insert(usize, usize),
    /// Any byte, UTF-8 or not.
    Set(usize, u8),
}

pub fn byte_edit() -> impl Strategy<Value = ByteEdit> {
    let n = any::<usize>;
    let short = 1usize..64;
    prop_oneof![
        2 => n().prop_map(ByteEdit::Truncate),
        1 => (n(), short.clone()).prop_map(|(a, l)| ByteEdit::Delete(a, l)),
        1 => (n(), short, n()).prop_map(|(a, l, to)| ByteEdit::Copy(a, l, to)),
        4 => (n(), 0..SNIPPETS.len()).prop_map(|(a, s)| ByteEdit::Insert(a, s)),
        1 => (n(), any::<u8>()).prop_map(|(a, b)| ByteEdit::Set(a, b)),
    ]
}

impl ByteEdit {
    pub fn apply(&self, bytes: &mut Vec<u8>) {
        let len = bytes.len();
        let at = |p: usize| p % (len + 1);
        match *self {
            ByteEdit::Truncate(p) => bytes.truncate(at(p)),
            ByteEdit::Delete(p, l) => {
                let start = at(p);
                bytes.drain(start..(start + l).min(len));
            }
            ByteEdit::Copy(p, l, to) => {
                let start = at(p);
                let piece = bytes[start..(start + l).min(len)].to_vec();
                let to = at(to);
                bytes.splice(to..to, piece);
            }
            ByteEdit::Insert(p, s) => {
                let to = at(p);
                bytes.splice(to..to, SNIPPETS[s].bytes());
            }
            ByteEdit::Set(p, b) => {
                if len > 0 {
                    bytes[p % len] = b;
                }
            }
        }
    }
}
