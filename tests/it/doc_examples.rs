//! Every documented example is run: each `$ axcomp …` line of a ```console
//! block in README.md and under docs/ is run by the binary, and what it
//! prints (stdout, then stderr) must be the lines below it, so a document
//! cannot show output the program no longer prints.
//!
//! The form is trycmd's: a block is one session in a fresh folder that sees
//! the repository's `fixtures/`, `tests/` and `formats/` and `../shared`, as a
//! clone does; `...` alone on a line stands for any lines, `[..]` for any
//! text within a line (snapbox's wildcards); a line `? N` right below a
//! command expects exit code N (else 0). Only `axcomp` is run: a block with
//! another command fails, so every block here is one the test runs.

use std::path::{Path, PathBuf};
use std::process::Command;

use snapbox::IntoData;

use crate::util::root;

/// One `$ axcomp …` line and the output written below it.
#[derive(Debug, PartialEq)]
struct Example {
    /// Where it is: `README.md:640`.
    at: String,
    /// The words after `$ axcomp`.
    arguments: Vec<String>,
    /// The exit code expected (`? N`, else 0).
    code: i32,
    /// The lines below it, up to the next command or the block's end.
    output: String,
}

/// The ```console blocks of `markdown`, each a list of examples.
fn console_blocks(file: &str, markdown: &str) -> Result<Vec<Vec<Example>>, String> {
    let mut blocks = Vec::new();
    let mut block: Option<Vec<Example>> = None;
    for (index, line) in markdown.lines().enumerate() {
        let at = format!("{file}:{}", index + 1);
        match &mut block {
            None if line.trim_start().starts_with("```console") => block = Some(Vec::new()),
            None => {}
            Some(examples) if line.trim_start().starts_with("```") => {
                blocks.push(std::mem::take(examples));
                block = None;
            }
            Some(examples) => {
                if let Some(command) = line.strip_prefix("$ ") {
                    let words = shlex::split(command).ok_or(format!("{at}: unbalanced quotes"))?;
                    let Some(("axcomp", arguments)) =
                        words.split_first().map(|(p, a)| (p.as_str(), a))
                    else {
                        return Err(format!("{at}: only `$ axcomp …` is run here: {command}"));
                    };
                    examples.push(Example {
                        at,
                        arguments: arguments.to_vec(),
                        code: 0,
                        output: String::new(),
                    });
                    continue;
                }
                let Some(example) = examples.last_mut() else {
                    return Err(format!("{at}: output before any `$ axcomp` line"));
                };
                if let Some(code) = line
                    .strip_prefix("? ")
                    .filter(|_| example.output.is_empty())
                {
                    example.code = code
                        .parse()
                        .map_err(|_| format!("{at}: `? N` expects a number"))?;
                    continue;
                }
                example.output.push_str(line);
                example.output.push('\n');
            }
        }
    }
    if block.is_some() {
        return Err(format!("{file}: a ```console block is not closed"));
    }
    Ok(blocks)
}

/// A fresh folder laid out as a clone's: `work/` (the commands' folder)
/// sees the repository's fixtures, tests and formats, and `../shared`.
fn session_folder() -> (tempfile::TempDir, PathBuf) {
    let directory = tempfile::tempdir().unwrap();
    let work = directory.path().join("work");
    std::fs::create_dir(&work).unwrap();
    for name in ["fixtures", "tests", "formats"] {
        std::os::unix::fs::symlink(root().join(name), work.join(name)).unwrap();
    }
    std::os::unix::fs::symlink(root().join("../shared"), directory.path().join("shared")).unwrap();
    (directory, work)
}

/// Runs the examples of one block in order; the first mismatch, as text.
fn run_block(examples: &[Example]) -> Result<usize, String> {
    let (_directory, work) = session_folder();
    for example in examples {
        let output = Command::new(env!("CARGO_BIN_EXE_axcomp"))
            .args(&example.arguments)
            .current_dir(&work)
            .env("NO_COLOR", "1")
            .output()
            .map_err(|e| format!("{}: {e}", example.at))?;
        let code = output.status.code().unwrap_or(-1);
        let mut printed = String::from_utf8_lossy(&output.stdout).into_owned();
        printed.push_str(&String::from_utf8_lossy(&output.stderr));
        if code != example.code {
            return Err(format!(
                "{}: exit code {code}, the document says {}\n{printed}",
                example.at, example.code
            ));
        }
        snapbox::Assert::new()
            .try_eq(
                Some(&example.at),
                printed.into_data(),
                example.output.clone().into_data(),
            )
            .map_err(|e| format!("{}: the output differs from the document:\n{e}", example.at))?;
    }
    Ok(examples.len())
}

