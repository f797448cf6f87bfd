//! Where a value stands in a RON document, as RON's own parser reads it:
//! the line and column of the value at a field path, the field path of the
//! value at a line and column, and the bytes of a value and of a block's
//! children (which `timeline::edit` rewrites). Each level is read as `RawValue`s, slices
//! of the document's text, so comments and same-named fields elsewhere
//! never match.

use crate::error::Place;
use ron::value::RawValue;
use serde::de::{Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};
use std::ops::Range;

/// One step of a field path: `.name`, `[3]` or `["camera.position"]`.
#[derive(Clone, Debug, PartialEq)]
pub enum Step {
    Field(String),
    Index(usize),
    Key(String),
}

/// The steps of a field path as messages write them:
/// `scene.extra_lights[0].direction`, `tracks["camera.position"].keys[3]`.
/// A step that cannot be read ends the path there.
pub fn steps(path: &str) -> Vec<Step> {
    let mut steps = Vec::new();
    let mut rest = path;
    while !rest.is_empty() {
        if let Some(quoted) = rest.strip_prefix("[\"") {
            let Some((key, after)) = unquoted(quoted) else {
                break;
            };
            steps.push(Step::Key(key));
            let Some(after) = after.strip_prefix(']') else {
                break;
            };
            rest = after;
        } else if let Some(indexed) = rest.strip_prefix('[') {
            let Some(end) = indexed.find(']') else { break };
            let Ok(i) = indexed[..end].parse() else { break };
            steps.push(Step::Index(i));
            rest = &indexed[end + 1..];
        } else {
            let name = rest.strip_prefix('.').unwrap_or(rest);
            let end = name.find(['.', '[']).unwrap_or(name.len());
            steps.push(Step::Field(name[..end].to_string()));
            rest = &name[end..];
        }
    }
    steps
}

/// The key a path quotes as Rust's `{:?}` writes a string (its opening
/// quote taken off already), and the text after its closing quote.
fn unquoted(quoted: &str) -> Option<(String, &str)> {
    let mut key = String::new();
    let mut chars = quoted.char_indices();
    while let Some((i, c)) = chars.next() {
        match c {
            '"' => return Some((key, &quoted[i + 1..])),
            '\\' => match chars.next()?.1 {
                'n' => key.push('\n'),
                'r' => key.push('\r'),
                't' => key.push('\t'),
                '0' => key.push('\0'),
                'u' => {
                    let rest = &quoted[chars.next()?.0 + 1..];
                    let end = rest.find('}')?;
                    key.push(char::from_u32(u32::from_str_radix(&rest[..end], 16).ok()?)?);
                    (0..=end).for_each(|_| {
                        chars.next();
                    });
                }
                other => key.push(other),
            },
            c => key.push(c),
        }
    }
    None
}

/// Writes steps back as a field path.
pub fn path_of(steps: &[Step]) -> String {
    let mut path = String::new();
    for step in steps {
        match step {
            Step::Field(name) if path.is_empty() => path.push_str(name),
            Step::Field(name) => {
                path.push('.');
                path.push_str(name);
            }
            Step::Index(i) => path.push_str(&format!("[{i}]")),
            Step::Key(key) => path.push_str(&format!("[{key:?}]")),
        }
    }
    path
}

/// Where the value at `path` starts, or `None` where the document does
/// not give it (a default) or is not RON.
pub fn place_of(text: &str, path: &str) -> Option<Place> {
    let wanted = steps(path);
    let (found, at) = deepest(text, &wanted)?;
    (found == wanted.len()).then(|| place(text, at))
}

/// The deepest part of `path` the document gives: how many steps of it,
/// and where that value starts (the whole document for none).
pub fn nearest(text: &str, path: &str) -> Option<(usize, Place)> {
    let (found, at) = deepest(text, &steps(path))?;
    Some((found, place(text, at)))
}

