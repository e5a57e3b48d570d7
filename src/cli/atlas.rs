//! `cumulus atlas`: writes the sprite method's 16-tile texture sheet (Wang
//! 2003 §3.2, generated from our own noise) as a PNG, the same sheet the
//! renderer uploads.

use std::path::PathBuf;

use anyhow::Context as _;
use cumulus::methods::sprites::gpu::atlas::{ATLAS_SEED, TILE_TEXELS};
use cumulus::methods::sprites::model::Atlas;

/// Arguments of `cumulus atlas`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Output PNG (4 × 4 tiles: foggy ×3 and the flat bottom on top, then
    /// six wispy and six puffy tiles).
    #[arg(long)]
    pub out: PathBuf,
    /// Side of one tile (128 to 1024; the renderer uses 128). units: texels
    #[arg(long, default_value_t = TILE_TEXELS, value_parser = clap::value_parser!(u32).range(128..=1024))]
    pub tile: u32,
    /// Seed of the noise (the renderer uses 1).
    #[arg(long, default_value_t = ATLAS_SEED)]
    pub seed: u32,
}

/// Runs `cumulus atlas`.
pub fn run(args: Args) -> anyhow::Result<()> {
    super::output_extension("--out", &args.out, &[("png", "")])?;
    super::writable_output("--out", &args.out)?;
    let atlas = Atlas::generate(args.tile, args.seed);
    atlas
        .write_png(&args.out)
        .with_context(|| format!("writing the atlas to {}", args.out.display()))?;
    eprintln!(
        "{}: {}² texels, 16 tiles of {}²",
        args.out.display(),
        atlas.size,
        atlas.tile_size()
    );
    Ok(())
}
