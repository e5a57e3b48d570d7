//! `cumulus stability`.

/// Arguments of `cumulus stability`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `cumulus stability`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("`cumulus stability` is not built yet")
}
