//! The layering of DESIGN.md §1: the atmosphere and the physics never import
//! the GPU or the window, so they build, run and test without either, and the
//! renderer reads only their output.

use std::path::Path;

fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

#[test]
fn atmosphere_and_physics_import_no_gpu_or_window_code() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let forbidden = [
        "wgpu",
        "naga",
        "winit",
        "egui",
        "crate::render",
        "crate::app",
    ];
    let mut files = Vec::new();
    for layer in ["atmosphere", "physics", "authored"] {
        rust_files(&root.join(layer), &mut files);
    }
    assert!(files.len() >= 8, "found only {files:?}");
    let mut offences = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            for word in forbidden {
                if code.contains(word) {
                    offences.push(format!("{}:{}: {}", f.display(), n + 1, line.trim()));
                }
            }
        }
    }
    assert!(
        offences.is_empty(),
        "GPU/window code in a CPU layer:\n{}",
        offences.join("\n")
    );
}
