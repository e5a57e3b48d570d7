//! The README's command lines run as written. Every line of a ```sh block
//! that starts with `cargo run --release --` or `cumulus ` is run with the
//! built binary, except those that open a window (`watch` without
//! `--screenshot`), with only these rewrites so the run stays short:
//! `--width`/`--height` become 64×48 (and `render`, `watch` and
//! `bench --gpu-check` get them when absent), `--duration` is cut to 120 s and `--time` to 600 s, output
//! files (`--out`, `--plot`, `--csv`, `--save-parcels`, `--screenshot`) go
//! into a temporary folder, and `bench` (but `--gpu-check`) runs `--tiny`
//! instead of `--quick` or its full run. Each must exit 0.

use std::path::Path;

use crate::common;
use crate::common::cli;

/// One README command line: its line number and the arguments after the
/// binary's name.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadmeCommand {
    pub line: usize,
    pub text: String,
    pub args: Vec<String>,
}

/// Splits a shell line into words (plain words, '…' and "…" quotes).
fn shell_words(line: &str) -> Vec<String> {
    let mut words = Vec::new();
    let mut word = String::new();
    let mut in_word = false;
    let mut quote: Option<char> = None;
    for c in line.chars() {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), c) => word.push(c),
            (None, '\'' | '"') => {
                quote = Some(c);
                in_word = true;
            }
            (None, c) if c.is_whitespace() => {
                if in_word {
                    words.push(std::mem::take(&mut word));
                    in_word = false;
                }
            }
            (None, c) => {
                word.push(c);
                in_word = true;
            }
        }
    }
    if in_word {
        words.push(word);
    }
    words
}

/// The line without a trailing `# comment` (a `#` that starts a word).
fn strip_comment(line: &str) -> &str {
    let mut prev_space = true;
    for (i, c) in line.char_indices() {
        if c == '#' && prev_space {
            return &line[..i];
        }
        prev_space = c.is_whitespace();
    }
    line
}

/// The cumulus command lines of the ```sh blocks of a README, joined
/// across `\` continuations, those that open a window left out.
pub fn readme_commands(readme: &str) -> Vec<ReadmeCommand> {
    let mut out = Vec::new();
    let mut in_sh = false;
    let mut pending: Option<(usize, String)> = None;
    for (i, raw) in readme.lines().enumerate() {
        let trimmed = raw.trim();
        if trimmed.starts_with("```") {
            in_sh = !in_sh && trimmed == "```sh";
            pending = None;
            continue;
        }
        if !in_sh {
            continue;
        }
        let (start, mut text) = match pending.take() {
            Some((start, text)) => (start, text + " " + trimmed),
            None => (i + 1, trimmed.to_string()),
        };
        if let Some(head) = text.strip_suffix('\\') {
            text = head.trim_end().to_string();
            pending = Some((start, text));
            continue;
        }
        let line = strip_comment(&text).trim().to_string();
        let rest = if let Some(r) = line.strip_prefix("cargo run --release -- ") {
            r
        } else if let Some(r) = line.strip_prefix("cumulus ") {
            r
        } else {
            continue; // cargo test, cargo build, cargo run without a command, pip, python3
        };
        let args = shell_words(rest);
        let window =
            args.first().is_none_or(|a| a == "watch") && !args.iter().any(|a| a == "--screenshot");
        if window {
            continue;
        }
        out.push(ReadmeCommand {
            line: start,
            text: line,
            args,
        });
    }
    out
}

/// Options whose value is a file the command writes.
const OUTPUTS: &[&str] = &["--out", "--plot", "--csv", "--save-parcels", "--screenshot"];

/// The arguments to run for `args`, with the rewrites of the module docs;
/// outputs go under `tmp`.
pub fn rewrite(args: &[String], tmp: &Path) -> Vec<String> {
    let sub = args.first().map(String::as_str).unwrap_or("");
    let mut out: Vec<String> = Vec::new();
    let mut it = args.iter().peekable();
    let (mut width, mut height) = (false, false);
    while let Some(a) = it.next() {
        let (flag, inline) = match a.split_once('=') {
            Some((f, v)) if f.starts_with("--") => (f.to_string(), Some(v.to_string())),
            _ => (a.clone(), None),
        };
        let takes_value = ["--width", "--height", "--duration", "--time"].contains(&flag.as_str())
            || OUTPUTS.contains(&flag.as_str());
        if !takes_value {
            if !(sub == "bench" && flag == "--quick") {
                out.push(a.clone());
            }
            continue;
        }
        let value = inline.or_else(|| it.next().cloned()).unwrap_or_default();
        let cap = |v: &str, max: f64| {
            let x: f64 = v.parse().unwrap_or(max);
            format!("{}", x.min(max))
        };
        let value = match flag.as_str() {
            "--width" => {
                width = true;
                "64".to_string()
            }
            "--height" => {
                height = true;
                "48".to_string()
            }
            "--duration" => cap(&value, 120.0),
            "--time" => cap(&value, 600.0),
            _ => {
                let name = Path::new(&value).file_name().unwrap_or_default();
                tmp.join(name).to_string_lossy().into_owned()
            }
        };
        out.push(flag);
        out.push(value);
    }
    let gpu_check = sub == "bench" && out.iter().any(|a| a == "--gpu-check");
    if matches!(sub, "render" | "watch") || gpu_check {
        if !width {
            out.extend(["--width".to_string(), "64".to_string()]);
        }
        if !height {
            out.extend(["--height".to_string(), "48".to_string()]);
        }
    }
    if sub == "bench" && !gpu_check && !out.iter().any(|a| a == "--tiny") {
        out.push("--tiny".to_string());
    }
    out
}

