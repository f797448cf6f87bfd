//! Edits of a timeline's RON text that keep everything else as written: a
//! scene value set, a track's key set, moved or deleted. Each edit finds
//! its place with RON's own parser (`spans`) and changes only the bytes it
//! must, so the author's comments, field order and layout survive a save.

use super::parameters::{self, Parameter, Shape};
use super::spans::{self, Block, Step};
use super::{KeyValue, Timeline, ZOOM_TRACK};
use crate::math::Real;
use crate::scene::Scene;
use std::ops::Range;

/// One change a user makes to a timeline.
#[derive(Clone, Debug, PartialEq)]
pub enum Edit {
    /// `scene.<parameter>`: replaced where written, else inserted with any
    /// block missing around it.
    SetScene { parameter: String, value: KeyValue },
    /// The key of `track` at `time`: its value replaced, else a key added
    /// in time order (and the track, and `tracks`, where absent).
    SetKey {
        track: String,
        time: Real,
        value: KeyValue,
    },
    /// Removes key `index`; removing the last key removes the track.
    DeleteKey { track: String, index: usize },
    /// Gives key `index` a new time, moving it to keep the keys in order.
    MoveKey {
        track: String,
        index: usize,
        time: Real,
    },
}

impl Edit {
    /// Whether the edit sets a point a timeline may write as digits, with
    /// numbers (`keeping_digits`).
    pub fn may_round_digits(&self) -> bool {
        let (name, value) = match self {
            Edit::SetScene { parameter, value } => (parameter, value),
            Edit::SetKey { track, value, .. } => (track, value),
            _ => return false,
        };
        let takes = parameters::find(name).is_some_and(|p| p.digits.is_some());
        takes && matches!(value, KeyValue::Triple(..))
    }
}

/// Key times closer than this are the same key's.
const SAME_TIME: Real = 1e-9;

/// Scene fields held as whole numbers: RON refuses `8.5` (or `8.0`) there.
const WHOLE_NUMBERS: [&str; 2] = ["fractal.iterations", "quality.max_steps"];

/// `text` with `edit` made, or what stops it. A file whose lines all end
/// in CR LF keeps them so: it is edited with LF and turned back.
pub fn apply(text: &str, edit: &Edit) -> Result<String, String> {
    edited(text, |value| apply_to_value(value, edit))
}

/// `text` with `scene.camera.target` written as `target`, RON text as
/// `pick` prints it (digit strings for deep targets), where no track sets it.
pub fn set_target(text: &str, target: &str) -> Result<String, String> {
    edited(text, |value| {
        spans::block_at(value, &[]).ok_or("the text is not a timeline in RON: `( … )`")?;
        if keys(value, "camera.target")?.is_some() {
            return Err(
                "a \"camera.target\" track sets the target: change its keys instead".into(),
            );
        }
        let path = ["scene", "camera", "target"].map(|f| Step::Field(f.into()));
        set_field(value, &path, target)
    })
}

/// Whether `values` are only the nearest numbers of digits `scene` holds
/// for `parameter`: a page holds numbers, and sends them back unmoved.
pub fn rounds_digits(scene: &Scene, parameter: &Parameter, values: &[Real]) -> bool {
    let held = parameter.digits.and_then(|exact| (exact.get)(scene));
    held.is_some_and(|point| point.value.to_array()[..] == *values)
}

/// `edit` with the digits `timeline` holds at its place where its value is
/// only their nearest numbers (`rounds_digits`), so an edit sent back
/// unmoved never writes rounded digits over exact ones.
pub fn keeping_digits(timeline: &Timeline, edit: Edit) -> Edit {
    let (name, time, value) = match &edit {
        Edit::SetScene { parameter, value } => (parameter, None, value),
        Edit::SetKey { track, time, value } => (track, Some(*time), value),
        _ => return edit,
    };
    let Some(parameter) = parameters::find(name).filter(|_| edit.may_round_digits()) else {
        return edit;
    };
    let scene = time.map_or_else(|| timeline.base.clone(), |t| timeline.scene_at_time(t));
    let held = parameter.digits.and_then(|exact| (exact.get)(&scene));
    let Some(point) = held.filter(|_| rounds_digits(&scene, parameter, &value.components())) else {
        return edit;
    };
    let value = KeyValue::Digits(point);
    match edit {
        Edit::SetScene { parameter, .. } => Edit::SetScene { parameter, value },
        Edit::SetKey { track, time, .. } => Edit::SetKey { track, time, value },
        other => other,
    }
}

