//! `cumulus simulate`.

/// Arguments of `cumulus simulate`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `cumulus simulate`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("`cumulus simulate` is not built yet")
}
