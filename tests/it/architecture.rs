//! The architecture test, as rust-analyzer keeps its tidy tests: it reads the
//! imports of every file under `src/` as text and holds them against the
//! layers ARCHITECTURE.md lists (between its `<!-- layers -->` markers).
//!
//! Two rules (ARCHITECTURE.md, "Layers"):
//! - a stage (a top-level module of `src/`) imports only from a stage on a
//!   lower layer: never from a peer on its own layer, never from above;
//! - inside a stage, no files import each other, in a pair or a longer
//!   circle (a parent `mod.rs` and its own children are one unit: Rust's
//!   `pub use` of a child and a child's `use super::Type` are not a circle).
//!
//! Test code is exempt (`tests.rs` files and each item under `#[cfg(test)]`),
//! and so are comments. The checker works on text in memory, so the tests
//! below also show that it fails on an upward import and on a pair of files
//! that import each other.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A module's path from the crate root: `src/diagnose/fit.rs` is
/// `["diagnose", "fit"]`, `src/diagnose/mod.rs` is `["diagnose"]`.
type ModulePath = Vec<String>;

/// The layer of each stage, from ARCHITECTURE.md.
fn layers_from(markdown: &str) -> Result<BTreeMap<String, usize>, String> {
    let start = markdown
        .find("<!-- layers -->")
        .ok_or("ARCHITECTURE.md has no <!-- layers --> marker")?;
    let end = markdown
        .find("<!-- /layers -->")
        .ok_or("ARCHITECTURE.md has no <!-- /layers --> marker")?;
    let mut layers = BTreeMap::new();
    for line in markdown[start..end].lines() {
        // `- 3: `cycle`, `spline`, `read`: …`
        let Some(rest) = line.trim().strip_prefix("- ") else {
            continue;
        };
        let Some((number, stages)) = rest.split_once(':') else {
            continue;
        };
        let Ok(layer) = number.trim().parse::<usize>() else {
            continue;
        };
        let stages = stages.split(':').next().unwrap_or_default();
        for stage in stages.split(',') {
            let name = stage.trim().trim_matches('`');
            if !name.is_empty() && layers.insert(name.to_string(), layer).is_some() {
                return Err(format!("ARCHITECTURE.md lists `{name}` on two layers"));
            }
        }
    }
    if layers.is_empty() {
        return Err("ARCHITECTURE.md's layers list no stage".to_string());
    }
    Ok(layers)
}

fn module_path(relative: &Path) -> ModulePath {
    let mut parts: Vec<String> = relative
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    let file = parts.pop().unwrap_or_default();
    let stem = file.trim_end_matches(".rs");
    if !matches!(stem, "mod" | "lib" | "main") {
        parts.push(stem.to_string());
    }
    parts
}

/// The code of a file without comments and without its tests: the item
/// after each `#[cfg(test)]` (a `mod tests;` line, or an item up to the `}`
/// that closes it) is left out, and reading goes on after it.
fn code_of(text: &str) -> String {
    let mut code = String::new();
    let mut test_item: Option<TestItem> = None;
    for line in text.lines() {
        let trimmed = line.trim_start();
        if trimmed.starts_with("//") {
            continue;
        }
        let line = line.split(" //").next().unwrap_or_default();
        if let Some(item) = &mut test_item {
            if item.ends_with(line) {
                test_item = None;
            }
            continue;
        }
        if trimmed.starts_with("#[cfg(test)]") {
            test_item = Some(TestItem::default());
            continue;
        }
        code.push_str(line);
        code.push('\n');
    }
    code
}

/// Where a `#[cfg(test)]` item ends: its braces balanced once opened, or a
/// `;` before any brace (`mod tests;`, `use …;`). Braces in strings are
/// counted too, which test code rarely has unbalanced.
#[derive(Default)]
struct TestItem {
    depth: usize,
    opened: bool,
}