/// `edit` made to the document's value, after RON's inner attributes
/// (`#![enable(…)]`) if any, keeping CR LF line ends where all are.
fn edited(text: &str, edit: impl Fn(&str) -> Result<String, String>) -> Result<String, String> {
    let crlf = text.contains("\r\n") && text.matches('\n').count() == text.matches("\r\n").count();
    let lf = if crlf {
        text.replace("\r\n", "\n")
    } else {
        text.to_string()
    };
    let (attributes, value) = lf.split_at(attributes_end(&lf));
    let done = format!("{attributes}{}", edit(value)?);
    Ok(if crlf {
        done.replace('\n', "\r\n")
    } else {
        done
    })
}

/// Where RON's inner attributes before the document's value end.
fn attributes_end(text: &str) -> usize {
    let mut at = 0;
    loop {
        let start = spans::skip_blank(text, at);
        let close = text[start..]
            .strip_prefix("#![")
            .and_then(|rest| rest.find(']'));
        match close {
            Some(close) => at = start + 3 + close + 1,
            None => return at,
        }
    }
}

fn apply_to_value(text: &str, edit: &Edit) -> Result<String, String> {
    spans::block_at(text, &[]).ok_or("the text is not a timeline in RON: `( … )`")?;
    match edit {
        Edit::SetScene { parameter, value } => set_scene(text, parameter, value),
        Edit::SetKey { track, time, value } => set_key(text, track, *time, value),
        Edit::DeleteKey { track, index } => delete_key(text, track, *index),
        Edit::MoveKey { track, index, time } => move_key(text, track, *index, *time),
    }
}

fn set_scene(text: &str, name: &str, value: &KeyValue) -> Result<String, String> {
    let parameter = parameter(name)?;
    if parameter.name == ZOOM_TRACK {
        return Err(format!(
            "{ZOOM_TRACK} is no scene field: only a track sets it"
        ));
    }
    auto_kept(text, name)?;
    let written = written(value, parameter)?;
    if let (true, KeyValue::Number(v)) = (WHOLE_NUMBERS.contains(&name), value) {
        if v.fract() != 0.0 || !(0.0..=u32::MAX as Real).contains(v) {
            return Err(format!("scene.{name} is a whole number, got {v}"));
        }
    }
    // A palette stop's parameter indexes its list: `look.palette.stops[1].colour`.
    let mut path = vec![Step::Field("scene".into())];
    path.extend(spans::steps(name));
    set_field(text, &path, &written)
}

/// Refuses a number for `fractal.iterations`, as a scene value or a key,
/// where the scene writes `Auto`: a number there would silently end the
/// per-frame choice, so switching to a fixed count is the author's, in the
/// text.
fn auto_kept(text: &str, name: &str) -> Result<(), String> {
    const ITERATIONS: &str = "fractal.iterations";
    let path = ["scene", "fractal", "iterations"].map(|f| Step::Field(f.into()));
    let auto = name == ITERATIONS
        && spans::range_at(text, &path).is_some_and(|r| text[r].trim_start().starts_with("Auto"));
    match auto {
        true => Err(format!(
            "scene.{ITERATIONS} is `Auto`, which chooses each frame's count: the explorer writes no number over it; to fix the count, write a number in place of `Auto` in the timeline's text"
        )),
        false => Ok(()),
    }
}

