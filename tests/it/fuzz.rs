//! Fuzzing of timeline reading, parsing and validation, in process
//! (`Timeline::load`): every input, valid or not, gets its answer, a
//! timeline or an error pointing into the file, without a panic, within
//! `DEADLINE` and `guard::MAX_LIVE_BYTES`. The inputs are the example
//! timelines and docs/timeline.md's reference one, and timelines written from a
//! grammar of the schema (`grammar`), broken by `mutate`'s edits.
//!
//! `cargo test` runs `CASES` cases a property from a fixed seed, so CI is
//! repeatable; docs/development.md says how to run longer.

mod grammar;
mod guard;
mod mutate;

use guard::Outcome;
use mandelreel::error::Error;
use mandelreel::timeline::{validate_scene, Timeline};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestError, TestRunner};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// Cases a property in `cargo test`, a few seconds on two cores;
/// `PROPTEST_CASES` overrides it.
const CASES: u32 = 1000;

/// The seed of `cargo test`'s cases; `PROPTEST_RNG_SEED` overrides it.
const SEED: u64 = 21;

/// Longer than any answer takes (milliseconds), short enough for a hang
/// to fail the test quickly.
const DEADLINE: Duration = Duration::from_secs(5);

fn config() -> Config {
    let given = |name: &str| std::env::var_os(name).is_some();
    // The default reads every PROPTEST_ variable.
    let mut config = Config::default();
    if !given("PROPTEST_CASES") {
        config.cases = CASES;
    }
    if !given("PROPTEST_RNG_SEED") {
        config.rng_seed = RngSeed::Fixed(SEED);
    }
    if !given("PROPTEST_MAX_SHRINK_TIME") {
        // Each step of shrinking a hang takes the whole deadline.
        config.max_shrink_time = 60_000;
    }
    // A failure prints its smallest input; no regression files in the tree.
    config.failure_persistence = None;
    config
}

/// A folder with the files a timeline's environment map may name
/// (`grammar::MAP_PATHS`), where each case's timeline is written. It is in
/// target/tmp, so a crash that ends the test process (a stack overflow)
/// leaves its input there.
struct Fixtures {
    dir: tempfile::TempDir,
}

impl Fixtures {
    fn new() -> Fixtures {
        let dir = tempfile::Builder::new()
            .prefix("fuzz-")
            .tempdir_in(env!("CARGO_TARGET_TMPDIR"))
            .expect("temporary folder");
        let at = |name: &str| dir.path().join(name);
        write_sky(&at("sky.exr"));
        std::fs::write(at("empty.exr"), b"").expect("write fixture");
        std::fs::write(at("junk.exr"), b"v/1\x01 not an EXR file").expect("write fixture");
        std::fs::write(at("junk.hdr"), b"#?RADIANCE\nnonsense\n").expect("write fixture");
        std::fs::write(at("liar.exr"), lying_exr(1 << 28, 1)).expect("write fixture");
        let hdr = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4000 +X 8000\n";
        std::fs::write(at("liar.hdr"), hdr).expect("write fixture");
        std::fs::create_dir(at("folder")).expect("make fixture folder");
        let made = std::process::Command::new("mkfifo")
            .arg(at("fifo"))
            .status();
        assert!(
            made.as_ref().is_ok_and(|s| s.success()),
            "mkfifo failed: {made:?}"
        );
        Fixtures { dir }
    }

    /// Loads `bytes` as a timeline under the guard; the problem, if any.
    fn check(&self, bytes: &[u8]) -> Result<(), String> {
        let path = self.dir.path().join("timeline.ron");
        std::fs::write(&path, bytes).expect("write the case");
        let lines = bytes.iter().filter(|&&b| b == b'\n').count() + 1;
        let case = path.clone();
        let judged = judge(guard::run(DEADLINE, move || answer(&case, lines)));
        // Removed, not overwritten: ext4 flushes a file truncated and
        // written again on close, a few milliseconds each.
        let _ = std::fs::remove_file(&path);
        judged
    }
}