impl TestItem {
    /// Takes the next line of the item; true when the item ends on it.
    fn ends_with(&mut self, line: &str) -> bool {
        let trimmed = line.trim_start();
        if !self.opened && trimmed.starts_with("#[") {
            return false;
        }
        for c in line.chars() {
            match c {
                '{' => {
                    self.depth += 1;
                    self.opened = true;
                }
                '}' => self.depth = self.depth.saturating_sub(1),
                ';' if !self.opened => return true,
                _ => {}
            }
        }
        self.opened && self.depth == 0
    }
}

/// Every path the code names from `crate::`, `super::` or `self::`, as
/// absolute paths, with `use` groups (`use crate::{a::B, c::{d, e}}`) expanded.
fn named_paths(module: &[String], code: &str) -> Vec<ModulePath> {
    let mut paths = Vec::new();
    let chars: Vec<char> = code.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let starts_word = i == 0 || !is_ident(chars[i - 1]) && chars[i - 1] != ':';
        let rest: String = chars[i..chars.len().min(i + 7)].iter().collect();
        let root = ["crate::", "super::", "self::"]
            .into_iter()
            .find(|r| rest.starts_with(r));
        match root {
            Some(root) if starts_word => {
                let (tree, next) = parse_tree(&chars, i + root.len());
                let base = match root {
                    "crate::" => Vec::new(),
                    // `super` of `a/b.rs` (module `a::b`) is `a`; of
                    // `a/mod.rs` (module `a`) it is the root.
                    "super::" => module[..module.len().saturating_sub(1)].to_vec(),
                    _ => module.to_vec(),
                };
                for tail in tree {
                    let mut path = base.clone();
                    path.extend(tail);
                    paths.push(path);
                }
                i = next;
            }
            _ => i += 1,
        }
    }
    paths
}