/// The field at `path` set to `value`: replaced where written (inside its
/// `Some(…)`), else inserted in the deepest block given, nested in the
/// blocks missing.
fn set_field(text: &str, path: &[Step], value: &str) -> Result<String, String> {
    if let Some(range) = spans::range_at(text, path) {
        let range = spans::inside_some(text, range.clone()).unwrap_or(range);
        return Ok(rewritten(text, range, value));
    }
    let given = (0..path.len())
        .rev()
        .find(|&n| spans::range_at(text, &path[..n]).is_some())
        .unwrap_or(0);
    let block = spans::block_at(text, &path[..given]).ok_or_else(|| {
        let path = spans::path_of(&path[..given]);
        format!("{path} is written as a value, not a block of fields")
    })?;
    let mut entry = value.to_string();
    for (i, step) in path[given..].iter().enumerate().rev() {
        let Step::Field(name) = step else {
            return Err(format!("cannot write {}", spans::path_of(path)));
        };
        let last = i + given + 1 == path.len();
        entry = if last {
            format!("{name}: {entry}")
        } else {
            format!("{name}: ({entry})")
        };
    }
    Ok(insert(text, &block, block.children.len(), &entry))
}

fn set_key(text: &str, track: &str, time: Real, value: &KeyValue) -> Result<String, String> {
    let value = written(value, parameter(track)?)?;
    auto_kept(text, track)?;
    let time_text = key_time_text(time)?;
    let Some(keys) = keys(text, track)? else {
        let key = format!("(time: {time_text}, value: {value})");
        return add_track(text, track, &key);
    };
    if let Some(i) = keys.times.iter().position(|t| (t - time).abs() < SAME_TIME) {
        let range = key_part(text, keys.range(i), "value")?;
        return Ok(rewritten(text, range, &value));
    }
    let index = keys.times.iter().filter(|&&t| t < time).count();
    // Written like the key before it (or after, for a new first key).
    let key = match keys.block.children.len() {
        0 => format!("(time: {time_text}, value: {value})"),
        _ => {
            let like = keys.range(index.saturating_sub(1));
            with_parts(text, like, &[("time", &time_text), ("value", &value)])?
        }
    };
    Ok(insert(text, &keys.block, index, &key))
}

fn delete_key(text: &str, track: &str, index: usize) -> Result<String, String> {
    let keys = existing_keys(text, track, index)?;
    if keys.block.children.len() > 1 {
        return Ok(remove(text, &keys.block, index, true));
    }
    let tracks = spans::block_at(text, &tracks_path()).ok_or("tracks is not a map")?;
    let entry = tracks
        .children
        .iter()
        .position(|(step, _)| matches!(step, Step::Key(k) | Step::Field(k) if k == track))
        .ok_or_else(|| format!("there is no track \"{track}\""))?;
    Ok(remove(text, &tracks, entry, true))
}

fn move_key(text: &str, track: &str, index: usize, time: Real) -> Result<String, String> {
    let keys = existing_keys(text, track, index)?;
    let time_text = key_time_text(time)?;
    let others = || keys.times.iter().enumerate().filter(|&(i, _)| i != index);
    if others().any(|(_, t)| (t - time).abs() < SAME_TIME) {
        return Err(format!(
            "track \"{track}\" has a key at time {time} already"
        ));
    }
    let target = others().filter(|&(_, &t)| t < time).count();
    if target == index {
        let range = key_part(text, keys.range(index), "time")?;
        return Ok(spliced(text, range, &time_text));
    }
    let key = with_parts(text, keys.range(index), &[("time", &time_text)])?;
    // A moved key's comment stays where it was written.
    let without = remove(text, &keys.block, index, false);
    let keys = self::keys(&without, track)?.ok_or("the track went missing")?;
    Ok(insert(&without, &keys.block, target, &key))
}

/// A track's keys as written, and their times.
struct Keys {
    block: Block,
    times: Vec<Real>,
}

impl Keys {
    fn range(&self, index: usize) -> Range<usize> {
        self.block.children[index].1.clone()
    }
}

