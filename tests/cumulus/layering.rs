//! The layering of `src/lib.rs`: every top-level module imports only the
//! modules listed before it in the crate docs' layer list, so the import
//! graph between top-level modules has no cycle; the CPU models (the
//! top-level ones and each method's `model/`) import no GPU core, method
//! GPU side, scene, renderer, front end or GPU crate; and each render
//! method (`src/methods/<method>/`) imports no other method. Every
//! `crate::` path counts, in `use` lines and inline in code (comments and
//! doc comments do not).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The top-level CPU models: atmosphere, physics, sun, sky, landscape
/// and noise (the methods' models are their `model/` folders).
const CPU_MODELS: [&str; 6] = ["landscape", "noise", "atmosphere", "sun", "sky", "physics"];
/// What a CPU model must not import.
const NOT_FOR_MODELS: [&str; 10] = [
    "gpu",
    "methods",
    "scene",
    "plots",
    "render",
    "export",
    "stability",
    "bench",
    "app",
    "cli",
];
/// External crates of the GPU and the window, which no CPU model names.
const GPU_CRATES: [&str; 4] = ["wgpu", "naga", "winit", "egui"];

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The layer list of the crate docs: the module of each `//! N. [`name`]`
/// line, in order.
fn layer_order(lib_rs: &str) -> Vec<String> {
    lib_rs
        .lines()
        .filter_map(|l| l.strip_prefix("//! "))
        .filter(|l| {
            l.split_once(". ")
                .is_some_and(|(n, _)| n.parse::<u32>().is_ok())
        })
        .filter_map(|l| {
            let rest = l.split_once("[`")?.1;
            Some(rest.split_once('`')?.0.to_string())
        })
        .collect()
}

/// Code of a line without its `//` comment (doc comments included).
fn code_of(line: &str) -> &str {
    match line.find("//") {
        Some(i) => &line[..i],
        None => line,
    }
}

/// Every top-level module a source text names through `crate::`, with the
/// 1-based line: `crate::a::…` gives `a`, `crate::{a::x, b}` gives `a` and
/// `b` (a group may span lines).
fn crate_paths(text: &str) -> Vec<(usize, String)> {
    let code: Vec<(usize, &str)> = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, code_of(l)))
        .collect();
    let joined: String = code.iter().map(|(_, l)| format!("{l}\n")).collect();
    let line_at = |offset: usize| joined[..offset].matches('\n').count() + 1;
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(i) = joined[from..].find("crate::") {
        let at = from + i;
        from = at + "crate::".len();
        // `cumulus::crate::` cannot occur; a preceding identifier character
        // means another word (e.g. `subcrate::`).
        if joined[..at]
            .chars()
            .last()
            .is_some_and(|c| c.is_alphanumeric() || c == '_')
        {
            continue;
        }
        let rest = &joined[from..];
        if let Some(group) = rest.strip_prefix('{') {
            // Top-level names of the group: at brace depth 0 after `{`.
            let mut depth = 0;
            let mut word = String::new();
            let mut expect_name = true;
            for c in group.chars() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => expect_name = true,
                    c if (c.is_alphanumeric() || c == '_') && depth == 0 && expect_name => {
                        word.push(c)
                    }
                    _ => {
                        if !word.is_empty() {
                            out.push((line_at(at), std::mem::take(&mut word)));
                            expect_name = false;
                        }
                    }
                }
            }
        } else {
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if !name.is_empty() {
                out.push((line_at(at), name));
            }
        }
    }
    out
}

/// The top-level module a file under `src/` belongs to (None: the crate
/// root `lib.rs`, the binary's `main.rs` and its `cli/`).
fn top_module(src: &Path, file: &Path) -> Option<String> {
    let rel = file.strip_prefix(src).unwrap();
    let first = rel.components().next()?.as_os_str().to_str()?.to_string();
    let name = first.strip_suffix(".rs").unwrap_or(&first).to_string();
    (!matches!(name.as_str(), "lib" | "main" | "cli")).then_some(name)
}

