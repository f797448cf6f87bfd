//! Every command block of README.md and docs/*.md, run as written: a
//! recipe in the docs is code. Each document's ```sh blocks run in order,
//! in one folder holding copies of timelines/, docs/ and examples/, with
//! the test build as `mandelreel` on PATH; a ```ron block headed
//! `file=NAME` is written to NAME there first, as the reader would.
//!
//! What changes, so the whole docs run in minutes: `cargo run --release --`
//! is the test build; `render`, `accuracy` and `status TIMELINE` run at
//! `SIZE` (pixels, frames, samples and everything else as written);
//! `ffplay FILE` checks that FILE is there to play. Not run: the `cargo`
//! lines (`.ci/run` runs the test command and the install step), and a
//! block after a `<!-- recipe: not run: REASON -->` line, which must say
//! why and where it is run instead.

use crate::util::tool;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// The size renders run at.
const SIZE: &str = "32x18";
/// What one block may take before it counts as hung.
const BLOCK_LIMIT: Duration = Duration::from_secs(600);
const SKIP: &str = "<!-- recipe: not run:";

/// A fenced block of a document, with the line its fence opens on.
#[derive(Debug)]
struct Block {
    info: String,
    line: usize,
    text: String,
    /// The reason given in a `recipe: not run` line just before it.
    skipped: Option<String>,
}

fn blocks(markdown: &str) -> Vec<Block> {
    let mut found = Vec::new();
    let mut open: Option<Block> = None;
    let mut skipped = None;
    for (i, line) in markdown.lines().enumerate() {
        match (&mut open, line.strip_prefix("```")) {
            (None, Some(info)) => {
                open = Some(Block {
                    info: info.trim().to_string(),
                    line: i + 1,
                    text: String::new(),
                    skipped: skipped.take(),
                })
            }
            (Some(_), Some(_)) => found.extend(open.take()),
            (Some(block), None) => {
                block.text.push_str(line);
                block.text.push('\n');
            }
            (None, None) => {
                if let Some(reason) = line.trim().strip_prefix(SKIP) {
                    skipped = Some(reason.trim_end_matches("-->").trim().to_string());
                } else if !line.trim().is_empty() {
                    skipped = None;
                }
            }
        }
    }
    found
}

/// `block`'s lines as the test runs them: continuations joined, each
/// command rewritten (`rewrite`).
fn script(block: &str) -> String {
    block
        .replace("\\\n", " ")
        .lines()
        .map(rewrite)
        .collect::<Vec<_>>()
        .join("\n")
}

/// One command line as the test runs it (see the module's comment). A
/// `mandelreel` line must be one plain command, so that what is changed
/// is that command's size and nothing else.
fn rewrite(line: &str) -> String {
    let line = line.replacen("cargo run --release --", "mandelreel", 1);
    let (command, _comment) = match line.find(" #") {
        Some(at) => line.split_at(at),
        None => (line.as_str(), ""),
    };
    let mut words: Vec<String> = command.split_whitespace().map(String::from).collect();
    match words.first().map(String::as_str) {
        Some("cargo") => return format!(": not run here: {}", command.trim()),
        Some("ffplay") => {
            let file = words.last().cloned().unwrap_or_default();
            return format!("test -s {file} # {}", command.trim());
        }
        Some("mandelreel") => {}
        _ => {
            assert!(
                !words.iter().skip(1).any(|w| w == "mandelreel"),
                "{line:?}: start the line with mandelreel, so its size can be set"
            );
            return line;
        }
    }
    assert!(
        !command.contains(['|', ';', '&', '\'', '"', '`', '$', '<', '>']),
        "{line:?}: a mandelreel line in a recipe is one plain command"
    );
    let timeline = words.get(2).is_some_and(|w| w.ends_with(".ron"));
    let sized = match words.get(1).map(String::as_str) {
        _ if words.iter().any(|w| w == "--help") => false,
        // status of a timeline names the size its render used.
        Some("status") => timeline,
        Some("render") | Some("accuracy") => true,
        _ => false,
    };
    if sized {
        set_option(&mut words, "--size", SIZE);
    }
    words.join(" ")
}