/// Every Markdown file under `folder`, at any depth, sorted.
pub fn markdown_under(folder: &Path) -> Vec<PathBuf> {
    fn walk(folder: &Path, found: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(folder) else {
            return;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                walk(&path, found);
            } else if path.extension().is_some_and(|e| e == "md") {
                found.push(path);
            }
        }
    }
    let mut found = Vec::new();
    walk(folder, &mut found);
    found.sort();
    found
}

/// README.md and every Markdown file under docs/.
fn documents() -> Vec<PathBuf> {
    let mut found = vec![root().join("README.md")];
    found.extend(markdown_under(&root().join("docs")));
    found
}

#[test]
fn every_documented_example_prints_what_the_document_shows() {
    let mut run = 0;
    let mut failures = Vec::new();
    for path in documents() {
        let file = path.strip_prefix(root()).unwrap().display().to_string();
        let text = std::fs::read_to_string(&path).unwrap();
        let blocks = console_blocks(&file, &text).unwrap_or_else(|e| panic!("{e}"));
        for block in blocks {
            match run_block(&block) {
                Ok(count) => run += count,
                Err(failure) => failures.push(failure),
            }
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n\n"));
    // The README alone shows the demo, an evaluation and a table.
    assert!(run >= 3, "only {run} documented examples ran");
}

/// The check fails on output changed by hand, on a wrong exit code and on a
/// block that runs something else, and takes the wildcards.
#[test]
fn the_example_check_can_fail() {
    let document =
        |output: &str| format!("text\n```console\n$ axcomp man nosuch\n? 2\n{output}```\n");
    let right = "axcomp: error: axcomp has no command \"nosuch\": expected one of [..]\n";
    let blocks = console_blocks("doc.md", &document(right)).unwrap();
    assert_eq!(blocks.len(), 1);
    assert_eq!(blocks[0][0].code, 2);
    assert_eq!(run_block(&blocks[0]), Ok(1));
    let elided = console_blocks("doc.md", &document("...\n")).unwrap();
    assert_eq!(run_block(&elided[0]), Ok(1));

    let changed = right.replace("no command", "no such command");
    let blocks = console_blocks("doc.md", &document(&changed)).unwrap();
    let failure = run_block(&blocks[0]).unwrap_err();
    assert!(
        failure.starts_with("doc.md:3: the output differs"),
        "{failure}"
    );

    let no_code = "```console\n$ axcomp man nosuch\n...\n```\n";
    let blocks = console_blocks("doc.md", no_code).unwrap();
    let failure = run_block(&blocks[0]).unwrap_err();
    assert!(
        failure.starts_with("doc.md:2: exit code 2, the document says 0"),
        "{failure}"
    );

    let other = console_blocks("doc.md", "```console\n$ ls\n```\n").unwrap_err();
    assert_eq!(other, "doc.md:2: only `$ axcomp …` is run here: ls");
}

/// A real example of the README, one figure changed by hand as a careless
/// edit would, no longer passes.
#[test]
fn a_readme_example_changed_by_hand_fails() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let blocks = console_blocks("README.md", &readme).unwrap();
    let mut block = blocks
        .into_iter()
        .find(|block| block.iter().any(|e| e.output.contains("13.19 ± 1.82")))
        .expect("README shows the sample's A, 13.19 ± 1.82 µm");
    assert_eq!(run_block(&block), Ok(block.len()));
    for example in &mut block {
        example.output = example.output.replace("13.19 ± 1.82", "13.18 ± 1.82");
    }
    let failure = run_block(&block).unwrap_err();
    assert!(failure.contains("the output differs"), "{failure}");
}