/// Offences of `text` (the source of a file of module `module`) against
/// the layer order and the CPU-model rule.
fn offences(module: &str, order: &[String], file: &str, text: &str) -> Vec<String> {
    let rank = |m: &str| order.iter().position(|o| o == m);
    let mut out = Vec::new();
    let Some(own) = rank(module) else {
        return vec![format!(
            "{file}: module `{module}` is not in lib.rs's layer list"
        )];
    };
    for (line, target) in crate_paths(text) {
        if target == module {
            continue;
        }
        match rank(&target) {
            // `crate::Error`, `crate::Result`: the root's re-exports.
            None if target.chars().next().is_some_and(char::is_uppercase) => {}
            None => out.push(format!(
                "{file}:{line}: `crate::{target}` is not a module of the layer list"
            )),
            Some(r) if r > own => out.push(format!(
                "{file}:{line}: `{module}` imports `{target}`, a layer above it"
            )),
            Some(_) => {}
        }
        if CPU_MODELS.contains(&module) && NOT_FOR_MODELS.contains(&target.as_str()) {
            out.push(format!(
                "{file}:{line}: the CPU model `{module}` imports `{target}`"
            ));
        }
    }
    out.extend(gpu_crates(module, file, text));
    out
}

/// A GPU or window crate named in the code of a CPU model's file.
fn gpu_crates(module: &str, file: &str, text: &str) -> Vec<String> {
    let mut out = Vec::new();
    if CPU_MODELS.contains(&module) || module.ends_with("::model") {
        for (n, line) in text.lines().enumerate() {
            let code = code_of(line);
            for word in GPU_CRATES {
                let named = code.match_indices(word).any(|(i, _)| {
                    let before = code[..i].chars().last();
                    let after = code[i + word.len()..].chars().next();
                    !before.is_some_and(|c| c.is_alphanumeric() || c == '_')
                        && !after.is_some_and(|c| c.is_alphanumeric() || c == '_')
                });
                if named {
                    out.push(format!(
                        "{file}:{}: the CPU model `{module}` names `{word}`",
                        n + 1
                    ));
                }
            }
        }
    }
    out
}

/// Offences of a file of method `method` (`src/methods/<method>/`,
/// `model` when in its `model/` folder): a method imports no other
/// method, and its model neither its GPU side nor the GPU core.
fn method_offences(method: &str, model: bool, file: &str, text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let code: String = text.lines().map(|l| format!("{}\n", code_of(l))).collect();
    for (i, _) in code.match_indices("crate::methods::") {
        let rest = &code[i + "crate::methods::".len()..];
        let other: String = rest
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        let line = code[..i].matches('\n').count() + 1;
        if other != method && other != "standin" {
            out.push(format!(
                "{file}:{line}: method `{method}` imports method `{other}`"
            ));
        }
        if model && rest[other.len()..].starts_with("::gpu") {
            out.push(format!(
                "{file}:{line}: the model of `{method}` imports its GPU side"
            ));
        }
    }
    if model {
        for (line, target) in crate_paths(text) {
            if NOT_FOR_MODELS.contains(&target.as_str()) && target != "methods" {
                out.push(format!(
                    "{file}:{line}: the model of `{method}` imports `{target}`"
                ));
            }
        }
        out.extend(gpu_crates(&format!("{method}::model"), file, text));
    }
    out
}

/// The import graph between top-level modules (edges in `src/`).
fn graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in files {
        let Some(m) = top_module(src, &f) else {
            continue;
        };
        let text = std::fs::read_to_string(&f).unwrap();
        let targets = g.entry(m.clone()).or_default();
        for (_, t) in crate_paths(&text) {
            if t != m && !t.chars().next().is_some_and(char::is_uppercase) {
                targets.insert(t);
            }
        }
    }
    g
}

/// A cycle of `g`, if any (modules in order, the first repeated last).
fn find_cycle(g: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        n: &str,
        g: &BTreeMap<String, BTreeSet<String>>,
        stack: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(i) = stack.iter().position(|s| s == n) {
            let mut c = stack[i..].to_vec();
            c.push(n.to_string());
            return Some(c);
        }
        if done.contains(n) {
            return None;
        }
        stack.push(n.to_string());
        for m in g.get(n).into_iter().flatten() {
            if let Some(c) = visit(m, g, stack, done) {
                return Some(c);
            }
        }
        stack.pop();
        done.insert(n.to_string());
        None
    }
    let mut done = BTreeSet::new();
    g.keys()
        .find_map(|n| visit(n, g, &mut Vec::new(), &mut done))
}

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