/// `option VALUE` in `words`: replaced where given, else added.
fn set_option(words: &mut Vec<String>, option: &str, value: &str) {
    match words.iter().position(|w| w == option) {
        Some(at) if at + 1 < words.len() => words[at + 1] = value.to_string(),
        _ => words.extend([option.to_string(), value.to_string()]),
    }
}

/// A folder with copies of what the docs' commands read.
fn workspace(repo: &Path) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("temporary folder");
    for folder in ["timelines", "docs", "examples"] {
        let copied = Command::new("cp")
            .arg("-R")
            .arg(repo.join(folder))
            .arg(dir.path())
            .status()
            .expect("run cp");
        assert!(copied.success(), "copying {folder}");
    }
    let bin = dir.path().join(".bin");
    std::fs::create_dir(&bin).unwrap();
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_mandelreel"), bin.join("mandelreel")).unwrap();
    dir
}

/// Runs `script` in `dir` with the test build first on PATH; the output,
/// or what went wrong. Its output is read as it comes (a full pipe would
/// stall it), and a block past `BLOCK_LIMIT` is killed with all it started.
fn run(dir: &Path, script: &str) -> Result<String, String> {
    use std::os::unix::process::CommandExt as _;
    let path = format!(
        "{}:{}",
        dir.join(".bin").display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let mut child = Command::new("bash")
        .args(["-euo", "pipefail", "-c", script])
        .current_dir(dir)
        .env("PATH", path)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .process_group(0)
        .spawn()
        .expect("run bash");
    let read = |pipe: Option<Box<dyn std::io::Read + Send>>| {
        std::thread::spawn(move || {
            let mut text = Vec::new();
            if let Some(mut pipe) = pipe {
                let _ = pipe.read_to_end(&mut text);
            }
            String::from_utf8_lossy(&text).into_owned()
        })
    };
    let out = read(child.stdout.take().map(|p| Box::new(p) as _));
    let err = read(child.stderr.take().map(|p| Box::new(p) as _));
    let started = Instant::now();
    let group = nix::unistd::Pid::from_raw(child.id() as i32);
    let kill_group = || nix::sys::signal::killpg(group, nix::sys::signal::Signal::SIGKILL);
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait for bash") {
            break status;
        }
        if started.elapsed() > BLOCK_LIMIT {
            let _ = kill_group();
            let _ = child.wait();
            return Err(format!("still running after {BLOCK_LIMIT:?}"));
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    // Anything a block left running in the background holds its output
    // open: it goes with the block.
    let _ = kill_group();
    let (out, err) = (out.join().expect("stdout"), err.join().expect("stderr"));
    match status.success() {
        true => Ok(out),
        false => Err(format!("{}\n{}", tail(&out), tail(&err))),
    }
}

/// The last lines of `text`, where a failure shows.
fn tail(text: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(30)..].join("\n")
}

/// Runs every block of the document at `relative` (from the repository's
/// root); returns how many ran.
fn run_document(relative: &str) -> usize {
    let repo = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let markdown = std::fs::read_to_string(repo.join(relative)).expect("read the document");
    let dir = workspace(&repo);
    let mut ran = 0;
    for block in blocks(&markdown) {
        let at = format!("{relative}:{}", block.line);
        if let Some(reason) = &block.skipped {
            assert!(reason.len() > 10, "{at}: say why the block is not run");
            continue;
        }
        if let Some(name) = block.info.strip_prefix("ron file=") {
            std::fs::write(dir.path().join(name.trim()), &block.text).unwrap();
        }
        if block.info != "sh" {
            continue;
        }
        let script = script(&block.text);
        if let Err(problem) = run(dir.path(), &script) {
            panic!("{at}: the block fails as written:\n{script}\n---\n{problem}");
        }
        ran += 1;
    }
    ran
}