fn tracks_path() -> Vec<Step> {
    vec![Step::Field("tracks".into())]
}

/// The keys of `track`, or `None` where the timeline has no such track.
fn keys(text: &str, track: &str) -> Result<Option<Keys>, String> {
    let mut path = tracks_path();
    path.extend([Step::Key(track.into()), Step::Field("keys".into())]);
    let Some(block) = spans::block_at(text, &path) else {
        return match spans::range_at(text, &path[..2]) {
            Some(_) => Err(format!("track \"{track}\" has no list of keys")),
            None => Ok(None),
        };
    };
    let times = (0..block.children.len())
        .map(|i| {
            let range = key_part(text, block.children[i].1.clone(), "time")?;
            ron::from_str(&text[range]).map_err(|e| format!("key {i}'s time: {e}"))
        })
        .collect::<Result<_, String>>()?;
    Ok(Some(Keys { block, times }))
}

/// The keys of a track that exists and has key `index`.
fn existing_keys(text: &str, track: &str, index: usize) -> Result<Keys, String> {
    parameter(track)?;
    let keys = keys(text, track)?.ok_or_else(|| format!("there is no track \"{track}\""))?;
    let count = keys.times.len();
    if index >= count {
        return Err(format!(
            "track \"{track}\" has {count} keys, no key {index}"
        ));
    }
    Ok(keys)
}

/// Where field `name` of the key at `key` is written.
fn key_part(text: &str, key: Range<usize>, name: &str) -> Result<Range<usize>, String> {
    let within = spans::range_at(&text[key.clone()], &[Step::Field(name.into())])
        .ok_or_else(|| format!("a key without a {name}: {}", &text[key.clone()]))?;
    Ok(within.start + key.start..within.end + key.start)
}

/// The key at `key` written with some fields' values replaced.
fn with_parts(text: &str, key: Range<usize>, parts: &[(&str, &str)]) -> Result<String, String> {
    let mut ranges = parts
        .iter()
        .map(|&(name, new)| Ok((key_part(text, key.clone(), name)?, new)))
        .collect::<Result<Vec<_>, String>>()?;
    ranges.sort_by_key(|(range, _)| std::cmp::Reverse(range.start));
    let mut written = text[key.clone()].to_string();
    for (range, new) in ranges {
        written.replace_range(range.start - key.start..range.end - key.start, new);
    }
    Ok(written)
}

/// A new track with its one key, at the end of `tracks` (made where absent):
/// laid out over lines as the examples are, where `tracks` is.
fn add_track(text: &str, track: &str, key: &str) -> Result<String, String> {
    let entry = format!("\"{track}\": (keys: [{key}])");
    match spans::block_at(text, &tracks_path()) {
        Some(tracks) => {
            let entry = match text[tracks.inside.clone()].contains('\n') {
                true => format!("\"{track}\": (\n    keys: [\n        {key},\n    ],\n)"),
                false => entry,
            };
            Ok(insert(text, &tracks, tracks.children.len(), &entry))
        }
        None if spans::range_at(text, &tracks_path()).is_some() => {
            Err("tracks is not a map".into())
        }
        None => set_field(text, &tracks_path(), &format!("{{{entry}}}")),
    }
}

fn parameter(name: &str) -> Result<&'static Parameter, String> {
    parameters::find(name).ok_or_else(|| format!("no parameter is named \"{name}\""))
}

fn key_time_text(time: Real) -> Result<String, String> {
    if time < 0.0 {
        return Err(format!("a key's time must be 0 or later, got {time}"));
    }
    number(time)
}

/// A value as RON text, if it has the parameter's shape.
fn written(value: &KeyValue, parameter: &Parameter) -> Result<String, String> {
    match (value, parameter.shape) {
        (KeyValue::Number(v), Shape::Number) => number(*v),
        (KeyValue::Triple(x, y, z), Shape::Triple) => Ok(format!(
            "({}, {}, {})",
            number(*x)?,
            number(*y)?,
            number(*z)?
        )),
        (KeyValue::Digits(point), Shape::Triple) if parameter.digits.is_some() => {
            let d = point.clone().with_digits().digits.unwrap_or_default();
            Ok(format!("({:?}, {:?}, {:?})", d[0], d[1], d[2]))
        }
        (_, shape) => Err(format!(
            "{} takes {} number(s), got {value:?}",
            parameter.name,
            shape.components()
        )),
    }
}