/// Runs each command (rewritten into `tmp`); the failures, each naming the
/// README line, the command run and its stderr.
pub fn failures(commands: &[ReadmeCommand], tmp: &Path) -> Vec<String> {
    let mut failed = Vec::new();
    for c in commands {
        let args = rewrite(&c.args, tmp);
        let run = cli::run(&args);
        let panicked = run.stderr().contains("panicked");
        if !run.succeeded() || panicked {
            failed.push(format!(
                "README.md:{}: `{}`\n  ran: cumulus {}\n  {}\n  stderr:\n{}",
                c.line,
                c.text,
                args.join(" "),
                run.output.status,
                run.stderr()
            ));
        }
    }
    failed
}

#[test]
fn readme_commands_run_and_exit_0() {
    let readme = std::fs::read_to_string(super::root().join("README.md")).unwrap();
    let commands = readme_commands(&readme);
    // The tour shows every headless command; a parser that found nothing
    // would pass vacuously.
    for sub in [
        "render",
        "parcel",
        "simulate",
        "export",
        "bench",
        "stability",
        "atlas",
    ] {
        assert!(
            commands
                .iter()
                .any(|c| c.args.first().is_some_and(|a| a == sub)),
            "no `{sub}` command line in a ```sh block of README.md (found: {:?})",
            commands.iter().map(|c| &c.text).collect::<Vec<_>>()
        );
    }
    // The render commands need an adapter: the GPU tests' policy.
    let Some(_ctx) = common::context("README command lines") else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let failed = failures(&commands, tmp.path());
    assert!(
        failed.is_empty(),
        "{} of {} README command lines failed:\n{}",
        failed.len(),
        commands.len(),
        failed.join("\n")
    );
}

#[test]
fn readme_command_lines_are_found_and_rewritten_short() {
    let readme = "\
text `cargo run --release -- render --out not_in_a_block.png`
```sh
cargo run --release
cargo run --release -- watch profiles/x.toml
cargo test --release
cargo run --release -- render profiles/a.toml --width 960 --out pics/a.png   # a comment
cargo run --release -- parcel --sounding s.txt \\
    --dynamic --duration 3600 --csv t.csv
cumulus bench --quick --out report
cumulus watch --screenshot shot.png --frames 60
```
```toml
cumulus render --out toml_block.png
```
";
    let found = readme_commands(readme);
    let lines: Vec<usize> = found.iter().map(|c| c.line).collect();
    assert_eq!(lines, vec![6, 7, 9, 10], "{found:#?}");
    let tmp = Path::new("/tmp/t");
    let words = |s: &str| s.split(' ').map(String::from).collect::<Vec<_>>();
    assert_eq!(
        rewrite(&found[0].args, tmp),
        words("render profiles/a.toml --width 64 --out /tmp/t/a.png --height 48")
    );
    assert_eq!(
        rewrite(&found[1].args, tmp),
        words("parcel --sounding s.txt --dynamic --duration 120 --csv /tmp/t/t.csv")
    );
    assert_eq!(
        rewrite(&found[2].args, tmp),
        words("bench --out /tmp/t/report --tiny")
    );
    assert_eq!(
        rewrite(&found[3].args, tmp),
        words("watch --screenshot /tmp/t/shot.png --frames 60 --width 64 --height 48")
    );
    assert_eq!(
        rewrite(&words("bench --gpu-check --out gc"), tmp),
        words("bench --gpu-check --out /tmp/t/gc --width 64 --height 48")
    );
}

/// A command line that fails is reported with its README line and stderr
/// (no GPU needed: the sounding is missing).
#[test]
fn a_failing_readme_command_is_reported_with_its_line_and_stderr() {
    let readme = "```sh\ncumulus parcel --sounding profiles/soundings/no_such_file.txt\n```\n";
    let commands = readme_commands(readme);
    let tmp = tempfile::tempdir().unwrap();
    let failed = failures(&commands, tmp.path());
    assert_eq!(failed.len(), 1, "{failed:?}");
    assert!(
        failed[0].contains("README.md:2:") && failed[0].contains("no_such_file.txt"),
        "{}",
        failed[0]
    );
}