/// The real tools the docs' recipes call; absent outside CI, the test
/// skips (`util::tool`).
fn tools_present() -> bool {
    tool("ffmpeg", "-version") && tool("oiiotool", "--version")
}

#[test]
fn readme_recipes_run_as_written() {
    if tools_present() {
        assert!(run_document("README.md") >= 7);
    }
}

#[test]
fn docs_recipes_run_as_written() {
    if !tools_present() {
        return;
    }
    let mut documents: Vec<String> =
        std::fs::read_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/docs"))
            .expect("docs/")
            .map(|e| {
                e.expect("a docs/ entry")
                    .file_name()
                    .to_string_lossy()
                    .into_owned()
            })
            .filter(|name| name.ends_with(".md"))
            .collect();
    documents.sort();
    let ran: usize = documents
        .iter()
        .map(|d| run_document(&format!("docs/{d}")))
        .sum();
    assert!(ran >= 1, "no docs/ recipe ran");
}

#[test]
fn commands_are_rewritten_to_small_sizes_and_nothing_else() {
    assert_eq!(
        rewrite("cargo run --release -- render timelines/zoom.ron   # renders"),
        "mandelreel render timelines/zoom.ron --size 32x18"
    );
    assert_eq!(
        rewrite("mandelreel render t.ron --size 1920x1080 --samples 9 --out o"),
        "mandelreel render t.ron --size 32x18 --samples 9 --out o"
    );
    assert_eq!(
        rewrite("mandelreel status t.ron --frames 0..3"),
        "mandelreel status t.ron --frames 0..3 --size 32x18"
    );
    assert_eq!(
        rewrite("mandelreel status out/zoom"),
        "mandelreel status out/zoom"
    );
    assert_eq!(
        rewrite("mandelreel pick z.ron --pixel 100,60 --aim"),
        "mandelreel pick z.ron --pixel 100,60 --aim"
    );
    assert!(rewrite("cargo test").starts_with(": not run here"));
    assert_eq!(rewrite("  ls out | wc -l"), "  ls out | wc -l");
    assert_eq!(
        rewrite("ffplay -loop 0 a.mp4"),
        "test -s a.mp4 # ffplay -loop 0 a.mp4"
    );
}

#[test]
fn a_block_is_skipped_only_with_a_reason() {
    let text =
        "<!-- recipe: not run: run by .ci/slurm-test -->\n```sh\nsbatch x\n```\n\n```sh\nls\n```\n";
    let found = blocks(text);
    assert_eq!(found.len(), 2);
    assert_eq!(found[0].skipped.as_deref(), Some("run by .ci/slurm-test"));
    assert_eq!(found[1].skipped, None);
    assert_eq!(found[1].line, 6);
}

#[test]
#[should_panic(expected = "one plain command")]
fn a_mandelreel_line_with_a_pipe_is_refused() {
    rewrite("mandelreel render t.ron | tee log");
}

#[test]
#[should_panic(expected = "start the line with mandelreel")]
fn a_mandelreel_command_later_in_a_line_is_refused() {
    rewrite("time mandelreel render t.ron");
}

#[test]
fn a_block_that_fails_or_talks_a_lot_is_told_apart() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join(".bin")).unwrap();
    // More than a pipe holds, then success: not a hang.
    let chatty = run(
        dir.path(),
        "head -c 300000 /dev/zero | tr '\\0' x; echo; echo done >&2",
    );
    assert!(chatty.is_ok_and(|out| out.len() > 300000));
    let background = run(dir.path(), "sleep 600 & echo started");
    assert!(background.is_ok_and(|out| out.contains("started")));
    let failed = run(dir.path(), "echo one; false; echo two").unwrap_err();
    assert!(
        failed.contains("one") && !failed.contains("two"),
        "{failed}"
    );
}