/// The field path of the innermost value at `line`:`column`, where the
/// document is RON (a value of the wrong shape for its field is still RON),
/// and the place to show: the start of a value with nothing inside it, or
/// of one that only white space separates from `line`:`column`.
pub fn path_at(text: &str, line: usize, column: usize) -> Option<(String, Place)> {
    let offset = offset_of(text, line, column)?;
    let mut node = Node::read(text)?;
    let (mut path, mut shown) = (Vec::new(), offset);
    let span = |raw: &str| {
        let end = raw.as_ptr() as usize - text.as_ptr() as usize + raw.len();
        start_of(text, raw)..end
    };
    let before = |start: usize| offset < start && text[offset..start].chars().all(is_blank);
    loop {
        let found = node
            .children
            .into_iter()
            .find(|(_, raw)| span(raw).contains(&offset) || before(span(raw).start));
        let Some((step, raw)) = found else {
            return Some((path_of(&path), place(text, shown)));
        };
        path.push(step);
        let start = span(raw).start;
        match Node::read(raw) {
            Some(child) if !child.children.is_empty() => {
                node = child;
                shown = shown.max(start);
            }
            _ => return Some((path_of(&path), place(text, start))),
        }
    }
}

/// A struct, map, tuple or list as written: its inside, from past the
/// opening bracket to the closing one, and each child's value.
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    pub inside: Range<usize>,
    pub children: Vec<(Step, Range<usize>)>,
}

/// The bytes of the value at `steps`, without the blanks and comments
/// around it; `None` where the document does not give it or is not RON.
pub fn range_at(text: &str, steps: &[Step]) -> Option<Range<usize>> {
    let raw = raw_at(text, steps)?;
    let start = start_of(text, raw);
    Some(start..value_end(text, start)?)
}

/// The block at `steps` (inside `Some(…)` where it is written so), or
/// `None` where that value is not a block or not given.
pub fn block_at(text: &str, steps: &[Step]) -> Option<Block> {
    let raw = raw_at(text, steps)?;
    let node = Node::read(raw)?;
    let mut range = range_at(text, steps)?;
    if let Some(inner) = inside_some(text, range.clone()) {
        range = inner;
    }
    // A struct's name may stand before its bracket: `Camera(…)`.
    let open = range.start + text[range.clone()].find(['(', '{', '['])?;
    let named = |c: char| c.is_alphanumeric() || c == '_' || is_blank(c);
    let inside = open + 1..range.end - 1;
    let empty = skip_blank(text, inside.start) >= inside.end;
    // An enum's variant `Filmic(…)` reads as a leaf: it is no block.
    if !text[range.start..open].chars().all(named) || (node.children.is_empty() && !empty) {
        return None;
    }
    let children = node
        .children
        .into_iter()
        .map(|(step, raw)| {
            let start = start_of(text, raw);
            Some((step, start..value_end(text, start)?))
        })
        .collect::<Option<_>>()?;
    Some(Block { inside, children })
}

/// The value inside `Some(…)` where `range` is written so.
pub fn inside_some(text: &str, range: Range<usize>) -> Option<Range<usize>> {
    let rest = text[range.clone()].strip_prefix("Some")?;
    let open = range.end - rest.len() + rest.find('(')?;
    let start = skip_blank(text, open + 1);
    Some(start..value_end(text, start)?)
}

/// The raw slice of the value at `steps`.
fn raw_at<'a>(text: &'a str, steps: &[Step]) -> Option<&'a str> {
    let mut raw = text;
    for step in steps {
        let node = Node::read(raw)?;
        raw = node.children.into_iter().find(|(s, _)| same(s, step))?.1;
    }
    Some(raw)
}

/// Whether two steps name the same child: a struct's field and a map's
/// string key are both names.
fn same(a: &Step, b: &Step) -> bool {
    match (a, b) {
        (Step::Index(a), Step::Index(b)) => a == b,
        (Step::Field(a) | Step::Key(a), Step::Field(b) | Step::Key(b)) => a == b,
        _ => false,
    }
}

/// Where the value starting at `start` ends, as RON reads it.
fn value_end(text: &str, start: usize) -> Option<usize> {
    let options =
        ron::Options::default().with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME);
    let mut de = ron::Deserializer::from_str_with_options(&text[start..], &options).ok()?;
    serde::de::IgnoredAny::deserialize(&mut de).ok()?;
    Some(text.len() - de.remainder().len())
}

/// White space as RON skips it (Unicode's pattern white space).
fn is_blank(c: char) -> bool {
    c.is_whitespace() || matches!(c, '\u{200e}' | '\u{200f}')
}