fn is_ident(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// Parses `a::b::{c, d::{e}}` from `at`; returns the paths and where it ended.
fn parse_tree(chars: &[char], mut at: usize) -> (Vec<Vec<String>>, usize) {
    let mut prefix = Vec::new();
    loop {
        while chars.get(at).is_some_and(|c| c.is_whitespace()) {
            at += 1;
        }
        if chars.get(at) == Some(&'{') {
            let mut paths = Vec::new();
            at += 1;
            loop {
                while chars
                    .get(at)
                    .is_some_and(|c| c.is_whitespace() || *c == ',')
                {
                    at += 1;
                }
                match chars.get(at) {
                    None => return (paths, at),
                    Some('}') => return (paths, at + 1),
                    _ => {}
                }
                let (inner, next) = parse_tree(chars, at);
                if next == at {
                    at += 1;
                    continue;
                }
                for tail in inner {
                    let mut path = prefix.clone();
                    path.extend(tail);
                    paths.push(path);
                }
                at = next;
            }
        }
        let start = at;
        while chars.get(at).is_some_and(|c| is_ident(*c)) {
            at += 1;
        }
        if at == start {
            return (vec![prefix], at);
        }
        prefix.push(chars[start..at].iter().collect());
        if chars.get(at) == Some(&':') && chars.get(at + 1) == Some(&':') {
            at += 2;
        } else {
            return (vec![prefix], at);
        }
    }
}

/// The longest prefix of `path` that is a module of the tree.
fn resolve(path: &[String], modules: &BTreeSet<ModulePath>) -> Option<ModulePath> {
    (1..=path.len())
        .rev()
        .map(|n| path[..n].to_vec())
        .find(|prefix| modules.contains(prefix))
}

/// What breaks the rules in a tree of `(path under src/, text)`.
fn violations(layers: &BTreeMap<String, usize>, files: &[(PathBuf, String)]) -> Vec<String> {
    let modules: BTreeSet<ModulePath> = files.iter().map(|(p, _)| module_path(p)).collect();
    let mut found = Vec::new();
    let mut edges: BTreeMap<ModulePath, BTreeSet<ModulePath>> = BTreeMap::new();
    let mut file_of: BTreeMap<ModulePath, String> = BTreeMap::new();
    for (path, text) in files {
        let module = module_path(path);
        file_of.insert(module.clone(), format!("src/{}", path.display()));
        if path.file_name().is_some_and(|n| n == "tests.rs") || module.is_empty() {
            continue;
        }
        let stage = &module[0];
        let Some(&layer) = layers.get(stage) else {
            found.push(format!(
                "src/{}: stage `{stage}` is on no layer of ARCHITECTURE.md",
                path.display()
            ));
            continue;
        };
        for named in named_paths(&module, &code_of(text)) {
            let Some(target) = resolve(&named, &modules) else {
                continue;
            };
            if target.is_empty() || target == module {
                continue;
            }
            let other = &target[0];
            if other != stage {
                match layers.get(other) {
                    Some(&l) if l < layer => {}
                    Some(&l) => found.push(format!(
                        "src/{}: `{stage}` (layer {layer}) imports crate::{} (layer {l}): a dependency that does not point down",
                        path.display(),
                        named.join("::")
                    )),
                    None => {}
                }
                continue;
            }
            // Inside a stage: a parent and its descendants are one unit.
            let related = target.starts_with(&module) || module.starts_with(&target);
            if !related {
                edges.entry(module.clone()).or_default().insert(target);
            }
        }
    }
    for circle in circles(&edges) {
        let names: Vec<&str> = circle.iter().map(|m| file_of[m].as_str()).collect();
        found.push(format!("files import each other: {}", names.join(" → ")));
    }
    found.sort();
    found.dedup();
    found
}

/// The circles of a directed graph: strongly connected parts with more than
/// one node (Tarjan).
fn circles(edges: &BTreeMap<ModulePath, BTreeSet<ModulePath>>) -> Vec<Vec<ModulePath>> {
    struct State<'a> {
        edges: &'a BTreeMap<ModulePath, BTreeSet<ModulePath>>,
        index: BTreeMap<&'a ModulePath, usize>,
        low: BTreeMap<&'a ModulePath, usize>,
        stack: Vec<&'a ModulePath>,
        on_stack: BTreeSet<&'a ModulePath>,
        found: Vec<Vec<ModulePath>>,
    }
    fn visit<'a>(s: &mut State<'a>, node: &'a ModulePath) {
        let n = s.index.len();
        s.index.insert(node, n);
        s.low.insert(node, n);
        s.stack.push(node);
        s.on_stack.insert(node);
        for next in s.edges.get(node).into_iter().flatten() {
            if !s.index.contains_key(next) {
                visit(s, next);
                let low = s.low[node].min(s.low[next]);
                s.low.insert(node, low);
            } else if s.on_stack.contains(next) {
                let low = s.low[node].min(s.index[next]);
                s.low.insert(node, low);
            }
        }
        if s.low[node] == s.index[node] {
            let mut part = Vec::new();
            while let Some(top) = s.stack.pop() {
                s.on_stack.remove(top);
                part.push(top.clone());
                if top == node {
                    break;
                }
            }
            if part.len() > 1 {
                part.sort();
                s.found.push(part);
            }
        }
    }
    let mut state = State {
        edges,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        found: Vec::new(),
    };
    for node in edges.keys() {
        if !state.index.contains_key(node) {
            visit(&mut state, node);
        }
    }
    state.found
}