/// The shortest text that reads back as `v`: whole numbers without `.0`,
/// as integer fields need, and exponents for the very large and small.
fn number(v: Real) -> Result<String, String> {
    if !v.is_finite() {
        return Err(format!("{v} is not a finite number"));
    }
    Ok(if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{v}")
    } else {
        format!("{v:?}")
    })
}

/// `text` with the value at `range` rewritten as `value` (`keeping_components`).
fn rewritten(text: &str, range: Range<usize>, value: &str) -> String {
    let value = keeping_components(&text[range.clone()], value);
    spliced(text, range, &value)
}

/// `new` written over `old` with every component that reads as the same
/// number (or the same text) kept as `old` writes it: typing one component
/// of `(0.55, 0.50, 0.45)` leaves `0.50` as it was, not `0.5`.
fn keeping_components(old: &str, new: &str) -> String {
    let (Some(old_parts), Some(new_parts)) = (components(old), components(new)) else {
        return new.to_string();
    };
    if old_parts.len() != new_parts.len() {
        return new.to_string();
    }
    let same = |a: &str, b: &str| {
        let (a, b) = (a.trim(), b.trim());
        a == b || matches!((a.parse::<Real>(), b.parse::<Real>()), (Ok(x), Ok(y)) if x == y)
    };
    let mut kept = old.to_string();
    for (o, n) in old_parts.iter().zip(&new_parts).rev() {
        if !same(&old[o.clone()], &new[n.clone()]) {
            kept = spliced(&kept, o.clone(), new[n.clone()].trim());
        }
    }
    kept
}

/// The ranges of a value's components: the parts between the commas of a
/// `( … )` written on its own, or the whole of a plain number. None where
/// the text nests, quotes a comma or holds a comment, which are written anew.
fn components(text: &str) -> Option<Vec<Range<usize>>> {
    if text.contains("//") || text.contains("/*") {
        return None;
    }
    let trimmed = text.trim();
    let start = text.len() - text.trim_start().len();
    let Some(inner) = trimmed.strip_prefix('(').and_then(|t| t.strip_suffix(')')) else {
        let whole = start..start + trimmed.len();
        return (!text.contains(['(', ')', ','])).then(|| std::iter::once(whole).collect());
    };
    if inner.contains(['(', ')']) || inner.matches('"').count() % 2 != 0 {
        return None;
    }
    let mut parts = Vec::new();
    let mut from = start + 1;
    // A trailing comma, as a value laid out over lines may have.
    let inner = match inner.trim_end().strip_suffix(',') {
        Some(listed) => listed,
        None => inner,
    };
    for piece in inner.split(',') {
        if piece.contains('"') && piece.trim().matches('"').count() != 2 {
            return None;
        }
        let lead = piece.len() - piece.trim_start().len();
        parts.push(from + lead..from + lead + piece.trim().len());
        from += piece.len() + 1;
    }
    Some(parts)
}

/// `entry` made child `index` of `block`: on a line of its own, indented
/// as its neighbour is, where the neighbour stands on its own line.
fn insert(text: &str, block: &Block, index: usize, entry: &str) -> String {
    if index > 0 {
        return insert_after(text, block, index - 1, entry);
    }
    if block.children.is_empty() {
        return insert_into_empty(text, block, entry);
    }
    let start = entry_start(text, block, 0);
    let line = line_start(text, start);
    if text[line..start].trim().is_empty() {
        let indent = &text[line..start];
        let entry = indented(entry, indent);
        spliced(text, line..line, &format!("{indent}{entry},\n"))
    } else {
        spliced(text, start..start, &format!("{entry}, "))
    }
}

