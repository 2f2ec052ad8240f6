//! Every relative link in README.md, CONTRIBUTING.md and the guide
//! (docs/src/) points at a file that exists, and at a heading of it where it
//! names one; the guide's SUMMARY.md lists every page of docs/src, so the
//! book built from it has them all; the Windows zip (`scripts/dist-files`)
//! ships every file its Markdown links.

use std::path::{Path, PathBuf};

use crate::doc_examples::markdown_under;
use crate::util::root;

/// The Markdown files whose links are checked: README.md, CONTRIBUTING.md
/// and every page under docs/src.
fn documents() -> Vec<PathBuf> {
    let mut found = vec![root().join("README.md"), root().join("CONTRIBUTING.md")];
    found.extend(guide_pages());
    found
}

/// Every `.md` file under docs/src, at any depth.
fn guide_pages() -> Vec<PathBuf> {
    markdown_under(&root().join("docs/src"))
}

/// The targets of the inline links `[text](target)` of `markdown`, outside
/// fenced code blocks and code spans, with their line numbers.
fn link_targets(markdown: &str) -> Vec<(usize, String)> {
    let mut targets = Vec::new();
    let mut fenced = false;
    for (index, line) in markdown.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        // Code spans hold examples, not links.
        let prose: String = line
            .split('`')
            .enumerate()
            .filter(|(i, _)| i % 2 == 0)
            .map(|(_, part)| part)
            .collect::<Vec<_>>()
            .join(" ");
        let mut rest = prose.as_str();
        while let Some(start) = rest.find("](") {
            let after = &rest[start + 2..];
            let Some(end) = after.find(')') else { break };
            targets.push((index + 1, after[..end].to_string()));
            rest = &after[end..];
        }
    }
    targets
}

/// The anchor a heading gets (mdBook's and GitHub's rule for plain
/// headings): letters, digits, `-` and `_` kept and lower-cased, spaces
/// made `-`, anything else dropped.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .chars()
        .filter_map(|c| {
            if c.is_alphanumeric() || c == '-' || c == '_' {
                Some(c.to_lowercase().next().unwrap_or(c))
            } else if c.is_whitespace() {
                Some('-')
            } else {
                None
            }
        })
        .collect()
}

/// The anchors of the headings of `markdown` (outside fenced code).
fn anchors(markdown: &str) -> Vec<String> {
    let mut found = Vec::new();
    let mut fenced = false;
    for line in markdown.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
        } else if !fenced && line.starts_with('#') {
            found.push(anchor(line.trim_start_matches('#')));
        }
    }
    found
}

/// What is wrong with one link of `file`, if anything.
fn broken(file: &Path, target: &str) -> Option<String> {
    if target.contains("://") || target.starts_with("mailto:") {
        return None;
    }
    let (path, fragment) = match target.split_once('#') {
        Some((path, fragment)) => (path, Some(fragment)),
        None => (target, None),
    };
    let linked = if path.is_empty() {
        file.to_path_buf()
    } else {
        file.parent().unwrap().join(path)
    };
    if !linked.exists() {
        return Some(format!("{target}: no such file"));
    }
    let fragment = fragment?;
    if linked.extension().is_none_or(|e| e != "md") {
        return None;
    }
    let text = std::fs::read_to_string(&linked).unwrap();
    if anchors(&text).iter().any(|a| a == fragment) {
        return None;
    }
    Some(format!("{target}: no heading with the anchor #{fragment}"))
}