fn source_tree() -> Vec<(PathBuf, String)> {
    fn walk(dir: &Path, root: &Path, files: &mut Vec<(PathBuf, String)>) {
        let mut entries: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        entries.sort();
        for path in entries {
            if path.is_dir() {
                walk(&path, root, files);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let text = std::fs::read_to_string(&path).unwrap();
                files.push((path.strip_prefix(root).unwrap().to_path_buf(), text));
            }
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    walk(&root, &root, &mut files);
    files
}

fn real_layers() -> BTreeMap<String, usize> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("ARCHITECTURE.md");
    layers_from(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn every_dependency_points_down_and_no_files_import_each_other() {
    let found = violations(&real_layers(), &source_tree());
    assert!(found.is_empty(), "\n{}", found.join("\n"));
}

#[test]
fn an_upward_import_added_to_the_real_tree_is_caught() {
    let before = violations(&real_layers(), &source_tree());
    let mut files = source_tree();
    let units = files
        .iter_mut()
        .find(|(p, _)| p == Path::new("units.rs"))
        .unwrap();
    units.1.insert_str(0, "use crate::report::acceptance;\n");
    let after = violations(&real_layers(), &files);
    let added: Vec<&String> = after.iter().filter(|v| !before.contains(v)).collect();
    let report = real_layers()["report"];
    let expected = format!(
        "src/units.rs: `units` (layer 0) imports crate::report::acceptance (layer {report}): a dependency that does not point down"
    );
    assert_eq!(added, [&expected]);
}

/// The inputs of a step that only `src/workflow/` puts together, so that the
/// CLI, the web app and the demo cannot each assemble a step their own way.
const WORKFLOW_ONLY: [&str; 2] = ["DiagnoseInput", "ReportInput"];

/// Where a file outside `src/workflow/` builds one of [`WORKFLOW_ONLY`] as a
/// struct literal (`DiagnoseInput {`), test code and comments aside.
fn assembled_outside_the_workflow(files: &[(PathBuf, String)]) -> Vec<String> {
    let mut found = Vec::new();
    for (path, text) in files {
        if path.starts_with("workflow") {
            continue;
        }
        let code = code_of(text);
        for name in WORKFLOW_ONLY {
            let literal = format!("{name} {{");
            if code.contains(&literal) {
                found.push(format!(
                    "src/{}: builds a {name}; only src/workflow/ does (ARCHITECTURE.md, front ends thin over workflow)",
                    path.display()
                ));
            }
        }
    }
    found
}

#[test]
fn only_the_workflow_assembles_a_diagnosis_or_a_report() {
    let found = assembled_outside_the_workflow(&source_tree());
    assert!(found.is_empty(), "\n{}", found.join("\n"));
}

#[test]
fn a_report_assembled_in_the_web_app_is_caught() {
    let files = tree(&[
        (
            "serve/steps.rs",
            "fn f() { let input = ReportInput {\n before, after: None };\n}\n// ReportInput { in a comment }",
        ),
        (
            "workflow/report.rs",
            "fn input() { ReportInput { before } }",
        ),
        ("report/acceptance.rs", "pub struct ReportInput<'a> {\n}"),
        (
            "cli/diagnose.rs",
            "#[cfg(test)]\nmod tests {\n fn t() { let _ = DiagnoseInput { after }; }\n}",
        ),
    ]);
    assert_eq!(
        assembled_outside_the_workflow(&files),
        [
            "src/serve/steps.rs: builds a ReportInput; only src/workflow/ does (ARCHITECTURE.md, front ends thin over workflow)"
        ]
    );
}

/// Where a file outside `src/report/` derives `Serialize`: the wire
/// structs (whose keys are a promise to scripts) live in `report`
/// (ARCHITECTURE.md, "Serialisation"). Reading a file (`Deserialize`) is
/// anyone's.
fn wire_structs_outside_report(files: &[(PathBuf, String)]) -> Vec<String> {
    let mut found = Vec::new();
    for (path, text) in files {
        if path.starts_with("report") {
            continue;
        }
        let derives_serialize = code_of(text).lines().any(|line| {
            line.trim_start()
                .strip_prefix("#[derive(")
                .is_some_and(|list| {
                    list.trim_end_matches(")]")
                        .split(',')
                        .any(|name| matches!(name.trim(), "Serialize" | "serde::Serialize"))
                })
        });
        if derives_serialize {
            found.push(format!(
                "src/{}: derives Serialize; wire structs live in src/report/",
                path.display()
            ));
        }
    }
    found
}

#[test]
fn only_report_derives_serialize() {
    let found = wire_structs_outside_report(&source_tree());
    assert!(found.is_empty(), "\n{}", found.join("\n"));
}

#[test]
fn a_wire_struct_outside_report_is_caught() {
    let files = tree(&[
        (
            "serve/mod.rs",
            "#[derive(Debug, Serialize)]\nstruct Answer {}",
        ),
        ("emit/profile.rs", "#[derive(Deserialize)]\nstruct File {}"),
        (
            "report/web.rs",
            "#[derive(Serialize)]\npub struct Answer {}",
        ),
        ("cli/mod.rs", "// #[derive(Serialize)]\nfn f() {}"),
    ]);
    assert_eq!(
        wire_structs_outside_report(&files),
        ["src/serve/mod.rs: derives Serialize; wire structs live in src/report/"]
    );
}

fn layers() -> BTreeMap<String, usize> {
    layers_from(
        "<!-- layers -->\n- 0: `units`\n- 1: `compensate`, `model`: peers\n- 2: `diagnose`\n<!-- /layers -->",
    )
    .unwrap()
}

fn tree(files: &[(&str, &str)]) -> Vec<(PathBuf, String)> {
    files
        .iter()
        .map(|(p, t)| (PathBuf::from(p), t.to_string()))
        .collect()
}

#[test]
fn the_layers_are_read_from_the_markdown_list() {
    let layers = layers();
    assert_eq!(layers["units"], 0);
    assert_eq!(layers["model"], 1);
    assert_eq!(layers["diagnose"], 2);
    assert!(layers_from("no markers").is_err());
}

#[test]
fn upward_and_peer_imports_are_caught_and_downward_ones_are_not() {
    let files = tree(&[
        ("units.rs", "pub fn mm() {}"),
        (
            "compensate/mod.rs",
            "use crate::units::mm;\nuse crate::{\n    diagnose::Effect,\n    model::Machine,\n};",
        ),
        ("model/mod.rs", "pub struct Machine;"),
        (
            "diagnose/mod.rs",
            "use crate::compensate;\npub struct Effect;",
        ),
    ]);
    let found = violations(&layers(), &files);
    assert_eq!(found.len(), 2, "{found:?}");
    assert!(found[0].contains("imports crate::diagnose::Effect (layer 2)"));
    assert!(found[1].contains("imports crate::model::Machine (layer 1)"));
}

#[test]
fn files_that_import_each_other_are_caught_but_a_parent_and_its_child_are_not() {
    let files = tree(&[
        (
            "diagnose/mod.rs",
            "mod a;\nmod b;\npub use a::Fold;\npub struct Input;",
        ),
        (
            "diagnose/a.rs",
            "use super::Input;\nuse super::b::levels;\npub struct Fold;",
        ),
        (
            "diagnose/b.rs",
            "pub fn levels() -> super::a::Fold { todo!() }",
        ),
    ]);
    let found = violations(&layers(), &files);
    assert_eq!(
        found,
        ["files import each other: src/diagnose/a.rs → src/diagnose/b.rs"]
    );
}

#[test]
fn comments_and_tests_are_not_imports() {
    let files = tree(&[
        (
            "units.rs",
            "//! see crate::diagnose\n#[cfg(test)]\nmod tests { use crate::diagnose; }",
        ),
        ("diagnose/mod.rs", "pub struct Effect;"),
        ("diagnose/tests.rs", "use crate::units;"),
        ("model/mod.rs", "pub fn f() {} // crate::diagnose::Effect"),
    ]);
    assert_eq!(violations(&layers(), &files), Vec::<String>::new());
}

#[test]
fn a_stage_missing_from_the_layers_is_named() {
    let files = tree(&[("servo/mod.rs", "pub fn f() {}")]);
    assert_eq!(
        violations(&layers(), &files),
        ["src/servo/mod.rs: stage `servo` is on no layer of ARCHITECTURE.md"]
    );
}

/// Code after a `#[cfg(test)]` item is read again: an upward import below a
/// test-only function (as `evaluate/mod.rs` has one in its `impl`) or below
/// a `mod tests;` line is caught.
#[test]
fn code_after_a_test_item_is_read() {
    let files = tree(&[
        (
            "units.rs",
            "pub struct Mm;\nimpl Mm {\n    #[cfg(test)]\n    pub(crate) fn of(\n        a: f64,\n    ) -> Mm {\n        if a > 0.0 { Mm } else { Mm }\n    }\n}\n#[cfg(test)]\nmod tests;\nuse crate::diagnose::Effect;",
        ),
        ("diagnose/mod.rs", "pub struct Effect;"),
    ]);
    assert_eq!(
        violations(&layers(), &files),
        [
            "src/units.rs: `units` (layer 0) imports crate::diagnose::Effect (layer 2): a dependency that does not point down"
        ]
    );
}