/// `entry` as the only child of `block`: on a line of its own, indented a
/// step past the closing bracket, where the empty block spans lines.
fn insert_into_empty(text: &str, block: &Block, entry: &str) -> String {
    let at = block.inside.start;
    if !text[block.inside.clone()].contains('\n') {
        return spliced(text, at..at, entry);
    }
    let close = block.inside.end;
    let line = line_start(text, close);
    let closing = &text[line..close];
    let base = if closing.trim().is_empty() {
        closing
    } else {
        ""
    };
    let indent = format!("{base}    ");
    let entry = indented(entry, &indent);
    spliced(text, at..at, &format!("\n{indent}{entry},"))
}

/// `entry`'s later lines indented as its first stands.
fn indented(entry: &str, indent: &str) -> String {
    entry.replace('\n', &format!("\n{indent}"))
}

fn insert_after(text: &str, block: &Block, index: usize, entry: &str) -> String {
    let end = block.children[index].1.end;
    let comma = comma_after(text, end);
    let past = comma.map_or(end, |c| c + 1);
    let rest_of_line = text[past..]
        .find('\n')
        .map(|n| (past + n, text[past..past + n].trim()));
    match (rest_of_line, comma) {
        (Some((eol, rest)), _) if rest.is_empty() || rest.starts_with("//") => {
            let line = line_start(text, entry_start(text, block, index));
            let indent = &text[line..line + text[line..].len() - text[line..].trim_start().len()];
            let comma_text = if comma.is_some() { "," } else { "" };
            let entry = indented(entry, indent);
            let with_line = spliced(
                text,
                eol + 1..eol + 1,
                &format!("{indent}{entry}{comma_text}\n"),
            );
            match comma {
                Some(_) => with_line,
                None => spliced(&with_line, end..end, ","),
            }
        }
        (_, Some(c)) => spliced(text, c + 1..c + 1, &format!(" {entry},")),
        (_, None) => spliced(text, end..end, &format!(", {entry}")),
    }
}

/// `text` without child `index` of `block`: its whole line where it stands
/// on its own (with the comment after it, where `comment_too`), else the
/// child and its comma.
fn remove(text: &str, block: &Block, index: usize, comment_too: bool) -> String {
    let start = entry_start(text, block, index);
    let end = block.children[index].1.end;
    let comma = comma_after(text, end);
    let past = comma.map_or(end, |c| c + 1);
    let eol = text[past..].find('\n').map_or(text.len(), |n| past + n);
    let line = line_start(text, start);
    let rest = &text[past..eol];
    // A comment after an entry on its line is the entry's.
    let gone = rest.trim().is_empty() || (comment_too && rest.trim_start().starts_with("//"));
    if text[line..start].trim().is_empty() && gone {
        return spliced(text, line..(eol + 1).min(text.len()), "");
    }
    match (comma, index) {
        (None, 1..) => spliced(text, block.children[index - 1].1.end..end, ""),
        _ => {
            let spaces = rest.len() - rest.trim_start().len();
            spliced(text, start..past + spaces, "")
        }
    }
}

/// Where child `index`'s entry starts: its name or key, or the value itself.
fn entry_start(text: &str, block: &Block, index: usize) -> usize {
    let from = match index {
        0 => block.inside.start,
        _ => {
            let end = block.children[index - 1].1.end;
            comma_after(text, end).map_or(end, |c| c + 1)
        }
    };
    spans::skip_blank(text, from)
}

fn comma_after(text: &str, end: usize) -> Option<usize> {
    let at = spans::skip_blank(text, end);
    text[at..].starts_with(',').then_some(at)
}

fn line_start(text: &str, at: usize) -> usize {
    text[..at].rfind('\n').map_or(0, |i| i + 1)
}

fn spliced(text: &str, range: Range<usize>, new: &str) -> String {
    format!("{}{new}{}", &text[..range.start], &text[range.end..])
}

#[cfg(test)]
mod tests;
