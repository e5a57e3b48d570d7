//! The documentation as a user meets it: the README's command lines run,
//! every relative link in the README and `docs/` points to a file, and the
//! README stays short enough to read.

mod commands;
mod links;

use std::path::{Path, PathBuf};

/// The crate root, where the README and `docs/` live.
fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// README.md and every `docs/*.md`, with their text.
fn markdown_files() -> Vec<(PathBuf, String)> {
    let mut paths = vec![root().join("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root().join("docs"))
        .expect("docs/ exists")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    docs.sort();
    paths.extend(docs);
    paths
        .into_iter()
        .map(|p| {
            let text = std::fs::read_to_string(&p)
                .unwrap_or_else(|e| panic!("cannot read {}: {e}", p.display()));
            (p, text)
        })
        .collect()
}

/// The most lines the README may have (issue 31: a user's guide, not a
/// lab notebook; the rest lives in `docs/`).
const README_MAX_LINES: usize = 350;

#[test]
fn readme_is_at_most_350_lines() {
    let text = std::fs::read_to_string(root().join("README.md")).unwrap();
    let lines = text.lines().count();
    assert!(
        lines <= README_MAX_LINES,
        "README.md has {lines} lines (at most {README_MAX_LINES}): move detail into docs/"
    );
}