#[test]
fn every_module_imports_only_the_layers_below_it() {
    let src = src();
    let lib = std::fs::read_to_string(src.join("lib.rs")).unwrap();
    let order = layer_order(&lib);
    assert!(
        order.len() >= 15,
        "layer list not found in lib.rs: {order:?}"
    );
    let declared: BTreeSet<String> = lib
        .lines()
        .filter_map(|l| l.strip_prefix("pub mod "))
        .map(|l| l.trim_end_matches(';').to_string())
        .collect();
    let listed: BTreeSet<String> = order.iter().cloned().collect();
    assert_eq!(
        declared, listed,
        "lib.rs's modules and its layer list differ"
    );

    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut all = Vec::new();
    for f in &files {
        if let Some(m) = top_module(&src, f) {
            let text = std::fs::read_to_string(f).unwrap();
            all.extend(offences(&m, &order, &f.display().to_string(), &text));
        }
    }
    assert!(all.is_empty(), "layering offences:\n{}", all.join("\n"));
}

/// The method of a file under `src/methods/<method>/` and whether it is in
/// its `model/` folder.
fn method_of(src: &Path, file: &Path) -> Option<(String, bool)> {
    let rel = file.strip_prefix(src.join("methods")).ok()?;
    let mut parts = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().to_string());
    let method = parts.next()?;
    let next = parts.next()?;
    Some((method, next == "model"))
}

#[test]
fn each_method_stands_alone_and_its_model_needs_no_gpu() {
    let src = src();
    let mut files = Vec::new();
    rust_files(&src.join("methods"), &mut files);
    let mut all = Vec::new();
    let mut models = 0;
    for f in &files {
        if let Some((method, model)) = method_of(&src, f) {
            models += model as usize;
            let text = std::fs::read_to_string(f).unwrap();
            all.extend(method_offences(
                &method,
                model,
                &f.display().to_string(),
                &text,
            ));
        }
    }
    assert!(models >= 10, "found {models} model files");
    assert!(all.is_empty(), "method offences:\n{}", all.join("\n"));
}

#[test]
fn no_import_cycle_between_top_level_modules() {
    let g = graph(&src());
    assert!(g.len() >= 15, "found only {:?}", g.keys());
    if let Some(c) = find_cycle(&g) {
        panic!("import cycle: {}", c.join(" -> "));
    }
}

#[test]
fn the_checker_sees_paths_groups_and_cycles() {
    // It must fail for the reasons the tests above name.
    let order: Vec<String> = ["error", "physics", "render"].map(String::from).to_vec();
    let upward = "use crate::{error::Result, render::{A, B}};\nfn f() { crate::render::x(); }\n";
    let found = offences("physics", &order, "p.rs", upward);
    assert_eq!(found.len(), 4, "{found:?}"); // two upward, two model rule
    assert!(found[0].contains("p.rs:1") && found[0].contains("`render`"));
    assert!(found.iter().any(|o| o.contains("p.rs:2")));
    let commented =
        "// use crate::render::X;\n/// [`crate::render::Y`]\nlet s = 1; // crate::render\n";
    assert!(offences("physics", &order, "p.rs", commented).is_empty());
    let gpu = "fn f(d: &wgpu::Device) {}\nlet wgpu_like = 1;\n";
    assert_eq!(offences("physics", &order, "p.rs", gpu).len(), 1);
    assert!(offences("render", &order, "r.rs", upward).is_empty());
    let cross = "use crate::methods::raymarch::pack;\nuse crate::gpu::GpuContext;\n";
    assert_eq!(method_offences("slices", false, "s.rs", cross).len(), 1);
    let model = "use crate::methods::slices::gpu::X;\nfn f(q: &wgpu::Queue) {}\n";
    assert_eq!(method_offences("slices", true, "m.rs", model).len(), 2);
    assert_eq!(method_offences("slices", true, "m.rs", cross).len(), 2);

    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    g.entry("a".into()).or_default().insert("b".into());
    g.entry("b".into()).or_default().insert("c".into());
    assert!(find_cycle(&g).is_none());
    g.entry("c".into()).or_default().insert("a".into());
    assert_eq!(find_cycle(&g).unwrap(), ["a", "b", "c", "a"]);
}