#[test]
fn every_relative_link_points_at_an_existing_file_and_heading() {
    let mut failures = Vec::new();
    let mut checked = 0;
    for file in documents() {
        let text =
            std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        for (line, target) in link_targets(&text) {
            checked += 1;
            if let Some(why) = broken(&file, &target) {
                let name = file.strip_prefix(root()).unwrap().display();
                failures.push(format!("{name}:{line}: {why}"));
            }
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
    assert!(checked > 50, "only {checked} links found");
}

#[test]
fn the_summary_lists_every_page_of_the_guide() {
    let src = root().join("docs/src");
    let summary = std::fs::read_to_string(src.join("SUMMARY.md")).unwrap();
    let listed: Vec<PathBuf> = link_targets(&summary)
        .into_iter()
        .map(|(_, target)| src.join(target))
        .collect();
    let missing: Vec<String> = guide_pages()
        .into_iter()
        .filter(|page| !page.ends_with("SUMMARY.md") && !listed.contains(page))
        .map(|page| page.strip_prefix(&src).unwrap().display().to_string())
        .collect();
    assert!(missing.is_empty(), "SUMMARY.md does not list {missing:?}");
    assert!(root().join("docs/book.toml").exists());
}

/// The checks find what they must: a missing file, a missing heading, and a
/// page SUMMARY.md would not list; code is not read as links.
#[test]
fn the_link_check_can_fail() {
    let text = "# A page\n\n## Sub-heading: ISO 230-2 (2014)\n\nSee [x](missing.md), \
                [y](#sub-heading-iso-230-2-2014), [z](#nowhere) and `[c](code.md)`.\n\
                ```sh\n[d](fenced.md)\n```\n";
    let targets: Vec<String> = link_targets(text).into_iter().map(|(_, t)| t).collect();
    assert_eq!(
        targets,
        ["missing.md", "#sub-heading-iso-230-2-2014", "#nowhere"]
    );
    let directory = tempfile::tempdir().unwrap();
    let file = directory.path().join("page.md");
    std::fs::write(&file, text).unwrap();
    assert_eq!(
        broken(&file, "missing.md").as_deref(),
        Some("missing.md: no such file")
    );
    assert_eq!(broken(&file, "#sub-heading-iso-230-2-2014"), None);
    assert_eq!(
        broken(&file, "#nowhere").as_deref(),
        Some("#nowhere: no heading with the anchor #nowhere")
    );
    assert_eq!(broken(&file, "https://example.com/x"), None);
    assert_eq!(anchor(" Valášek (2021), and why"), "valášek-2021-and-why");
}

/// README.md is the front page: install, set-up, the demo, the workflow and
/// where to go next, in at most 300 lines; the rest belongs in the guide.
#[test]
fn the_readme_stays_a_front_page() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let lines = readme.lines().count();
    assert!(
        lines <= 300,
        "README.md has {lines} lines; move detail into docs/src"
    );
    for (what, needle) in [
        ("install", "cargo install --path ."),
        ("the demo", "$ axcomp demo"),
        ("the tests", "scripts/test"),
        ("the guide", "docs/src/SUMMARY.md"),
    ] {
        assert!(readme.contains(needle), "README.md lacks {what} ({needle})");
    }
}

/// The paths `scripts/dist` puts in the Windows zip beside `axcomp.exe`.
fn shipped_in_the_zip() -> Vec<PathBuf> {
    let list = std::fs::read_to_string(root().join("scripts/dist-files")).unwrap();
    list.lines()
        .filter(|line| !line.is_empty() && !line.starts_with('#'))
        .map(|line| root().join(line))
        .collect()
}

#[test]
fn the_windows_zip_ships_every_file_its_documents_link() {
    let shipped = shipped_in_the_zip();
    let is_shipped = |path: &Path| shipped.iter().any(|s| path.starts_with(s));
    let documents: Vec<PathBuf> = shipped
        .iter()
        .flat_map(|path| match path.is_dir() {
            true => markdown_under(path),
            false => vec![path.clone()],
        })
        .collect();
    assert!(documents.contains(&root().join("README.md")));
    assert!(is_shipped(&root().join("fixtures/sample-x.rtl")));
    let mut failures = Vec::new();
    for file in &documents {
        assert!(file.exists(), "{} is listed but missing", file.display());
        if file.extension().is_none_or(|e| e != "md") {
            continue;
        }
        let text = std::fs::read_to_string(file).unwrap();
        for (line, target) in link_targets(&text) {
            let path = target.split('#').next().unwrap_or_default();
            if target.contains("://") || target.starts_with("mailto:") || path.is_empty() {
                continue;
            }
            // Lexically: `..` in a link must not climb out of the zip.
            let mut linked = file.parent().unwrap().to_path_buf();
            for part in Path::new(path).components() {
                match part {
                    std::path::Component::ParentDir => {
                        linked.pop();
                    }
                    other => linked.push(other),
                }
            }
            if !is_shipped(&linked) {
                let name = file.strip_prefix(root()).unwrap().display();
                failures.push(format!("{name}:{line}: {target} is not in the zip"));
            }
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}
