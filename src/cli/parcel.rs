//! `cumulus parcel`.

/// Arguments of `cumulus parcel`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `cumulus parcel`.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("`cumulus parcel` is not built yet")
}
