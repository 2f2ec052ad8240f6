//! docs/src/json.md, the JSON reference, is made from the module docs of the
//! `--json` output types (one copy: the wire format is written beside the
//! structs that produce it), so the guide cannot drift from them. After a
//! module doc changes, `AXCOMP_UPDATE_GOLDEN=1 cargo test --test it
//! json_reference` rewrites the page; review the diff.

use crate::util::{assert_golden, root};

/// Each section of the page: its heading (the anchor the guide links to),
/// what it covers, and the module whose doc holds it.
const SECTIONS: &[(&str, &str, &str)] = &[
    ("evaluate", "`axcomp evaluate --json`", "src/report/json.rs"),
    (
        "verdict",
        "the `verdict` key (with acceptance limits)",
        "src/report/verdict.rs",
    ),
    (
        "uncertainty",
        "the `uncertainty_um` key",
        "src/report/uncertainty.rs",
    ),
    (
        "convert",
        "`axcomp convert --json`",
        "src/report/convert.rs",
    ),
    (
        "update",
        "the `update` key of `convert --json` (with `--existing`)",
        "src/report/update.rs",
    ),
    (
        "predict",
        "`axcomp predict --json`",
        "src/report/predict.rs",
    ),
    (
        "diagnose",
        "`axcomp diagnose --json`",
        "src/report/diagnose/mod.rs",
    ),
    (
        "tolerance",
        "`axcomp tolerance --json`",
        "src/report/tolerance.rs",
    ),
    (
        "servo-sim",
        "`axcomp servo-sim --json`",
        "src/report/servo.rs",
    ),
    (
        "thermal",
        "`axcomp thermal evaluate` and `thermal apply --json`",
        "src/report/thermal.rs",
    ),
];

/// The leading `//!` lines of a source file, as Markdown with its headings
/// moved below the page's section headings.
fn module_doc(source: &str) -> String {
    let mut doc = String::new();
    for line in source.lines() {
        let Some(text) = line.strip_prefix("//!") else {
            break;
        };
        let text = text.strip_prefix(' ').unwrap_or(text);
        if text.starts_with('#') {
            doc.push_str("##");
        }
        doc.push_str(text);
        doc.push('\n');
    }
    doc
}

/// The page as the module docs make it.
fn json_reference() -> String {
    let mut page = String::from(
        "# JSON reference\n\n\
         Every command that takes `--json` prints one object on stdout; keys may\n\
         be added, never renamed or removed without a line in CHANGELOG.md.\n\
         Lengths and angles carry their unit in the key (`_mm`, `_um`, `_deg`,\n\
         `_arcsec`, `_urad`); a figure that is not evaluated is `null`, never 0.\n\n\
         This page is made from the module docs of the output types (the test\n\
         `tests/it/json_reference.rs` keeps it equal to them): each section\n\
         names its module.\n",
    );
    for (anchor, what, path) in SECTIONS {
        let source = std::fs::read_to_string(root().join(path)).unwrap();
        page.push_str(&format!("\n## {anchor}\n\n{what}, from `{path}`:\n\n"));
        page.push_str(&module_doc(&source));
    }
    page
}

#[test]
fn the_json_reference_is_made_from_the_module_docs() {
    assert_golden(&json_reference(), &root().join("docs/src/json.md"));
}

#[test]
fn module_doc_headings_sit_below_the_page_sections() {
    let doc = module_doc(
        "//! What it is.\n//!\n//! # Wire format\n//!\n//!   { }\nuse x;\n//! not this\n",
    );
    assert_eq!(doc, "What it is.\n\n### Wire format\n\n  { }\n");
}
