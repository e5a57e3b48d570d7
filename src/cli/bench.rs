//! `cumulus bench`.

/// Arguments of `cumulus bench`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `cumulus bench`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("`cumulus bench` is not built yet")
}
