//! `#import` for WGSL (naga has none): assembles one module from a root file
//! and the files it imports, each pulled in once, dependencies first.
//!
//! A file states its dependencies in its header, the lines before its first
//! line of code (only blank lines and `//` comments may come between them):
//!
//! ```text
//! #import "../common.wgsl"   // a file, relative to the importing file's folder
//! #import "density.wgsl"
//! #import <field>            // a slot: the file the caller binds to `field`
//! ```
//!
//! - `#import "path"` names a file by its path relative to the folder of the
//!   file that imports it (`..` goes up a folder, never above the root of
//!   the file set). Paths in the file set are relative to its root
//!   (`shaders/`), with `/` between folders.
//! - `#import <name>` names a slot: the caller of [`assemble`] binds each
//!   slot name to a path from the root, so one file can be assembled with
//!   different implementations of the same functions (the ray-march's
//!   `clouds.wgsl` imports `<field>`, bound to `raymarch/field_exact.wgsl`
//!   or `raymarch/field_baked.wgsl` by the render method). A binding is
//!   used only if some file of the module imports its slot.
//!
//! Each file enters the module once, however many files import it, after
//! everything it imports (depth first, in the order of its `#import`
//! lines), so the root comes last. In the output each file starts with a
//! `// file: path` line, and its `#import` lines become `// #import …`
//! comments, so lines keep their place within each file.
//!
//! A missing file, an unbound slot, a malformed or misplaced `#import` and an
//! import cycle are [`ImportError`]s naming the file and line.

use std::collections::HashMap;
use std::fmt;

/// Why a module could not be assembled: `file` (a path from the root of
/// the file set), line `line` (from 1; 0 for the root itself).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ImportError {
    pub file: String,
    pub line: usize,
    pub kind: ImportErrorKind,
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ImportErrorKind {
    /// The imported path (resolved from the root) is not in the file set.
    MissingFile(String),
    /// No file is bound to this slot.
    UnboundSlot(String),
    /// A `..` climbs above the root of the file set.
    OutsideRoot(String),
    /// A line starting with `#` that is not `#import "path"` or `#import <name>`.
    Malformed(String),
    /// An `#import` after the file's first line of code.
    AfterCode,
    /// The import closes a cycle: the files from the first on the cycle
    /// back to it.
    Cycle(Vec<String>),
}

impl fmt::Display for ImportError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "shaders/{}:{}: ", self.file, self.line)?;
        match &self.kind {
            ImportErrorKind::MissingFile(p) => write!(f, "no file shaders/{p} to import"),
            ImportErrorKind::UnboundSlot(s) => write!(f, "slot <{s}> is bound to no file"),
            ImportErrorKind::OutsideRoot(p) => write!(f, "import \"{p}\" leaves shaders/"),
            ImportErrorKind::Malformed(l) => write!(
                f,
                "expected `#import \"path\"` or `#import <slot>`, found `{l}`"
            ),
            ImportErrorKind::AfterCode => {
                write!(f, "#import after code: imports go in the file's header")
            }
            ImportErrorKind::Cycle(files) => {
                write!(f, "import cycle {}", files.join(" → "))
            }
        }
    }
}

impl std::error::Error for ImportError {}

/// One module's source and the files in it, in order (the root last).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Assembly {
    pub files: Vec<String>,
    pub source: String,
}

/// What an `#import` line names.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Target {
    Path(String),
    Slot(String),
}

/// One `#import` of a file: its line (from 1) and target.
struct Import {
    line: usize,
    target: Target,
}

/// The `#import`s of `text` (a file at `file`), checked for form and place.
fn imports(file: &str, text: &str) -> Result<Vec<Import>, ImportError> {
    let err = |line, kind| ImportError {
        file: file.to_string(),
        line,
        kind,
    };
    let mut out = Vec::new();
    let mut in_header = true;
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if !line.starts_with('#') {
            in_header &= line.is_empty() || line.starts_with("//");
            continue;
        }
        if !in_header {
            return Err(err(i + 1, ImportErrorKind::AfterCode));
        }
        let target = parse_import(line)
            .ok_or_else(|| err(i + 1, ImportErrorKind::Malformed(line.into())))?;
        out.push(Import {
            line: i + 1,
            target,
        });
    }
    Ok(out)
}