/// A case's outcome as the property sees it.
fn judge(outcome: Outcome<Result<(), String>>) -> Result<(), String> {
    match outcome {
        Outcome::Returned(answer) => answer,
        Outcome::Panicked(message) => Err(format!("panicked: {message}")),
        Outcome::Hung(after) => Err(format!("no answer after {after:.1?}")),
        Outcome::OverBudget(live) => Err(format!(
            "asked for more than {} bytes at once ({live} with its last request)",
            guard::MAX_LIVE_BYTES
        )),
    }
}

/// Loads the timeline; checks what a valid one promises, or that an error
/// points inside the file (`lines` long).
fn answer(path: &Path, lines: usize) -> Result<(), String> {
    match Timeline::load(path) {
        Ok(timeline) => use_timeline(&timeline),
        Err(e) => error_points_inside(&e, lines),
    }
}

/// A valid timeline's frames are scenes that pass validation: its first,
/// middle and last, every sample's instant of them included.
fn use_timeline(t: &Timeline) -> Result<(), String> {
    let last = t.frame_count - 1;
    for frame in [0, last / 2, last] {
        let _ = t.scene_at(frame);
        for scene in t.scenes_for_frame(frame) {
            validate_scene(&scene).map_err(|(field, message)| {
                format!("frame {frame} of a valid timeline fails validation: {field}: {message}")
            })?;
        }
    }
    Ok(())
}

fn error_points_inside(e: &Error, lines: usize) -> Result<(), String> {
    let shown = e.to_string();
    let line = match e {
        Error::Syntax { column: 0, .. } => {
            return Err(format!("column 0 (columns count from 1): {shown}"))
        }
        Error::Syntax { line, .. } => Some(*line),
        Error::Invalid { place: None, .. } => return Err(format!("no line: {shown}")),
        Error::Invalid {
            place: Some(at), ..
        } => Some(at.line),
        _ => return Err(format!("not a timeline error: {shown}")),
    };
    match line {
        Some(l) if l == 0 || l > lines => {
            Err(format!("line {l} of a file of {lines} lines: {shown}"))
        }
        _ => Ok(()),
    }
}

/// Runs `strategy`'s cases through `check`; on a failure, panics with its
/// smallest input (`report`).
fn fuzz(name: &str, strategy: impl Strategy<Value = Vec<u8>>) {
    let fixtures = Fixtures::new();
    let mut runner = TestRunner::new(config());
    let result = runner.run(&strategy, |bytes| {
        fixtures.check(&bytes).map_err(TestCaseError::fail)
    });
    match result {
        Ok(()) => {}
        Err(TestError::Fail(reason, bytes)) => panic!("{}", report(name, reason.message(), &bytes)),
        Err(TestError::Abort(reason)) => panic!("{name}: aborted: {reason}"),
    }
}

/// The failure and its input: saved whole in target/tmp, shown up to a
/// few thousand characters.
fn report(name: &str, reason: &str, bytes: &[u8]) -> String {
    const SHOWN: usize = 4000;
    let file = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("{name}.ron"));
    let saved = std::fs::write(&file, bytes).map_or_else(
        |e| format!("could not be saved to {}: {e}", file.display()),
        |()| format!("is in {}", file.display()),
    );
    let text = String::from_utf8_lossy(bytes);
    let cut = text
        .char_indices()
        .nth(SHOWN)
        .map_or(text.len(), |(i, _)| i);
    let more = if cut < text.len() { "\n…" } else { "" };
    format!(
        "{name}: {reason}\nthe smallest input ({} bytes) {saved}:\n{}{more}",
        bytes.len(),
        visible(&text[..cut])
    )
}

/// `text` with control and invisible formatting characters escaped (a
/// carriage return or a right-to-left mark would garble the report).
fn visible(text: &str) -> String {
    let hidden = |c: char| {
        (c.is_control() && c != '\n' && c != '\t')
            || matches!(c, '\u{200b}'..='\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}' | '\u{feff}')
    };
    text.chars()
        .map(|c| match hidden(c) {
            true => c.escape_unicode().to_string(),
            false => c.to_string(),
        })
        .collect()
}

