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
    ("leaves", &["math", "input", "interrupt", "host"]),
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

/// A source file's module path: `src/a/b.rs` and `src/a/b/mod.rs` are
/// `["a", "b"]`.
fn module_path(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).expect("under src");
    let mut path: Vec<String> = rel
        .components()
        .map(|c| {
            c.as_os_str()
                .to_string_lossy()
                .trim_end_matches(".rs")
                .to_string()
        })
        .collect();
    if path.last().is_some_and(|l| l == "mod" || l == "lib") {
        path.pop();
    }
    path
}

/// The module paths `text`, the file of module `own`, names: `crate::a::b`
/// and `super::c` (`super::{c, d}` too), resolved from the crate's root.
fn named_paths(own: &[String], text: &str) -> Vec<Vec<String>> {
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut found = Vec::new();
    // One line of code, so that a `use` group over several lines is whole.
    let code: Vec<&str> = text
        .lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect();
    let code = code.join(" ");
    let line = code.as_str();
    for (i, _) in line.match_indices("crate::") {
        if line[..i]
            .chars()
            .last()
            .is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '$')
        {
            continue;
        }
        let rest = &line[i + 7..];
        found.push(
            rest.split("::")
                .map(ident)
                .take_while(|s| !s.is_empty())
                .collect(),
        );
    }
    for (i, _) in line.match_indices("super::") {
        let before = &line[..i];
        if before.ends_with("super::")
            || before
                .chars()
                .last()
                .is_some_and(|c| c.is_alphanumeric() || c == '_')
        {
            continue; // counted from the first `super` of a chain
        }
        let mut base = own.to_vec();
        let mut rest = &line[i..];
        while let Some(r) = rest.strip_prefix("super::") {
            base.pop();
            rest = r;
        }
        let names: Vec<String> = match rest.strip_prefix('{') {
            Some(group) => group_items(group).iter().map(|s| ident(s.trim())).collect(),
            None => vec![ident(rest)],
        };
        for name in names.into_iter().filter(|n| !n.is_empty()) {
            let mut path = base.clone();
            path.push(name);
            found.push(path);
        }
    }
    found
}

/// The items of a `{…}` group, given its text after the `{`: split at its
/// own commas, up to its own `}`.
fn group_items(group: &str) -> Vec<&str> {
    let (mut depth, mut start, mut items) = (0, 0, Vec::new());
    for (i, c) in group.char_indices() {
        match c {
            '{' => depth += 1,
            '}' if depth == 0 => {
                items.push(&group[start..i]);
                return items;
            }
            '}' => depth -= 1,
            ',' if depth == 0 => {
                items.push(&group[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    items
}

/// The circles among the files of one folder: `(folder, members)` for each
/// set of sibling files that use one another in a ring. A folder's mod.rs
/// (its facade) and its tests stand outside.
fn circles(files: &[(Vec<String>, String)]) -> Vec<(String, Vec<String>)> {
    use std::collections::BTreeMap;
    let mut edges: BTreeMap<Vec<String>, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    for (own, text) in files {
        let named = named_paths(own, text);
        // Every folder this file sits below, with the child it sits in.
        for depth in 0..own.len() {
            let (folder, child) = (&own[..depth], &own[depth]);
            if child == "tests" || own.get(depth + 1).is_some_and(|c| c == "tests") {
                continue;
            }
            let siblings = edges.entry(folder.to_vec()).or_default();
            let out = siblings.entry(child.clone()).or_default();
            for path in &named {
                if path.len() > depth && path[..depth] == *folder && path[depth] != *child {
                    out.insert(path[depth].clone());
                }
            }
        }
    }
    let mut found = Vec::new();
    for (folder, graph) in &edges {
        // Keep only uses of files that are in this folder.
        let reaches = |from: &String| {
            let mut seen = BTreeSet::new();
            let mut stack = vec![from.clone()];
            while let Some(at) = stack.pop() {
                for next in graph.get(&at).into_iter().flatten() {
                    if graph.contains_key(next) && seen.insert(next.clone()) {
                        stack.push(next.clone());
                    }
                }
            }
            seen
        };
        let mut ring: Vec<String> = graph
            .keys()
            .filter(|k| reaches(k).contains(*k))
            .cloned()
            .collect();
        ring.retain(|k| k != "tests");
        if !ring.is_empty() {
            found.push((folder.join("/"), ring));
        }
    }
    found
}

#[test]
fn the_files_of_a_folder_use_one_another_one_way() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut paths = Vec::new();
    sources(&src, &mut paths);
    let files: Vec<(Vec<String>, String)> = paths
        .iter()
        .map(|p| {
            (
                module_path(&src, p),
                std::fs::read_to_string(p).expect("read source"),
            )
        })
        .collect();
    let found = circles(&files);
    assert!(
        found.is_empty(),
        "files in a circle (folder: files): {found:?}"
    );
}

#[test]
fn a_circle_between_two_files_is_found() {
    let file = |path: &str, text: &str| {
        let path = path.split('/').map(String::from).collect::<Vec<_>>();
        (path, text.to_string())
    };
    let ring = [
        file("render/band", "use super::film::Film;"),
        file("render/film", "use crate::render::band::BAND_ROWS;"),
        file("render", "mod band;\nmod film;\nuse band::x;"),
    ];
    assert_eq!(
        circles(&ring),
        [(
            "render".to_string(),
            vec!["band".to_string(), "film".to_string()]
        )]
    );
    let one_way = [
        file("render/band", "use super::{film::Film, rows};"),
        file("render/film", "use super::rows::BAND_ROWS;"),
        file("render/rows", "// use super::band in a comment"),
        file("fractal/deep/lanes", "use super::super::orbit::Orbit;"),
        file("fractal/orbit", "use super::power::x;"),
    ];
    assert!(circles(&one_way).is_empty());
    // A group over several lines, with groups inside it.
    let split = [
        file(
            "bench/run",
            "use super::{\n    rows::{pool_rows, Row},\n    ceiling,\n};",
        ),
        file(
            "bench/ceiling",
            "fn f(o: &super::run::Options) {}\nlet x = [1, 2];",
        ),
        file("bench/rows", "fn g() {}"),
    ];
    assert_eq!(
        circles(&split),
        [(
            "bench".to_string(),
            vec!["ceiling".to_string(), "run".to_string()]
        )]
    );
    let deep = [
        file("fractal/deep/lanes", "use super::super::orbit::Orbit;"),
        file("fractal/orbit", "fn f() -> super::deep::Derivative {}"),
    ];
    assert_eq!(
        circles(&deep),
        [(
            "fractal".to_string(),
            vec!["deep".to_string(), "orbit".to_string()]
        )]
    );
}
