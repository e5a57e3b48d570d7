//! What the world reports: clamp counts, fates, per-frame reports, stage
//! timers and the diagnostics snapshot.

use std::time::Duration;

use super::ParcelWorld;

/// Physical clamps and guards, counted by kind: none of them is silent.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ClampCounts {
    /// Vapour or liquid mixing ratio below zero, set to zero.
    pub negative_humidity: u64,
    /// Radius outside [min_radius_m, max_radius_m].
    pub radius: u64,
    /// Dry mass below 1 kg.
    pub mass: u64,
    /// Saturation vapour pressure capped near es → P (thermo's guard).
    pub saturation_cap: u64,
    /// Entrainment limited to half the parcel's mass in one sub-step (the
    /// explicit mixing step stays a convex mix of parcel and environment).
    pub entrainment: u64,
    /// Detrainment limited to half the dry air in one sub-step.
    pub detrainment: u64,
    /// Pair exchanges bounded so that each parcel keeps at least half its
    /// own air in the mix (no overshoot, no negative humidity).
    pub exchange: u64,
    /// Speed above max_speed_m_s.
    pub speed: u64,
    /// Frames that needed more sub-steps than max_substeps.
    pub substep_budget: u64,
    /// Parcels removed because a state value became NaN or infinite.
    pub non_finite: u64,
    /// Frames with a non-finite or non-positive frame dt (ignored).
    pub bad_frame_dt: u64,
    /// Atmospheric-pressure force capped at the sphere's weighted Archimedes force.
    pub atm_force: u64,
    /// Parcels whose viscous coupling was too strong for the sub-step
    /// (rate × dt > 1) and was scaled down to keep the step stable.
    pub viscosity: u64,
}

impl ClampCounts {
    pub(super) fn add(&mut self, o: &ClampCounts) {
        self.negative_humidity += o.negative_humidity;
        self.radius += o.radius;
        self.mass += o.mass;
        self.saturation_cap += o.saturation_cap;
        self.entrainment += o.entrainment;
        self.detrainment += o.detrainment;
        self.exchange += o.exchange;
        self.speed += o.speed;
        self.substep_budget += o.substep_budget;
        self.non_finite += o.non_finite;
        self.bad_frame_dt += o.bad_frame_dt;
        self.atm_force += o.atm_force;
        self.viscosity += o.viscosity;
    }

    /// Both added (a reduction of per-parcel counts: integer sums do not
    /// depend on the order, so parallel counts are exact).
    pub(super) fn sum(mut a: ClampCounts, b: ClampCounts) -> ClampCounts {
        a.add(&b);
        a
    }

    /// Every kind with its count, in a fixed order (names as the fields).
    pub fn kinds(&self) -> [(&'static str, u64); 13] {
        [
            ("negative_humidity", self.negative_humidity),
            ("radius", self.radius),
            ("mass", self.mass),
            ("saturation_cap", self.saturation_cap),
            ("entrainment", self.entrainment),
            ("detrainment", self.detrainment),
            ("exchange", self.exchange),
            ("speed", self.speed),
            ("substep_budget", self.substep_budget),
            ("non_finite", self.non_finite),
            ("bad_frame_dt", self.bad_frame_dt),
            ("atm_force", self.atm_force),
            ("viscosity", self.viscosity),
        ]
    }

    /// Sum of all counters.
    pub fn total(&self) -> u64 {
        self.kinds().iter().map(|(_, n)| n).sum()
    }
}

/// "speed 12, radius 3" (the kinds that were hit), or "none".
impl std::fmt::Display for ClampCounts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut first = true;
        for (k, n) in self.kinds().iter().filter(|(_, n)| *n > 0) {
            write!(f, "{}{k} {n}", if first { "" } else { ", " })?;
            first = false;
        }
        if first {
            write!(f, "none")?;
        }
        Ok(())
    }
}

/// Births, deaths and escapes.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Fates {
    /// Parcels emitted by the ground.
    pub emitted: u64,
    /// Emissions skipped because max_parcels were alive.
    pub suppressed: u64,
    /// Left through the sides of the domain.
    pub escaped_sides: u64,
    /// Left through the top of the domain or of the environment profile.
    pub escaped_top: u64,
    /// Died after losing their cloud: once cloudy, now without liquid water,
    /// sinking, and more than `death_depth_m` below their condensation plane.
    pub evaporated: u64,
    /// Sank with their centre below the ground.
    pub grounded: u64,
    /// Older than max_age_s.
    pub aged: u64,
}

impl Fates {
    /// Both added (for reductions).
    pub(super) fn sum(mut a: Fates, b: Fates) -> Fates {
        a.add(&b);
        a
    }

    pub(super) fn add(&mut self, o: &Fates) {
        self.emitted += o.emitted;
        self.suppressed += o.suppressed;
        self.escaped_sides += o.escaped_sides;
        self.escaped_top += o.escaped_top;
        self.evaporated += o.evaporated;
        self.grounded += o.grounded;
        self.aged += o.aged;
    }
}

/// What one frame did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepReport {
    /// Sub-steps taken.
    pub substeps: u32,
    /// Sub-step length. units: s
    pub dt_s: f64,
    /// Whether the sub-step budget capped this frame (dt then exceeds the limits).
    pub budget_hit: bool,
    /// Clamps in this frame.
    pub clamps: ClampCounts,
    /// Births and deaths in this frame.
    pub fates: Fates,
    /// Parcels shown fully opaque at this frame's end (see
    /// [`Diagnostics::opaque_parcel_frames`]).
    pub opaque_parcels: u64,
}