/// The example timelines and docs/timeline.md's reference timeline, by name.
fn seeds() -> Vec<(String, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut seeds = Vec::new();
    for folder in ["timelines", "timelines/bench"] {
        let mut files: Vec<PathBuf> = std::fs::read_dir(root.join(folder))
            .expect("read the example folder")
            .map(|entry| entry.expect("list the example folder").path())
            .filter(|p| p.extension().is_some_and(|e| e == "ron"))
            .collect();
        files.sort();
        for file in files {
            let text = std::fs::read_to_string(&file).expect("read an example");
            seeds.push((file.display().to_string(), text));
        }
    }
    seeds.push((
        "docs/timeline.md's reference timeline".into(),
        readme_timeline(),
    ));
    seeds
}

/// The first RON block of docs/timeline.md's "Timeline format" section.
fn readme_timeline() -> String {
    let readme = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/timeline.md"))
        .expect("read docs/timeline.md");
    let section = &readme[readme
        .find("# Timeline format")
        .expect("the timeline reference's section")..];
    let block = &section[section.find("```ron\n").expect("a RON block") + 7..];
    block[..block.find("```").expect("the block's end")].to_string()
}

/// Writes a small equirectangular EXR map.
fn write_sky(path: &Path) {
    use exr::prelude::*;
    write_rgba_file(path, 8, 4, |x, y| {
        (0.1 * x as f32, 0.2 * y as f32, 0.3, 1.0)
    })
    .expect("write the sky fixture");
}

/// An uncompressed scan-line EXR whose header claims `width`×`height`
/// pixels while the file holds one offset and no pixels.
fn lying_exr(width: i32, height: i32) -> Vec<u8> {
    let mut out = vec![0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0];
    let mut attribute = |name: &str, kind: &str, value: &[u8]| {
        for s in [name, kind] {
            out.extend(s.bytes());
            out.push(0);
        }
        out.extend((value.len() as i32).to_le_bytes());
        out.extend(value);
    };
    let mut channels = Vec::new();
    for name in ["B", "G", "R"] {
        channels.extend([name.as_bytes()[0], 0]);
        // FLOAT, linear 0, three reserved bytes, sampling 1 × 1.
        channels.extend(2i32.to_le_bytes());
        channels.extend([0, 0, 0, 0]);
        channels.extend(1i32.to_le_bytes());
        channels.extend(1i32.to_le_bytes());
    }
    channels.push(0);
    let window: Vec<u8> = [0, 0, width - 1, height - 1]
        .iter()
        .flat_map(|v: &i32| v.to_le_bytes())
        .collect();
    attribute("channels", "chlist", &channels);
    attribute("compression", "compression", &[0]);
    attribute("dataWindow", "box2i", &window);
    attribute("displayWindow", "box2i", &window);
    attribute("lineOrder", "lineOrder", &[0]);
    attribute("pixelAspectRatio", "float", &1f32.to_le_bytes());
    attribute("screenWindowCenter", "v2f", &[0; 8]);
    attribute("screenWindowWidth", "float", &1f32.to_le_bytes());
    out.push(0);
    let table_end = out.len() as u64 + 8 * height as u64;
    for _ in 0..height {
        out.extend(table_end.to_le_bytes());
    }
    out
}

#[test]
fn the_examples_and_the_readme_timeline_are_valid() {
    let fixtures = Fixtures::new();
    for (name, text) in seeds() {
        let path = fixtures.dir.path().join("example.ron");
        let parse = move || {
            Timeline::parse(&text, &path)
                .map(drop)
                .map_err(|e| e.to_string())
        };
        if let Err(problem) = judge(guard::run(DEADLINE, parse)) {
            panic!("{name}: {problem}");
        }
    }
}

#[test]
fn broken_examples_get_an_answer() {
    let seeds = seeds();
    let words = grammar::schema_words();
    let count = seeds.len();
    let edits = (
        0..count,
        proptest::collection::vec(mutate::token_edit(words.len()), 0..4),
        proptest::collection::vec(mutate::byte_edit(), 0..3),
    );
    let strategy = edits.prop_map(move |(seed, tokens, bytes)| {
        let mut text = seeds[seed].1.clone();
        for edit in tokens {
            edit.apply(&mut text, &words);
        }
        let mut text = text.into_bytes();
        for edit in bytes {
            edit.apply(&mut text);
        }
        text
    });
    fuzz("broken_examples", strategy);
}