/// How many of `wanted`'s steps the document gives, and the byte offset
/// of the deepest value found.
fn deepest(text: &str, wanted: &[Step]) -> Option<(usize, usize)> {
    let mut raw = text;
    if wanted.is_empty() {
        Node::read(raw)?;
    }
    for (depth, step) in wanted.iter().enumerate() {
        let Some(node) = Node::read(raw) else {
            // Text that is not RON has no places; a leaf has no fields.
            return (depth > 0).then(|| (depth, start_of(text, raw)));
        };
        match node.children.into_iter().find(|(s, _)| same(s, step)) {
            Some((_, child)) => raw = child,
            None => return Some((depth, start_of(text, raw))),
        }
    }
    Some((wanted.len(), start_of(text, raw)))
}

/// The byte offset in `text` where the value `raw` (a slice of it) starts,
/// past any comments RON kept in front of it.
fn start_of(text: &str, raw: &str) -> usize {
    skip_blank(text, raw.as_ptr() as usize - text.as_ptr() as usize)
}

/// `at` moved past white space and comments.
pub fn skip_blank(text: &str, mut at: usize) -> usize {
    loop {
        let rest = &text[at..];
        let trimmed = rest.trim_start_matches(is_blank);
        at += rest.len() - trimmed.len();
        if trimmed.starts_with("//") {
            at += trimmed.find('\n').unwrap_or(trimmed.len());
        } else if trimmed.starts_with("/*") {
            at += block_comment_len(trimmed);
        } else {
            return at;
        }
    }
}

/// The length of the block comment `text` starts with (RON's nest).
fn block_comment_len(text: &str) -> usize {
    let mut depth = 0usize;
    let mut i = 0;
    let bytes = text.as_bytes();
    while i < bytes.len() {
        match (bytes[i], bytes.get(i + 1)) {
            (b'/', Some(b'*')) => {
                depth += 1;
                i += 2;
            }
            (b'*', Some(b'/')) => {
                depth -= 1;
                i += 2;
                if depth == 0 {
                    return i;
                }
            }
            _ => i += 1,
        }
    }
    text.len()
}

/// The place of byte `offset` in `text`.
pub fn place(text: &str, offset: usize) -> Place {
    let before = &text[..offset];
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    Place {
        line: before.matches('\n').count() + 1,
        column: before[line_start..].chars().count() + 1,
    }
}

/// The byte offset of `line`:`column` (1-based) in `text`.
pub fn offset_of(text: &str, line: usize, column: usize) -> Option<usize> {
    let line_start = if line <= 1 {
        0
    } else {
        text.match_indices('\n').nth(line - 2)?.0 + 1
    };
    let row = &text[line_start..];
    let within = row
        .char_indices()
        .nth(column.saturating_sub(1))
        .map_or(row.len(), |(i, _)| i);
    Some(line_start + within)
}

/// One level of a document: its children by step, each a slice of the text.
struct Node<'a> {
    children: Vec<(Step, &'a str)>,
}

impl<'a> Node<'a> {
    /// `raw` read as one RON value; `None` where it is not RON.
    fn read(raw: &'a str) -> Option<Node<'a>> {
        let options = ron::Options::default()
            .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME);
        let braced = raw[skip_blank(raw, 0)..].starts_with('{');
        let level: Level = options.from_str(raw).ok()?;
        let children = match level {
            Level::Fields(fields) => fields
                .into_iter()
                .map(|(name, value)| {
                    let step = if braced {
                        Step::Key(name)
                    } else {
                        Step::Field(name)
                    };
                    (step, value.get_ron())
                })
                .collect(),
            Level::Items(items) => items
                .into_iter()
                .enumerate()
                .map(|(i, value)| (Step::Index(i), value.get_ron()))
                .collect(),
            Level::Leaf => Vec::new(),
        };
        Some(Node { children })
    }
}

/// A value read one level deep: named fields (a struct or map), items (a
/// tuple or list), or a leaf. `Some(x)` is read as `x`, as the schema's
/// paths name it.
enum Level<'a> {
    Fields(Vec<(String, &'a RawValue)>),
    Items(Vec<&'a RawValue>),
    Leaf,
}

impl<'de> Deserialize<'de> for Level<'de> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(LevelVisitor)
    }
}

struct LevelVisitor;

