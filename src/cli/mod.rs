//! Command-line front end: one module per subcommand, each with its clap
//! `Args` and a `run` function. `main.rs` only dispatches.

pub mod atlas;
pub mod bench;
pub mod export;
pub mod parcel;
mod parcel_report;
pub mod render;
pub mod simulate;
pub mod stability;
pub mod sun_args;
pub mod watch;

use std::path::Path;

/// `--set TABLE.KEY=VALUE`: scene overrides for every command that loads a
/// scene, applied to the TOML and validated exactly like the file
/// (`cumulus::scene::set`).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct SetArgs {
    /// Override a scene value, validated like the file (repeatable), e.g.
    /// `--set physics.mixing=false --set render.method=exact`.
    #[arg(long = "set", value_name = "TABLE.KEY=VALUE")]
    pub set: Vec<String>,
}

/// Whether `path`'s extension is `ext` (any case).
pub fn has_extension(path: &Path, ext: &str) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

/// Refuses, before any work, an output file `path` (the value of `flag`)
/// whose extension is none of `allowed`'s: the format follows the name.
/// `allowed` pairs each extension with what such a file holds ("" when
/// there is one format). Returns the extension found, as `allowed` spells it.
pub fn output_extension(
    flag: &str,
    path: &Path,
    allowed: &[(&'static str, &str)],
) -> anyhow::Result<&'static str> {
    if let Some(&(ext, _)) = allowed.iter().find(|(ext, _)| has_extension(path, ext)) {
        return Ok(ext);
    }
    let names: Vec<String> = allowed
        .iter()
        .map(|(ext, what)| match what {
            w if w.is_empty() => format!(".{ext}"),
            w => format!(".{ext} ({w})"),
        })
        .collect();
    anyhow::bail!(
        "invalid {flag} {}: the file name must end in {}",
        path.display(),
        names.join(" or ")
    )
}
