//! Export of one frame's cloud density to other renderers: a density (the
//! field of paper eq. 18, [`CloudField`], the CPU mirror of
//! shaders/raymarch/density.wgsl; for authored scenes, the `slices`
//! method's field of `methods::slices::gpu::field`) sampled on a regular grid at
//! cell centres, written as Mitsuba 3's `gridvolume` `.vol` ([`vol`]) with
//! a JSON sidecar ([`sidecar`]) giving the world box, camera, sun, sky,
//! phase function, albedo and extinction scale the renderer assumes, so a
//! path tracer can draw the same picture.
//!
//! Memory is stated before anything is allocated and capped: the default
//! voxel gives way to the finest that fits ([`GridSpec::fitting`], said on
//! stderr); a voxel asked for that does not fit is an error naming the
//! voxel size that would ([`GridSpec::covering`]).
//! Deterministic: every value is a pure function of its cell centre, so the
//! parallel sampling (rayon, by z slab) writes the same bytes on any
//! thread count.

pub mod sidecar;
pub mod vdb;
pub mod vol;

use glam::Vec3;
use rayon::prelude::*;

use crate::config::RenderConfig;
use crate::error::{Error, Result};
use crate::methods::raymarch::field::{CloudField, PLANE_SHELL};
use crate::noise;

pub use vol::{VolGrid, read_vol, write_vol};

/// The grid file formats `export` writes, chosen by the file's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GridFormat {
    /// Mitsuba 3's `gridvolume` ([`vol`]): dense float32.
    Vol,
    /// OpenVDB ([`vdb`]): a sparse float grid named `density`.
    Vdb,
}

impl GridFormat {
    /// The format of a file named `name` (`.vol` or `.vdb`, any case); None
    /// for any other name.
    pub fn of_path(path: &std::path::Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "vol" => Some(Self::Vol),
            "vdb" => Some(Self::Vdb),
            _ => None,
        }
    }

    /// [`GridFormat::of_path`] of a file name; `.vol` for any other.
    pub fn of_name(name: &str) -> Self {
        Self::of_path(std::path::Path::new(name)).unwrap_or(Self::Vol)
    }

    /// What the file's values are (the sidecar's `volume.values`).
    pub fn describe(self) -> &'static str {
        match self {
            Self::Vol => {
                "cloud density rho in [0, 1] of paper eq. 18 (noise included) at cell centres, \
                 x fastest; Mitsuba 3 gridvolume, float32, one channel"
            }
            Self::Vdb => {
                "cloud density rho in [0, 1] of paper eq. 18 (noise included); OpenVDB float grid \
                 'density' (class fog volume), sparse 8^3 leaves where rho > 0; index (i, j, k) \
                 is the cell centre bounds_min_m + voxel_m (i + 1/2, j + 1/2, k + 1/2) \
                 (UniformScaleTranslateMap)"
            }
        }
    }

    /// Writes `values` (x fastest over `spec`) in this format; `meta` goes
    /// into a `.vdb`'s grid metadata.
    pub fn write(
        self,
        w: &mut dyn std::io::Write,
        spec: &GridSpec,
        values: Vec<f32>,
        meta: &[(&str, vdb::Meta)],
    ) -> std::io::Result<()> {
        match self {
            Self::Vol => write_vol(w, &vol_grid(spec, values)),
            Self::Vdb => vdb::write_vdb(w, spec, &values, meta),
        }
    }
}

/// Default cap on the grid's memory (the values in RAM, and as much again
/// in the file). units: MiB
pub const DEFAULT_MAX_MEMORY_MIB: u64 = 2048;
/// Smallest voxel accepted (a 10 km cloud layer at 1 m is 10¹² cells:
/// the memory cap would refuse it anyway). units: m
pub const MIN_VOXEL_M: f32 = 0.5;

/// A regular grid of cubic voxels: `dims` cells of side `voxel_m` from `min`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridSpec {
    /// Lowest corner. units: m
    pub min: Vec3,
    /// Cell side. units: m
    pub voxel_m: f32,
    /// Cells along x, y, z.
    pub dims: [u32; 3],
}