impl<'de> Visitor<'de> for LevelVisitor {
    type Value = Level<'de>;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("any RON value")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Level<'de>, A::Error> {
        let mut fields = Vec::new();
        while let Some(Name(name)) = map.next_key()? {
            fields.push((name, map.next_value()?));
        }
        Ok(Level::Fields(fields))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Level<'de>, A::Error> {
        let mut items = Vec::new();
        while let Some(item) = seq.next_element()? {
            items.push(item);
        }
        Ok(Level::Items(items))
    }

    fn visit_some<D: Deserializer<'de>>(self, d: D) -> Result<Level<'de>, D::Error> {
        Level::deserialize(d)
    }

    fn visit_enum<A: serde::de::EnumAccess<'de>>(self, _: A) -> Result<Level<'de>, A::Error> {
        Ok(Level::Leaf)
    }

    fn visit_bool<E>(self, _: bool) -> Result<Level<'de>, E> {
        Ok(Level::Leaf)
    }
    fn visit_i64<E>(self, _: i64) -> Result<Level<'de>, E> {
        Ok(Level::Leaf)
    }
    fn visit_u64<E>(self, _: u64) -> Result<Level<'de>, E> {
        Ok(Level::Leaf)
    }
    fn visit_i128<E>(self, _: i128) -> Result<Level<'de>, E> {
        Ok(Level::Leaf)
    }
    fn visit_u128<E>(self, _: u128) -> Result<Level<'de>, E> {
        Ok(Level::Leaf)
    }
    fn visit_f64<E>(self, _: f64) -> Result<Level<'de>, E> {
        Ok(Level::Leaf)
    }
    fn visit_char<E>(self, _: char) -> Result<Level<'de>, E> {
        Ok(Level::Leaf)
    }
    fn visit_str<E>(self, _: &str) -> Result<Level<'de>, E> {
        Ok(Level::Leaf)
    }
    fn visit_bytes<E>(self, _: &[u8]) -> Result<Level<'de>, E> {
        Ok(Level::Leaf)
    }
    fn visit_none<E>(self) -> Result<Level<'de>, E> {
        Ok(Level::Leaf)
    }
    fn visit_unit<E>(self) -> Result<Level<'de>, E> {
        Ok(Level::Leaf)
    }
}

/// A field name or a map's key, whichever way RON hands it over.
struct Name(String);