#[test]
fn timelines_from_the_grammar_get_an_answer() {
    let edits = (
        grammar::timeline(),
        proptest::collection::vec(mutate::tree_edit(), 0..4),
        proptest::collection::vec(mutate::byte_edit(), 0..2),
    );
    let strategy = edits.prop_map(|(mut tree, tree_edits, byte_edits)| {
        for edit in tree_edits {
            edit.apply(&mut tree);
        }
        let mut text = tree.text().into_bytes();
        for edit in byte_edits {
            edit.apply(&mut text);
        }
        text
    });
    fuzz("grammar_timelines", strategy);
}

/// Every prefix of every example, cut at each character: one guarded
/// thread a seed, which says how far it got.
#[test]
fn every_truncation_of_the_examples_gets_an_answer() {
    let fixtures = Fixtures::new();
    for (name, text) in seeds() {
        let path = fixtures.dir.path().join("cut.ron");
        let reached = Arc::new(AtomicUsize::new(0));
        let progress = reached.clone();
        let cut_all = move || {
            let mut lines = 1;
            let ends = text.char_indices().map(|(i, c)| (i, Some(c)));
            for (cut, next) in ends.chain([(text.len(), None)]) {
                progress.store(cut, Ordering::Relaxed);
                let answer =
                    std::panic::catch_unwind(|| match Timeline::parse(&text[..cut], &path) {
                        Ok(t) => use_timeline(&t),
                        Err(e) => error_points_inside(&e, lines),
                    });
                match answer {
                    Ok(Ok(())) => {}
                    Ok(Err(problem)) => return Err(problem),
                    Err(_) => return Err("panicked (message above)".into()),
                }
                lines += usize::from(next == Some('\n'));
            }
            Ok(())
        };
        let outcome = guard::run(DEADLINE * 10, cut_all);
        let at = reached.load(Ordering::Relaxed);
        if let Err(problem) = judge(outcome) {
            panic!("{name}, cut at byte {at}: {problem}");
        }
    }
}

/// A path-traced still whose sky is the environment map at `path`.
fn sky_timeline(path: &str) -> String {
    format!(
        "(fps: 24, frames: 1, size: (8, 8), scene: (effects: (path_tracing: \
         (sky: Environment(path: \"{path}\", rotation_degrees: 30)))))"
    )
}

#[test]
fn every_kind_of_environment_map_path_gets_an_answer() {
    let fixtures = Fixtures::new();
    let absolute = fixtures.dir.path().join("sky.exr");
    let mut paths: Vec<String> = grammar::MAP_PATHS.iter().map(|p| p.to_string()).collect();
    paths.push(absolute.display().to_string());
    paths.push("folder/../sky.exr".into());
    // The good map is a good map: the harness sees the path that succeeds.
    let good = fixtures.dir.path().join("good.ron");
    std::fs::write(&good, sky_timeline("sky.exr")).expect("write a timeline");
    assert!(Timeline::load(&good).is_ok());
    let mut failures = Vec::new();
    for path in paths {
        if let Err(problem) = fixtures.check(sky_timeline(&path).as_bytes()) {
            failures.push(format!("{path:?}: {problem}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Inputs that would make loading walk billions of frames or read
/// forever, each spelled out: a frame count or duration that makes
/// validation walk millions of frames, and an environment map that never
/// ends (`/dev/zero`, `/dev/urandom`, a FIFO).
#[test]
fn the_known_endless_inputs_get_an_answer() {
    let fixtures = Fixtures::new();
    let still = |fields: &str| format!("(fps: 24, size: (8, 8), {fields})");
    let inputs = [
        still("frames: 4000000000"),
        still("frames: 4294967295"),
        still("duration_seconds: 100000000"),
        still("frames: 1000000, scene: (samples_per_pixel: 4096, effects: (motion_blur: ()))"),
        sky_timeline("/dev/zero"),
        sky_timeline("/dev/urandom"),
        sky_timeline("fifo"),
    ];
    let mut failures = Vec::new();
    for text in inputs {
        if let Err(problem) = fixtures.check(text.as_bytes()) {
            failures.push(format!("{text}\n    {problem}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