impl GridSpec {
    /// The smallest grid of `voxel_m` cells from `min` that covers `max`;
    /// errors name `--voxel` for a non-finite, too small value or a grid
    /// over `max_memory_mib` (naming the smallest voxel that fits).
    pub fn covering(min: Vec3, max: Vec3, voxel_m: f32, max_memory_mib: u64) -> Result<Self> {
        check_voxel(voxel_m)?;
        let (dims, mib) = Self::size(min, max, voxel_m);
        if fits(dims, mib, max_memory_mib) {
            return Ok(Self::of(min, voxel_m, dims));
        }
        let fitting = Self::fitting(min, max, voxel_m, max_memory_mib)?.voxel_m;
        // Rounded up to what the message prints: that size fits too
        // (fewer cells as the voxel grows).
        let named = (fitting * 10.0).ceil() / 10.0;
        Err(Error::invalid(
            "--voxel",
            voxel_m,
            format!(
                "a grid of {:.0}×{:.0}×{:.0} cells needs {mib:.0} MiB, over the {max_memory_mib} MiB \
                 limit (--max-memory-mib); a voxel of {named:.1} m or more fits",
                dims.x, dims.y, dims.z,
            ),
        ))
    }

    /// The grid of the finest voxel, `wanted_m` or coarser (to about 1 %), that
    /// covers `min`..`max` within `max_memory_mib`: how a default voxel
    /// gives way to a large field. [`GridSpec::coarsening_note`] says so.
    pub fn fitting(min: Vec3, max: Vec3, wanted_m: f32, max_memory_mib: u64) -> Result<Self> {
        check_voxel(wanted_m)?;
        if max_memory_mib == 0 {
            return Err(Error::invalid("--max-memory-mib", 0, "at least 1 MiB"));
        }
        let mut voxel_m = wanted_m;
        loop {
            let (dims, mib) = Self::size(min, max, voxel_m);
            if fits(dims, mib, max_memory_mib) {
                return Ok(Self::of(min, voxel_m, dims));
            }
            // Cells ∝ 1/voxel³; the ceil of each axis may need a step more.
            let ratio = (mib / max_memory_mib as f64)
                .cbrt()
                .max(dims.max_element() as f64 / i32::MAX as f64)
                .max(1.01);
            voxel_m *= ratio as f32;
        }
    }

    /// What to tell the user when the memory cap made the voxel coarser
    /// than `wanted_m` (the wording of the baked field's
    /// `BakeInfo::coarsening_note`); None when it did not.
    pub fn coarsening_note(&self, wanted_m: f32, max_memory_mib: u64) -> Option<String> {
        (self.voxel_m > wanted_m).then(|| {
            format!(
                "the export uses {:.1} m voxels instead of {wanted_m:.1} m to stay within \
                 --max-memory-mib {max_memory_mib} (clouds cover a large region; --voxel forces a size)",
                self.voxel_m
            )
        })
    }

    /// Cells per axis (as floats: a tiny voxel must not overflow u32) and
    /// the values' memory (MiB) of `voxel_m` cells over `min`..`max`.
    fn size(min: Vec3, max: Vec3, voxel_m: f32) -> (Vec3, f64) {
        let extent = (max - min).max(Vec3::splat(voxel_m));
        let dims = (extent / voxel_m).ceil();
        let cells = dims.x as f64 * dims.y as f64 * dims.z as f64;
        (dims, cells * 4.0 / (1024.0 * 1024.0))
    }

    fn of(min: Vec3, voxel_m: f32, dims: Vec3) -> Self {
        Self {
            min,
            voxel_m,
            dims: [dims.x as u32, dims.y as u32, dims.z as u32],
        }
    }

    /// Highest corner. units: m
    pub fn max(&self) -> Vec3 {
        self.min
            + self.voxel_m
                * Vec3::new(
                    self.dims[0] as f32,
                    self.dims[1] as f32,
                    self.dims[2] as f32,
                )
    }

