//! `cumulus watch`.

/// Arguments of `cumulus watch`.
#[derive(Debug, Default, clap::Args)]
pub struct Args {}

/// Runs `cumulus watch`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("`cumulus watch` is not built yet")
}
