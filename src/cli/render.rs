//! `cumulus render`.

/// Arguments of `cumulus render`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `cumulus render`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("`cumulus render` is not built yet")
}