    /// Number of cells.
    pub fn cells(&self) -> u64 {
        self.dims.iter().map(|&d| d as u64).product()
    }

    /// Memory of the values (float32). units: bytes
    pub fn bytes(&self) -> u64 {
        4 * self.cells()
    }

    /// Centre of cell (x, y, z). units: m
    pub fn centre(&self, x: u32, y: u32, z: u32) -> Vec3 {
        self.min + self.voxel_m * (Vec3::new(x as f32, y as f32, z as f32) + Vec3::splat(0.5))
    }
}

/// A voxel side the grids accept: finite, at least [`MIN_VOXEL_M`].
fn check_voxel(voxel_m: f32) -> Result<()> {
    if voxel_m.is_finite() && voxel_m >= MIN_VOXEL_M {
        return Ok(());
    }
    Err(Error::invalid(
        "--voxel",
        voxel_m,
        format!("a voxel side of at least {MIN_VOXEL_M} m"),
    ))
}

/// Whether a grid of `dims` cells taking `mib` MiB is within the cap (and
/// each axis within the `.vol` header's i32).
fn fits(dims: Vec3, mib: f64, max_memory_mib: u64) -> bool {
    mib <= max_memory_mib as f64 && dims.max_element() <= i32::MAX as f32
}

/// Default voxel side for `cfg` and the packed parcels of `field`.
///
/// The renderer samples ρ every `step_m` along a view ray, so detail finer
/// than step/2 is not in its picture either (Nyquist of its own sampling);
/// the finest noise fetch's texel (tile / texels, divided by the second
/// fetch's scale when octaves 5–6 are on) is the lower bound when it is
/// coarser than that. Capped so the shapes the
/// renderer does resolve stay resolved: half the condensation plane's shell
/// (the flat base's soft edge, PLANE_SHELL·shell) and a quarter of the
/// smallest rendered parcel radius. units: m
pub fn default_voxel_m(cfg: &RenderConfig, field: &CloudField) -> f32 {
    let second_fetch = if cfg.noise_octaves > noise::CHANNELS {
        noise::SECOND_FETCH_SCALE
    } else {
        1.0
    };
    let finest_texel_m = cfg.noise_scale_m / cfg.noise_texels as f32 / second_fetch;
    let sampling = (0.5 * cfg.step_m).max(0.5 * finest_texel_m);
    let base_edge = 0.5 * PLANE_SHELL * cfg.shell_m;
    let smallest_radius = field
        .parcels()
        .iter()
        .map(|p| p.radius_m)
        .fold(f32::INFINITY, f32::min);
    sampling
        .min(base_edge)
        .min(0.25 * smallest_radius)
        .max(MIN_VOXEL_M)
}

/// ρ at every cell centre of `spec` (x fastest), `progress(done, total)`
/// called after each slab of z slices. Same values on any thread count.
pub fn sample_grid(
    spec: &GridSpec,
    density: impl Fn(Vec3) -> f32 + Sync,
    mut progress: impl FnMut(u64, u64),
) -> Vec<f32> {
    let [nx, ny, nz] = spec.dims;
    let slice = (nx as usize) * (ny as usize);
    let mut values = vec![0.0f32; slice * nz as usize];
    // Slabs of z slices big enough to keep every thread busy, small enough
    // for the progress bar to move.
    let slab = (nz as usize).div_ceil(64).max(1);
    let total = spec.cells();
    let mut done = 0u64;
    for (s, chunk) in values.chunks_mut(slice * slab).enumerate() {
        chunk
            .par_chunks_mut(nx as usize)
            .enumerate()
            .for_each(|(row, out)| {
                let z = (s * slab + row / ny as usize) as u32;
                let y = (row % ny as usize) as u32;
                for (x, v) in out.iter_mut().enumerate() {
                    *v = density(spec.centre(x as u32, y, z));
                }
            });
        done += chunk.len() as u64;
        progress(done, total);
    }
    values
}

