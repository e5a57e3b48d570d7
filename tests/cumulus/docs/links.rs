//! Every relative link in README.md and docs/*.md (`[text](path)` and
//! `![alt](path)`) names a file or folder that exists, relative to the
//! page. Web addresses and pure `#anchors` are left out; a `#fragment` is
//! stripped. Fenced code blocks and inline code are not links.

use std::path::{Path, PathBuf};

/// The link targets of a markdown text with their line numbers (1-based).
pub fn link_targets(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut fenced = false;
    for (i, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        // Drop inline code spans: `a](b)` inside backticks is not a link.
        let mut prose = String::new();
        for (k, part) in line.split('`').enumerate() {
            if k % 2 == 0 {
                prose.push_str(part);
            }
        }
        let mut rest = prose.as_str();
        while let Some(at) = rest.find("](") {
            let after = &rest[at + 2..];
            let Some(end) = after.find(')') else { break };
            // `(path "title")`: the path is the first word.
            let target = after[..end].split_whitespace().next().unwrap_or("");
            out.push((i + 1, target.trim_matches(['<', '>']).to_string()));
            rest = &after[end + 1..];
        }
    }
    out
}

/// The links of `text` (a page at `page`) whose file is missing, as
/// "page:line: target".
pub fn broken_links(page: &Path, text: &str) -> Vec<String> {
    let dir = page.parent().unwrap_or(Path::new("."));
    link_targets(text)
        .into_iter()
        .filter_map(|(line, target)| {
            let external = target.starts_with("http://")
                || target.starts_with("https://")
                || target.starts_with("mailto:");
            let path = target.split('#').next().unwrap_or("");
            if external || path.is_empty() {
                return None;
            }
            let file: PathBuf = dir.join(path);
            (!file.exists()).then(|| format!("{}:{line}: {target}", page.display()))
        })
        .collect()
}

#[test]
fn relative_links_in_readme_and_docs_point_to_files() {
    let mut broken = Vec::new();
    let mut checked = 0;
    for (page, text) in super::markdown_files() {
        checked += link_targets(&text).len();
        broken.extend(broken_links(&page, &text));
    }
    assert!(
        checked >= 10,
        "found only {checked} links: is the parser reading the pages?"
    );
    assert!(
        broken.is_empty(),
        "links to missing files:\n{}",
        broken.join("\n")
    );
}

/// The checker itself: a missing file is reported, an existing one, a web
/// address, an anchor and code are not.
#[test]
fn the_link_check_reports_a_link_to_a_missing_file() {
    let page = super::root().join("docs").join("page.md");
    let text = "See [arch](ARCHITECTURE.md#layers), [web](https://example.org/x.md),\n\
                [here](#top), `[code](nothing.md)`, ![img](../profiles/images/watch.png)\n\
                and [gone](no_such_page.md).\n\
                ```\n[fenced](also_missing.md)\n```\n";
    assert_eq!(
        broken_links(&page, text),
        vec![format!("{}:3: no_such_page.md", page.display())]
    );
}