/// Per-stage CPU time and work counts (cumulative).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Counters {
    pub neighbours: Duration,
    pub sph: Duration,
    pub exposed_area: Duration,
    pub mixing: Duration,
    pub thermo: Duration,
    pub integrate: Duration,
    /// Parcels whose sphere was tessellated (one per parcel with an
    /// overlapping neighbour per sub-step).
    pub exposed_area_evaluations: u64,
    /// Quad-in-neighbour tests done.
    pub quads_tested: u64,
    /// Frames stepped.
    pub frames: u64,
    /// Sub-steps taken.
    pub substeps: u64,
}

/// A snapshot summary of the world.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Diagnostics {
    /// Simulated time. units: s
    pub time_s: f64,
    pub parcels: usize,
    pub condensed_parcels: usize,
    /// Lowest condensation plane of the condensed parcels. units: m
    pub cloud_base_m: Option<f64>,
    /// Highest sphere top of the condensed parcels. units: m
    pub cloud_top_m: Option<f64>,
    /// Vapour and liquid water in all parcels. units: kg
    pub total_water_kg: f64,
    /// Σ ½ m v². units: J
    pub kinetic_energy_j: f64,
    /// Sub-steps of the last frame.
    pub substeps: u32,
    /// Cumulative clamps.
    pub clamps: ClampCounts,
    /// Parcel-frames whose liquid water content exceeded the opaque
    /// content, so that the filling ratio shows 1 (cumulative). A display
    /// saturation, not a physics clamp: the physics keeps all the water, so
    /// it is kept out of [`ClampCounts`] and its total (a 3-hour trade-wind
    /// run counts 1.7 million of these).
    pub opaque_parcel_frames: u64,
    /// Cumulative births and deaths.
    pub fates: Fates,
    /// Parcels that left the domain (sides + top), cumulative.
    pub escaped: u64,
}

impl ParcelWorld {
    /// Summary of the current state.
    pub fn diagnostics(&self) -> Diagnostics {
        let mut d = Diagnostics {
            time_s: self.time_s,
            parcels: self.parcels.len(),
            substeps: self.last_substeps,
            clamps: self.clamps,
            opaque_parcel_frames: self.opaque_parcel_frames,
            fates: self.fates,
            escaped: self.fates.escaped_sides + self.fates.escaped_top,
            ..Diagnostics::default()
        };
        for p in &self.parcels {
            d.total_water_kg += p.water_kg();
            d.kinetic_energy_j += 0.5 * p.total_mass_kg() * p.velocity_m_s.length_squared();
            if p.is_condensed() {
                d.condensed_parcels += 1;
                let base = p.cond_plane_z_m;
                let top = p.position_m.z + p.radius_m;
                d.cloud_base_m = Some(d.cloud_base_m.map_or(base, |b: f64| b.min(base)));
                d.cloud_top_m = Some(d.cloud_top_m.map_or(top, |t: f64| t.max(top)));
            }
        }
        d
    }
}

/// Most raster cells along a side of the ground for [`ParcelWorld::cloud_cover`].
const COVER_CELLS_MAX: f64 = 1000.0;
/// Finest raster cell of [`ParcelWorld::cloud_cover`]. units: m
const COVER_CELL_MIN_M: f64 = 25.0;

impl ParcelWorld {
    /// Cloud cover: the fraction of the ground's area under cloud seen from
    /// straight above, as LES report it (columns with any liquid water).
    /// Each condensed parcel covers the horizontal projection of its sphere
    /// above its condensation plane (what the renderer fills): a disk of
    /// radius r, or √(r² − (z_c − z)²) where the plane cuts the sphere
    /// above its centre. Rasterised on cells of 25 m (coarser on grounds
    /// wider than 25 km: 1000 cells a side), counting a cell whose centre
    /// is covered. units: 1
    pub fn cloud_cover(&self) -> f64 {
        let size = self.cfg.ground.size_m;
        let cell = COVER_CELL_MIN_M.max(size[0].max(size[1]) / COVER_CELLS_MAX);
        let (nx, ny) = (
            (size[0] / cell).ceil() as usize,
            (size[1] / cell).ceil() as usize,
        );
        let mut covered = vec![false; nx * ny];
        let (x0, y0) = (-0.5 * size[0], -0.5 * size[1]);
        for p in self.parcels.iter().filter(|p| p.is_condensed()) {
            let above = p.cond_plane_z_m - p.position_m.z;
            let r2 = p.radius_m * p.radius_m - above.max(0.0).powi(2);
            if r2 <= 0.0 {
                continue;
            }
            let r = r2.sqrt();
            let (cx, cy) = (p.position_m.x, p.position_m.y);
            let span = |c: f64, lo: f64, n: usize| {
                let a = ((c - r - lo) / cell).floor().max(0.0) as usize;
                let b = (((c + r - lo) / cell).ceil().max(0.0) as usize).min(n);
                a..b
            };
            for j in span(cy, y0, ny) {
                let y = y0 + (j as f64 + 0.5) * cell - cy;
                for i in span(cx, x0, nx) {
                    let x = x0 + (i as f64 + 0.5) * cell - cx;
                    if x * x + y * y <= r2 {
                        covered[j * nx + i] = true;
                    }
                }
            }
        }
        covered.iter().filter(|&&c| c).count() as f64 / covered.len() as f64
    }

    /// Liquid water path: the liquid water of all parcels per unit area of
    /// the ground, the domain mean LES report. units: kg m⁻²
    pub fn liquid_water_path(&self) -> f64 {
        let size = self.cfg.ground.size_m;
        let liquid: f64 = self
            .parcels
            .iter()
            .map(|p| p.dry_mass_kg * p.ql_kg_per_kg)
            .sum();
        liquid / (size[0] * size[1])
    }
}
