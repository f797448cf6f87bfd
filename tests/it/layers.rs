//! The module dependency direction: each module of src/ uses only modules of
//! lower layers, and docs/architecture.md draws the layers this test holds.

use std::collections::BTreeSet;
use std::path::Path;

/// The layers, top first: a module may use modules of any later layer,
/// never one of its own layer or above.
const LAYERS: &[(&str, &[&str])] = &[
    ("commands", &["cli"]),
    ("explorer", &["explore"]),
    ("benchmark", &["bench"]),
    ("accuracy", &["accuracy"]),
    ("quality", &["quality"]),
    ("job", &["job"]),
    ("files", &["output"]),
    ("film", &["timeline", "render"]),
    ("deep frames", &["deep"]),
    ("scene", &["scene"]),
    ("shading", &["shade"]),
    ("camera", &["camera"]),
    ("march", &["march"]),
    ("fractal", &["fractal"]),
    ("light", &["color", "environment"]),
    ("errors", &["error"]),
    ("digits", &["exact"]),
    ("leaves", &["math", "spans", "input", "interrupt", "host"]),
];

fn rank(module: &str) -> Option<usize> {
    LAYERS.iter().position(|(_, ms)| ms.contains(&module))
}

/// Every `crate::name` a file's code names, comments left out.
fn uses(text: &str) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    for line in text.lines().filter(|l| !l.trim_start().starts_with("//")) {
        for (i, _) in line.match_indices("crate::") {
            let before = line[..i].chars().last();
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '$') {
                continue; // `$crate::` or an identifier ending in "crate"
            }
            let rest = &line[i + 7..];
            // A grouped `crate::{…}` hides its modules from this scan.
            assert!(!rest.starts_with('{'), "write one path per use: {line}");
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            found.insert(name);
        }
    }
    found
}

fn sources(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("read src") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The top-level module a source file belongs to (`src/job/plan.rs` → job).
fn module_of(src: &Path, file: &Path) -> Option<String> {
    let first = file.strip_prefix(src).ok()?.components().next()?;
    let name = first.as_os_str().to_str()?.trim_end_matches(".rs");
    (!matches!(name, "lib" | "main")).then(|| name.to_string())
}

/// The modules `text`, a file of `module`, uses against the layers.
fn uses_upwards(module: &str, text: &str) -> Vec<String> {
    let own = rank(module).unwrap_or_else(|| panic!("{module} is in no layer of LAYERS"));
    uses(text)
        .into_iter()
        // Unranked names are macros or items of lib.rs.
        .filter(|used| used != module && rank(used).is_some_and(|theirs| theirs <= own))
        .collect()
}

#[test]
fn every_module_uses_only_the_layers_below_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    let mut wrong = Vec::new();
    for file in &files {
        let Some(module) = module_of(&src, file) else {
            continue;
        };
        let text = std::fs::read_to_string(file).expect("read source");
        for used in uses_upwards(&module, &text) {
            wrong.push(format!("{} uses {used}", file.display()));
        }
    }
    assert!(
        wrong.is_empty(),
        "uses against the layers:\n{}",
        wrong.join("\n")
    );
}

/// The diagram docs/architecture.md shows, one layer a line, top first.
fn diagram() -> String {
    let lines: Vec<String> = LAYERS
        .iter()
        .map(|(name, modules)| format!("{name:<12} {}", modules.join(", ")))
        .collect();
    format!("```text\n{}\n```", lines.join("\n"))
}

#[test]
fn the_architecture_page_draws_the_layers_the_code_keeps() {
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/architecture.md"))
        .expect("read docs/architecture.md");
    let block = doc
        .split("<!-- layers:begin -->")
        .nth(1)
        .and_then(|rest| rest.split("<!-- layers:end -->").next())
        .expect("docs/architecture.md marks its layers");
    assert_eq!(
        block.trim(),
        diagram(),
        "docs/architecture.md's layers differ; expected:\n{}",
        diagram()
    );
}

#[test]
fn a_use_of_a_higher_layer_is_found() {
    let found = uses("use crate::render::Film;\n// crate::cli in a comment\nlet x = $crate::y;");
    assert_eq!(found, BTreeSet::from(["render".to_string()]));
    assert!(rank("cli") < rank("render") && rank("timeline") == rank("render"));
    let text = "use crate::math::Real;\nfn f() { crate::cli::run(); crate::timeline::x(); }";
    assert_eq!(uses_upwards("render", text), ["cli", "timeline"]);
    assert!(uses_upwards("cli", text).is_empty());
}