/// `spec`'s grid of ρ as a `.vol` grid.
pub fn vol_grid(spec: &GridSpec, values: Vec<f32>) -> VolGrid {
    VolGrid {
        dims: spec.dims,
        min: spec.min.to_array(),
        max: spec.max().to_array(),
        values,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_covers_the_box_and_states_memory() {
        let g = GridSpec::covering(Vec3::ZERO, Vec3::new(100.0, 50.0, 10.0), 20.0, 1).unwrap();
        assert_eq!(g.dims, [5, 3, 1]);
        assert_eq!(g.max(), Vec3::new(100.0, 60.0, 20.0));
        assert_eq!(g.bytes(), 4 * 15);
        assert_eq!(g.centre(0, 0, 0), Vec3::splat(10.0));
    }

    #[test]
    fn too_big_or_bad_voxels_are_errors() {
        let e = GridSpec::covering(Vec3::ZERO, Vec3::splat(10_000.0), 1.0, 64)
            .unwrap_err()
            .to_string();
        assert!(e.contains("--max-memory-mib") && e.contains("fits"), "{e}");
        for v in [0.0, -3.0, f32::NAN, f32::INFINITY] {
            let e = GridSpec::covering(Vec3::ZERO, Vec3::ONE, v, 64).unwrap_err();
            assert!(e.to_string().contains("--voxel"), "{e}");
        }
    }

    #[test]
    fn a_default_voxel_gives_way_to_the_finest_that_fits() {
        let (lo, hi) = (Vec3::ZERO, Vec3::new(40_000.0, 40_000.0, 1_500.0));
        // 20 m over 40 km × 40 km × 1.5 km: 3·10⁸ cells, 1.1 GiB; cap 64 MiB.
        assert!(GridSpec::covering(lo, hi, 20.0, 64).is_err());
        let g = GridSpec::fitting(lo, hi, 20.0, 64).unwrap();
        assert!(g.bytes() <= 64 << 20, "{g:?}");
        // The finest to 1 %: 1 % finer does not fit.
        assert!(GridSpec::covering(lo, hi, g.voxel_m / 1.01, 64).is_err());
        let note = g.coarsening_note(20.0, 64).unwrap();
        assert!(
            note.contains("instead of 20.0 m") && note.contains("--voxel"),
            "{note}"
        );
        // A voxel that fits is kept, and nothing is said.
        let same = GridSpec::fitting(lo, hi, 500.0, 64).unwrap();
        assert_eq!(same, GridSpec::covering(lo, hi, 500.0, 64).unwrap());
        assert_eq!(same.coarsening_note(500.0, 64), None);
        // The size a refused --voxel names does fit.
        let e = GridSpec::covering(lo, hi, 20.0, 64)
            .unwrap_err()
            .to_string();
        let named: f32 = e
            .split("a voxel of ")
            .nth(1)
            .and_then(|t| t.split(' ').next())
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("no size named: {e}"));
        assert!(GridSpec::covering(lo, hi, named, 64).is_ok(), "{e}");
        assert!(GridSpec::fitting(lo, hi, 20.0, 0).is_err());
    }

    #[test]
    fn sampling_is_ordered_x_fastest() {
        let g = GridSpec::covering(Vec3::ZERO, Vec3::new(3.0, 2.0, 5.0), 1.0, 1).unwrap();
        let mut calls = 0;
        let v = sample_grid(
            &g,
            |p| p.x + 10.0 * p.y + 100.0 * p.z,
            |d, t| {
                calls += 1;
                assert!(d <= t);
            },
        );
        assert!(calls >= 1);
        assert_eq!(v.len(), 30);
        assert_eq!(v[1], 1.5 + 5.0 + 50.0);
        assert_eq!(v[3], 0.5 + 15.0 + 50.0);
        assert_eq!(v[6], 0.5 + 5.0 + 150.0);
    }
}