/// The target of one `#import` line (trimmed), None if malformed. A
/// trailing `//` comment is allowed.
fn parse_import(line: &str) -> Option<Target> {
    let rest = line.strip_prefix("#import")?;
    if !rest.starts_with(char::is_whitespace) {
        return None;
    }
    let rest = rest.trim_start();
    let (target, tail) = if let Some(r) = rest.strip_prefix('"') {
        let end = r.find('"')?;
        (Target::Path(r[..end].to_string()), &r[end + 1..])
    } else if let Some(r) = rest.strip_prefix('<') {
        let end = r.find('>')?;
        let name = &r[..end];
        let ident = !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        if !ident {
            return None;
        }
        (Target::Slot(name.to_string()), &r[end + 1..])
    } else {
        return None;
    };
    let tail = tail.trim_start();
    let empty = match &target {
        Target::Path(p) => p.is_empty(),
        Target::Slot(_) => false,
    };
    (!empty && (tail.is_empty() || tail.starts_with("//"))).then_some(target)
}

/// `path` (relative to the folder of `from`) as a path from the root; None
/// if it climbs above the root.
fn resolve(from: &str, path: &str) -> Option<String> {
    let mut parts: Vec<&str> = from.split('/').collect();
    parts.pop(); // the importing file's own name
    for part in path.split('/') {
        match part {
            "" | "." => {}
            ".." => {
                parts.pop()?;
            }
            p => parts.push(p),
        }
    }
    Some(parts.join("/"))
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum State {
    /// On the current import chain (seeing it again is a cycle).
    Open,
    /// In the output already.
    Done,
}

struct Assembler<'a> {
    files: &'a [(&'a str, &'a str)],
    slots: &'a [(&'a str, &'a str)],
    state: HashMap<String, State>,
    /// The current import chain, root first.
    chain: Vec<String>,
    out: Assembly,
}

impl<'a> Assembler<'a> {
    fn text(&self, path: &str) -> Option<&'a str> {
        self.files.iter().find(|(p, _)| *p == path).map(|(_, t)| *t)
    }

    /// Adds `path` (known to exist) after its imports.
    fn visit(&mut self, path: &str) -> Result<(), ImportError> {
        let text = self.text(path).expect("checked by the caller");
        self.state.insert(path.to_string(), State::Open);
        self.chain.push(path.to_string());
        for import in imports(path, text)? {
            let err = |kind| ImportError {
                file: path.to_string(),
                line: import.line,
                kind,
            };
            let dep = match &import.target {
                Target::Path(p) => {
                    resolve(path, p).ok_or_else(|| err(ImportErrorKind::OutsideRoot(p.clone())))?
                }
                Target::Slot(s) => self
                    .slots
                    .iter()
                    .find(|(name, _)| name == s)
                    .map(|(_, p)| p.to_string())
                    .ok_or_else(|| err(ImportErrorKind::UnboundSlot(s.clone())))?,
            };
            match self.state.get(&dep) {
                Some(State::Done) => continue,
                Some(State::Open) => {
                    let first = self.chain.iter().position(|f| *f == dep).unwrap_or(0);
                    let mut cycle = self.chain[first..].to_vec();
                    cycle.push(dep);
                    return Err(err(ImportErrorKind::Cycle(cycle)));
                }
                None => {}
            }
            if self.text(&dep).is_none() {
                return Err(err(ImportErrorKind::MissingFile(dep)));
            }
            self.visit(&dep)?;
        }
        self.chain.pop();
        self.state.insert(path.to_string(), State::Done);
        self.emit(path, text);
        Ok(())
    }

    fn emit(&mut self, path: &str, text: &str) {
        let s = &mut self.out.source;
        s.push_str("// file: ");
        s.push_str(path);
        s.push('\n');
        for line in text.lines() {
            if line.trim_start().starts_with("#import") {
                s.push_str("// ");
            }
            s.push_str(line);
            s.push('\n');
        }
        self.out.files.push(path.to_string());
    }
}

