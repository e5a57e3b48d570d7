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
            &"" => format!(".{ext}"),
            w => format!(".{ext} ({w})"),
        })
        .collect();
    anyhow::bail!(
        "invalid {flag} {}: the file name must end in {}",
        path.display(),
        names.join(" or ")
    )
}

/// Checks, before any work, that the output file `path` (the value of
/// `flag`) can be written (`cumulus::output::check_writable`): the error
/// names the option and the path as given, and says what is wrong.
pub fn writable_output(flag: &str, path: &Path) -> anyhow::Result<()> {
    named_output(flag, path, cumulus::output::check_writable(path))
}

/// [`writable_output`] for an option naming a folder that files are
/// written into (`cumulus::output::check_folder_writable`).
pub fn writable_folder(flag: &str, dir: &Path) -> anyhow::Result<()> {
    named_output(flag, dir, cumulus::output::check_folder_writable(dir))
}

fn named_output(flag: &str, path: &Path, checked: cumulus::Result<()>) -> anyhow::Result<()> {
    match checked {
        Err(cumulus::Error::Io { source, .. }) => {
            anyhow::bail!("invalid {flag} {}: {source}", path.display())
        }
        other => Ok(other?),
    }
}