impl<'de> Deserialize<'de> for Name {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Text;
        impl Visitor<'_> for Text {
            type Value = Name;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a field name or a string key")
            }
            fn visit_str<E>(self, s: &str) -> Result<Name, E> {
                Ok(Name(s.to_string()))
            }
        }
        d.deserialize_any(Text)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DOC: &str = "// fps: 24 in a comment\n\
        (\n\
        \x20   size: (8, 8),\n\
        \x20   fps: /* fps: 1 */ 24,\n\
        \x20   scene: (\n\
        \x20       camera: (aperture_radius: 0.1, up: Some((0, 0, 1))),\n\
        \x20       effects: (ambient_occlusion: (radius: 0.2)),\n\
        \x20   ),\n\
        \x20   tracks: {\n\
        \x20       \"camera.fov_degrees\": (keys: [\n\
        \x20           (time: 0, value: 40),\n\
        \x20           (time: 1, value: 30),\n\
        \x20       ]),\n\
        \x20   },\n\
        )\n";

    fn at(line: usize, column: usize) -> Option<Place> {
        Some(Place { line, column })
    }

    #[test]
    fn paths_read_back_as_written() {
        for path in [
            "fps",
            "scene.extra_lights[0].direction",
            "tracks[\"camera.position\"].keys[3].time",
        ] {
            assert_eq!(path_of(&steps(path)), path);
        }
        assert_eq!(
            steps("tracks[\"a.b\"].keys[2]"),
            vec![
                Step::Field("tracks".into()),
                Step::Key("a.b".into()),
                Step::Field("keys".into()),
                Step::Index(2)
            ]
        );
    }

    #[test]
    fn a_value_is_found_where_it_stands_not_where_its_name_is_mentioned() {
        assert_eq!(place_of(DOC, "fps"), at(4, 23));
        assert_eq!(place_of(DOC, "size"), at(3, 11));
        assert_eq!(place_of(DOC, "size[1]"), at(3, 15));
        assert_eq!(place_of(DOC, "scene.camera.aperture_radius"), at(6, 35));
        assert_eq!(place_of(DOC, "scene.camera.up[2]"), at(6, 56));
        assert_eq!(
            place_of(DOC, "scene.effects.ambient_occlusion.radius"),
            at(7, 47)
        );
        assert_eq!(
            place_of(DOC, "tracks[\"camera.fov_degrees\"].keys[1].value"),
            at(12, 30)
        );
    }

    #[test]
    fn a_default_is_not_found_and_its_nearest_given_block_is() {
        assert_eq!(
            place_of(DOC, "scene.effects.ambient_occlusion.samples"),
            None
        );
        assert_eq!(place_of(DOC, "scene.look"), None);
        assert_eq!(
            nearest(DOC, "scene.camera.position"),
            Some((2, at(6, 17).unwrap()))
        );
        assert_eq!(nearest(DOC, "frames"), Some((0, at(2, 1).unwrap())));
    }

    #[test]
    fn a_place_is_named_by_its_innermost_field() {
        let named = |line, column| path_at(DOC, line, column).map(|(path, _)| path);
        let fov_key = "tracks[\"camera.fov_degrees\"].keys[1].value";
        assert_eq!(named(3, 15).as_deref(), Some("size[1]"));
        assert_eq!(named(12, 30).as_deref(), Some(fov_key));
        // Between fields, or in a comment: the block's.
        assert_eq!(named(1, 5).as_deref(), Some(""));
        assert_eq!(named(4, 10).as_deref(), Some(""));
        // White space before a value is the value's, and its start is shown.
        assert_eq!(
            path_at(DOC, 3, 10),
            Some(("size".into(), at(3, 11).unwrap()))
        );
        assert_eq!(
            path_at(DOC, 12, 29),
            Some((fov_key.into(), at(12, 30).unwrap()))
        );
    }

    #[test]
    fn a_key_with_quotes_and_escapes_reads_back() {
        let key = "a\"]b\u{200e}";
        let path = path_of(&[Step::Field("tracks".into()), Step::Key(key.into())]);
        assert_eq!(steps(&path)[1], Step::Key(key.into()));
        let doc = "(tracks: {\"a\\\"]b\u{200e}\": (keys: [3]), \"//x\": 1})";
        assert_eq!(place_of(doc, &format!("{path}.keys[0]")), at(1, 29));
        // A place inside a key's string is not read as a comment.
        let inside = path_at(doc, 1, 35).map(|(path, _)| path);
        assert_eq!(inside.as_deref(), Some("tracks"));
    }

    #[test]
    fn ranges_hold_the_value_alone_and_blocks_their_children() {
        let path = |p: &str| steps(p);
        let text = |p: &str| range_at(DOC, &path(p)).map(|r| &DOC[r]);
        assert_eq!(text("fps"), Some("24"));
        assert_eq!(text("scene.camera.up"), Some("Some((0, 0, 1))"));
        assert_eq!(text("scene.camera.up[1]"), Some("0"));
        assert_eq!(text("scene.camera.focus"), None);
        let up = block_at(DOC, &path("scene.camera.up")).unwrap();
        assert_eq!(&DOC[up.inside.clone()], "0, 0, 1");
        assert_eq!(up.children.len(), 3);
        let tracks = block_at(DOC, &path("tracks")).unwrap();
        let (key, value) = &tracks.children[0];
        assert_eq!(key, &Step::Key("camera.fov_degrees".into()));
        assert!(DOC[value.clone()].starts_with("(keys: [") && DOC[value.clone()].ends_with("])"));
        assert_eq!(block_at(DOC, &path("fps")), None);
        let empty = block_at("(a: (), b: Some(Named( /* c */ )))", &path("b")).unwrap();
        assert_eq!((empty.inside, empty.children), (22..31, vec![]));
    }

    #[test]
    fn text_that_is_not_ron_has_no_places() {
        assert_eq!(place_of("(fps: ", "fps"), None);
        assert_eq!(path_at("(fps: ", 1, 2), None);
        // RON's invisible marks are white space before a value.
        assert_eq!(place_of("(fps: \u{200e}1)", "fps"), at(1, 8));
    }
}