/// The module of `root` (a path from the root of `files`, which maps paths
/// to sources): `prefix`, then every file `root` imports, directly or not,
/// each once and after its own imports, then `root`. `slots` binds slot
/// names to paths from the root.
pub fn assemble(
    files: &[(&str, &str)],
    root: &str,
    slots: &[(&str, &str)],
    prefix: &str,
) -> Result<Assembly, ImportError> {
    let mut a = Assembler {
        files,
        slots,
        state: HashMap::new(),
        chain: Vec::new(),
        out: Assembly {
            files: Vec::new(),
            source: prefix.to_string(),
        },
    };
    if a.text(root).is_none() {
        return Err(ImportError {
            file: root.to_string(),
            line: 0,
            kind: ImportErrorKind::MissingFile(root.to_string()),
        });
    }
    a.visit(root)?;
    Ok(a.out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn order(files: &[(&str, &str)], root: &str, slots: &[(&str, &str)]) -> Vec<String> {
        assemble(files, root, slots, "").unwrap().files
    }

    fn error(files: &[(&str, &str)], root: &str, slots: &[(&str, &str)]) -> ImportError {
        assemble(files, root, slots, "").unwrap_err()
    }

    #[test]
    fn dependencies_come_first_in_import_order() {
        let files = [
            (
                "main.wgsl",
                "#import \"b.wgsl\"\n#import \"a.wgsl\"\nfn main() {}\n",
            ),
            ("a.wgsl", "fn a() {}\n"),
            ("b.wgsl", "#import \"c.wgsl\"\nfn b() {}\n"),
            ("c.wgsl", "fn c() {}\n"),
        ];
        assert_eq!(
            order(&files, "main.wgsl", &[]),
            ["c.wgsl", "b.wgsl", "a.wgsl", "main.wgsl"]
        );
    }

    #[test]
    fn a_file_imported_twice_enters_once() {
        // A diamond: both b and c import a.
        let files = [
            (
                "main.wgsl",
                "#import \"b.wgsl\"\n#import \"c.wgsl\"\n#import \"a.wgsl\"\n",
            ),
            ("a.wgsl", "fn a() {}\n"),
            ("b.wgsl", "#import \"a.wgsl\"\nfn b() {}\n"),
            ("c.wgsl", "#import \"a.wgsl\"\nfn c() {}\n"),
        ];
        let a = assemble(&files, "main.wgsl", &[], "").unwrap();
        assert_eq!(a.files, ["a.wgsl", "b.wgsl", "c.wgsl", "main.wgsl"]);
        assert_eq!(a.source.matches("fn a()").count(), 1);
    }

    #[test]
    fn output_keeps_lines_and_comments_out_the_imports() {
        let files = [
            (
                "main.wgsl",
                "// Main.\n#import \"a.wgsl\" // for a()\n\nfn main() {}\n",
            ),
            ("a.wgsl", "fn a() {}\n"),
        ];
        let a = assemble(&files, "main.wgsl", &[], "const N: u32 = 4u;\n").unwrap();
        assert_eq!(
            a.source,
            "const N: u32 = 4u;\n\
             // file: a.wgsl\nfn a() {}\n\
             // file: main.wgsl\n// Main.\n// #import \"a.wgsl\" // for a()\n\nfn main() {}\n"
        );
    }

    #[test]
    fn paths_are_relative_to_the_importing_file() {
        let files = [
            ("lib.wgsl", "fn lib() {}\n"),
            (
                "pass/main.wgsl",
                "#import \"../lib.wgsl\"\n#import \"part.wgsl\"\n",
            ),
            ("pass/part.wgsl", "#import \"./deep/x.wgsl\"\n"),
            ("pass/deep/x.wgsl", "#import \"../../lib.wgsl\"\n"),
        ];
        assert_eq!(
            order(&files, "pass/main.wgsl", &[]),
            [
                "lib.wgsl",
                "pass/deep/x.wgsl",
                "pass/part.wgsl",
                "pass/main.wgsl"
            ]
        );
        let outside = [("main.wgsl", "#import \"../x.wgsl\"\n")];
        assert_eq!(
            error(&outside, "main.wgsl", &[]).kind,
            ImportErrorKind::OutsideRoot("../x.wgsl".into())
        );
    }

    #[test]
    fn a_slot_imports_the_file_bound_to_it() {
        let files = [
            (
                "pass/main.wgsl",
                "#import <field>\nfn main() { value(); }\n",
            ),
            ("pass/field_a.wgsl", "fn value() -> f32 { return 1.0; }\n"),
            ("pass/field_b.wgsl", "fn value() -> f32 { return 2.0; }\n"),
        ];
        for f in ["pass/field_a.wgsl", "pass/field_b.wgsl"] {
            assert_eq!(
                order(&files, "pass/main.wgsl", &[("other", "x"), ("field", f)]),
                [f, "pass/main.wgsl"]
            );
        }
        let e = error(&files, "pass/main.wgsl", &[("other", "x")]);
        assert_eq!(
            e,
            ImportError {
                file: "pass/main.wgsl".into(),
                line: 1,
                kind: ImportErrorKind::UnboundSlot("field".into()),
            }
        );
        assert_eq!(
            e.to_string(),
            "shaders/pass/main.wgsl:1: slot <field> is bound to no file"
        );
    }

    #[test]
    fn a_cycle_is_an_error_naming_file_line_and_chain() {
        let files = [
            ("main.wgsl", "#import \"a.wgsl\"\n"),
            ("a.wgsl", "// A.\n#import \"b.wgsl\"\n"),
            ("b.wgsl", "\n\n#import \"a.wgsl\"\n"),
        ];
        let e = error(&files, "main.wgsl", &[]);
        assert_eq!(
            e,
            ImportError {
                file: "b.wgsl".into(),
                line: 3,
                kind: ImportErrorKind::Cycle(vec![
                    "a.wgsl".into(),
                    "b.wgsl".into(),
                    "a.wgsl".into()
                ]),
            }
        );
        assert_eq!(
            e.to_string(),
            "shaders/b.wgsl:3: import cycle a.wgsl → b.wgsl → a.wgsl"
        );
        let selfish = [("main.wgsl", "#import \"main.wgsl\"\n")];
        assert_eq!(
            error(&selfish, "main.wgsl", &[]).kind,
            ImportErrorKind::Cycle(vec!["main.wgsl".into(), "main.wgsl".into()])
        );
    }

    #[test]
    fn a_missing_file_is_an_error_naming_file_and_line() {
        let files = [("dir/main.wgsl", "\n#import \"nope.wgsl\"\n")];
        let e = error(&files, "dir/main.wgsl", &[]);
        assert_eq!(
            e,
            ImportError {
                file: "dir/main.wgsl".into(),
                line: 2,
                kind: ImportErrorKind::MissingFile("dir/nope.wgsl".into()),
            }
        );
        assert_eq!(
            e.to_string(),
            "shaders/dir/main.wgsl:2: no file shaders/dir/nope.wgsl to import"
        );
        // A slot bound to a missing file, and a missing root.
        let slot = [("main.wgsl", "#import <f>\n")];
        assert_eq!(
            error(&slot, "main.wgsl", &[("f", "gone.wgsl")]).kind,
            ImportErrorKind::MissingFile("gone.wgsl".into())
        );
        assert_eq!(error(&slot, "x.wgsl", &[]).line, 0);
    }

    #[test]
    fn imports_belong_in_the_header_and_well_formed() {
        let late = [("main.wgsl", "// Header.\n\nfn f() {}\n#import \"a.wgsl\"\n")];
        let e = error(&late, "main.wgsl", &[]);
        assert_eq!((e.line, e.kind), (4, ImportErrorKind::AfterCode));
        for bad in [
            "#import a.wgsl",
            "#import \"a.wgsl",
            "#import <>",
            "#import <a b>",
            "#import \"\"",
            "#import \"a.wgsl\" x",
            "#importx \"a.wgsl\"",
            "#include \"a.wgsl\"",
        ] {
            let files = [("main.wgsl", bad), ("a.wgsl", "")];
            let e = error(&files, "main.wgsl", &[]);
            assert_eq!(e.kind, ImportErrorKind::Malformed(bad.into()), "{bad}");
            assert_eq!(e.line, 1);
        }
    }
}
