//! The scene-profile tables the physics owns: `[physics]` (switches,
//! constants, time stepping), `[ground]` (domain and heat/humidity map),
//! `[emission]` (parcel generator) and `[wind]` (wind profile). Every field
//! has a unit and a default; `validate` names a bad field and its allowed
//! range.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Checks that `value` is finite and inside `[lo, hi]`: the one range
/// validator of the physics (tables and spawned parcels alike).
pub(crate) fn check(name: &str, value: f64, lo: f64, hi: f64) -> Result<()> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(())
    } else {
        Err(Error::invalid(
            name,
            value,
            format!("a finite number between {lo} and {hi}"),
        ))
    }
}

/// Physics switches and constants (the `[physics]` table).
///
/// Every term of paper Algorithm 1 has a switch; a switched-off term costs
/// nothing. With `mixing` and `atmospheric_pressure` both off no exposed-area
/// tessellation is ever evaluated.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PhysicsConfig {
    /// SPH pressure force between parcels (eqs 7–9).
    pub sph: bool,
    /// SPH viscosity force between parcels (eq 10).
    pub viscosity: bool,
    /// Atmospheric pressure on the exposed part of each sphere (§5.1).
    pub atmospheric_pressure: bool,
    /// Entrainment and detrainment with the environment (eqs 11–15).
    pub mixing: bool,
    /// Exchange of vapour, liquid water and heat between touching parcels (§5.3).
    pub exchange: bool,
    /// Condensation and evaporation with latent heat (eqs 1, 3).
    pub condensation: bool,
    /// Buoyancy from θ_v (eq 5).
    pub buoyancy: bool,
    /// Drag against the wind, ½ C_D ρ |v − w| (v − w) π r².
    pub drag: bool,
    /// Include liquid water in θ_v (condensate loading); the paper's eq 4 does not.
    pub condensate_loading: bool,
    /// SPH support radius h; also the neighbour-grid cell size. units: m
    pub support_radius_m: f64,
    /// SPH stiffness K of p = K(ρ − ρ0) (paper: 100). units: m² s⁻² (Pa per kg m⁻³)
    pub stiffness: f64,
    /// SPH viscosity coefficient μ (paper: 0.01). units: Pa s
    ///
    /// In SI the paper's 0.01 is all but inert: a parcel of r = 150 m
    /// relaxes towards a neighbour at s = μ m/(ρ_i ρ_j) ∇²W ≈ 4e-7 s⁻¹, so
    /// relative motion loses well under 1 % in ten minutes (tested in
    /// tests/cumulus/physics/fidelity.rs). Kept for fidelity to the paper; turbulent
    /// (eddy) viscosity of a convective boundary layer, μ ≈ ρ K with
    /// K ≈ 10–100 m² s⁻¹, is 10–100 Pa s and damps relative motion within
    /// minutes (the same test checks the computed e^{−2st} decay at 50).
    pub viscosity_mu: f64,
    /// Calibrated weight of the atmospheric-pressure term (paper §5.1; 1 =
    /// remove the full buoyancy of overlapping caps, see `world`). units: 1
    pub atm_pressure_weight: f64,
    /// Entrainment rate ε (ε' = ε r) of the paper's model. units: m⁻¹
    pub entrainment_rate_per_m: f64,
    /// How ε' depends on the radius (see [`EntrainmentModel`]); the paper's
    /// by default.
    pub entrainment_model: EntrainmentModel,
    /// Coefficient c of the plume model's fractional rate c/R. units: 1
    pub entrainment_plume_coefficient: f64,
    /// Fractional entrainment rate of the observed model, per metre of
    /// travel through the air. units: m⁻¹
    pub entrainment_observed_per_m: f64,
    /// Detrainment rate δ (δ' = δ r). units: m⁻¹
    pub detrainment_rate_per_m: f64,
    /// Sub-grid surface multiplier K_e for entrainment. units: 1
    pub entrainment_surface_factor: f64,
    /// Sub-grid surface multiplier K_d for detrainment. units: 1
    pub detrainment_surface_factor: f64,
    /// Small-scale turbulent speed δv_t that keeps mixing going at rest. units: m s⁻¹
    pub turbulence_m_s: f64,
    /// Exchange velocity of vapour diffusion through a contact disk. units: m s⁻¹
    pub exchange_velocity_m_s: f64,
    /// Latent-heat factor α of eq 1 (1 = physical; the paper's calibration is 0.3). units: 1
    pub latent_heat_alpha: f64,
    /// Drag coefficient C_D. units: 1
    pub drag_coefficient: f64,
    /// Liquid water content of the opaque fraction (ql0 of paper §6.1): a
    /// parcel with this much liquid per m³ is fully opaque (f = 1). Fair-weather
    /// cumulus hold 0.2–1 g m⁻³. units: kg m⁻³
    pub opaque_lwc_kg_m3: f64,
    /// Adiabatic exponent γ of eq 6. units: 1
    pub gamma: f64,
    /// Courant factor λ of the CFL and sound-speed limits. units: 1
    pub cfl: f64,
    /// Largest sub-step. units: s
    pub max_dt_s: f64,
    /// Most sub-steps per frame; hitting it is counted.
    pub max_substeps: u32,
    /// Speed cap (counted clamp). units: m s⁻¹
    pub max_speed_m_s: f64,
    /// Smallest parcel radius (counted clamp). units: m
    pub min_radius_m: f64,
    /// Largest parcel radius (counted clamp). units: m
    pub max_radius_m: f64,
    /// Parcels older than this are removed (counted). units: s
    pub max_age_s: f64,
    /// A parcel that was cloudy dies once it has no liquid water left, is
    /// sinking and lies this far below its condensation plane: its cloud is
    /// gone and it has sunk back into the sub-cloud layer. units: m
    pub death_depth_m: f64,
    /// Top of the simulated domain; parcels above it (or above the top of
    /// the environment profile) are removed and counted. units: m
    pub domain_top_m: f64,
}

/// How the entrainment coefficient ε' of eq 11 depends on the parcel's
/// radius R. For an isolated sphere eq 11 entrains ε'·4πR²·ρ·|v| per
/// second, a fractional rate of 3ε'/R per metre of travel through the air
/// (ρ_env ≈ ρ_parcel); each model picks ε' to give its fractional rate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EntrainmentModel {
    /// The paper's ε' = ε R: 3ε per metre at every radius (3·10⁻⁴ m⁻¹
    /// with the default ε).
    #[default]
    Paper,
    /// Plume and thermal theory (Morton, Taylor & Turner 1956; Simpson &
    /// Wiggert 1969): a fractional rate c/R, so ε' = c/3 and small
    /// parcels dilute fastest.
    Plume,
    /// A fixed fractional rate μ per metre, as diagnosed for shallow
    /// cumulus (1–2·10⁻³ m⁻¹, Siebesma & Cuijpers 1995): ε' = μR/3.
    Observed,
}

impl PhysicsConfig {
    /// ε' of eq 11 for a parcel of radius `radius_m` under the chosen
    /// [`EntrainmentModel`]. units: m → m (ε' multiplies area·ρ·speed)
    pub fn entrainment_coefficient(&self, radius_m: f64) -> f64 {
        match self.entrainment_model {
            EntrainmentModel::Paper => self.entrainment_rate_per_m * radius_m,
            EntrainmentModel::Plume => self.entrainment_plume_coefficient / 3.0,
            EntrainmentModel::Observed => self.entrainment_observed_per_m * radius_m / 3.0,
        }
    }
}

impl Default for PhysicsConfig {
    fn default() -> Self {
        PhysicsConfig {
            sph: true,
            viscosity: true,
            atmospheric_pressure: true,
            mixing: true,
            exchange: true,
            condensation: true,
            buoyancy: true,
            drag: true,
            condensate_loading: false,
            support_radius_m: 300.0,
            stiffness: 100.0,
            viscosity_mu: 0.01,
            atm_pressure_weight: 0.01,
            entrainment_rate_per_m: 1.0e-4,
            entrainment_model: EntrainmentModel::Paper,
            entrainment_plume_coefficient: 0.2,
            entrainment_observed_per_m: 1.5e-3,
            detrainment_rate_per_m: 2.0e-4,
            entrainment_surface_factor: 1.0,
            detrainment_surface_factor: 1.0,
            turbulence_m_s: 0.3,
            exchange_velocity_m_s: 0.05,
            latent_heat_alpha: 1.0,
            drag_coefficient: 0.5,
            opaque_lwc_kg_m3: 5.0e-4,
            gamma: 1.4,
            cfl: 0.4,
            max_dt_s: 1.0,
            max_substeps: 64,
            max_speed_m_s: 80.0,
            min_radius_m: 5.0,
            max_radius_m: 3000.0,
            max_age_s: 7200.0,
            death_depth_m: 200.0,
            domain_top_m: 10_000.0,
        }
    }
}

impl PhysicsConfig {
    /// Checks every constant against its allowed range.
    pub fn validate(&self) -> Result<()> {
        check(
            "physics.support_radius_m",
            self.support_radius_m,
            1.0,
            10_000.0,
        )?;
        // K = 0 would silently disable the pressure the `sph` switch says is
        // on (and K < 0 pulls parcels together): switch SPH off with `sph`.
        if !(self.stiffness.is_finite() && self.stiffness > 0.0 && self.stiffness <= 1.0e6) {
            return Err(Error::invalid(
                "physics.stiffness",
                self.stiffness,
                "a finite number above 0 and up to 1000000 (to turn SPH pressure off, set sph = false)",
            ));
        }
        check("physics.viscosity_mu", self.viscosity_mu, 0.0, 1.0e6)?;
        check(
            "physics.atm_pressure_weight",
            self.atm_pressure_weight,
            0.0,
            10.0,
        )?;
        check(
            "physics.entrainment_rate_per_m",
            self.entrainment_rate_per_m,
            0.0,
            0.1,
        )?;
        check(
            "physics.entrainment_plume_coefficient",
            self.entrainment_plume_coefficient,
            0.0,
            10.0,
        )?;
        check(
            "physics.entrainment_observed_per_m",
            self.entrainment_observed_per_m,
            0.0,
            0.1,
        )?;
        check(
            "physics.detrainment_rate_per_m",
            self.detrainment_rate_per_m,
            0.0,
            0.1,
        )?;
        check(
            "physics.entrainment_surface_factor",
            self.entrainment_surface_factor,
            0.0,
            100.0,
        )?;
        check(
            "physics.detrainment_surface_factor",
            self.detrainment_surface_factor,
            0.0,
            100.0,
        )?;
        check("physics.turbulence_m_s", self.turbulence_m_s, 0.0, 50.0)?;
        check(
            "physics.exchange_velocity_m_s",
            self.exchange_velocity_m_s,
            0.0,
            50.0,
        )?;
        check(
            "physics.latent_heat_alpha",
            self.latent_heat_alpha,
            0.0,
            2.0,
        )?;
        check("physics.drag_coefficient", self.drag_coefficient, 0.0, 10.0)?;
        check(
            "physics.opaque_lwc_kg_m3",
            self.opaque_lwc_kg_m3,
            1.0e-6,
            0.1,
        )?;
        check("physics.gamma", self.gamma, 1.0, 2.0)?;
        check("physics.cfl", self.cfl, 0.01, 1.0)?;
        check("physics.max_dt_s", self.max_dt_s, 1.0e-4, 600.0)?;
        if !(1..=100_000).contains(&self.max_substeps) {
            return Err(Error::invalid(
                "physics.max_substeps",
                self.max_substeps,
                "an integer between 1 and 100000",
            ));
        }
        check("physics.max_speed_m_s", self.max_speed_m_s, 0.1, 1000.0)?;
        check("physics.min_radius_m", self.min_radius_m, 0.01, 1.0e4)?;
        check(
            "physics.max_radius_m",
            self.max_radius_m,
            self.min_radius_m,
            1.0e5,
        )?;
        check("physics.max_age_s", self.max_age_s, 1.0, 1.0e7)?;
        check("physics.death_depth_m", self.death_depth_m, 0.0, 100_000.0)?;
        check("physics.domain_top_m", self.domain_top_m, 100.0, 100_000.0)?;
        Ok(())
    }

    /// Whether any term needs the exposed-area tessellation.
    pub fn needs_exposed_area(&self) -> bool {
        self.mixing || self.atmospheric_pressure
    }
}

/// Ground: size of the domain and the heat/humidity map that drives
/// emission (the `[ground]` table). The map is procedural: a few Gaussian
/// hot, moist patches placed by `map_seed` over a weak background.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GroundConfig {
    /// Domain extent in x and y, centred on the origin (paper: 10 km × 10 km). units: m
    pub size_m: [f64; 2],
    /// Number of hot/moist patches.
    pub patches: u32,
    /// Typical patch radius (Gaussian σ). units: m
    pub patch_radius_m: f64,
    /// Heat-map value away from patches, in [0, 1]. units: 1
    pub background: f64,
    /// θ excess of air leaving a patch centre (heat map = 1). units: K
    pub heat_excess_k: f64,
    /// Vapour excess of air leaving a patch centre (humidity map = 1). units: kg/kg
    pub moisture_excess_kg_per_kg: f64,
    /// Seed of the patch layout (independent of the world seed, so that the
    /// same ground can be rerun with other emission draws).
    pub map_seed: u64,
    /// The ground is the scene's terrain ([render.terrain]) rather than flat
    /// z = 0: parcels leave it at its height, sink back into it, and the
    /// heat/humidity maps follow it (see `ground`).
    pub follow_terrain: bool,
    /// The ground's height: flat unless `follow_terrain`, then the scene's
    /// terrain, set by `SceneProfile::world_config` (which reads heightmaps).
    #[serde(skip)]
    pub terrain: crate::landscape::Heightfield,
    /// Unit vector toward the midday sun that heats the slopes (x east, y
    /// north, z up): from the scene's `[sun]` clock (set by
    /// `SceneProfile::world_config`), else from the south, 60° high.
    #[serde(skip)]
    pub midday_sun: [f64; 3],
}

impl Default for GroundConfig {
    fn default() -> Self {
        GroundConfig {
            size_m: [10_000.0, 10_000.0],
            patches: 5,
            patch_radius_m: 700.0,
            background: 0.05,
            heat_excess_k: 2.0,
            moisture_excess_kg_per_kg: 2.0e-3,
            map_seed: 7,
            follow_terrain: false,
            terrain: crate::landscape::Heightfield::flat(),
            midday_sun: [0.0, -0.5, 0.866_025_403_784_438_6],
        }
    }
}

impl GroundConfig {
    /// Checks every field against its allowed range.
    pub fn validate(&self) -> Result<()> {
        check("ground.size_m[0]", self.size_m[0], 100.0, 1.0e6)?;
        check("ground.size_m[1]", self.size_m[1], 100.0, 1.0e6)?;
        if self.patches > 1000 {
            return Err(Error::invalid(
                "ground.patches",
                self.patches,
                "between 0 and 1000",
            ));
        }
        check("ground.patch_radius_m", self.patch_radius_m, 1.0, 1.0e5)?;
        check("ground.background", self.background, 0.0, 1.0)?;
        check("ground.heat_excess_k", self.heat_excess_k, 0.0, 20.0)?;
        check(
            "ground.moisture_excess_kg_per_kg",
            self.moisture_excess_kg_per_kg,
            0.0,
            0.02,
        )?;
        Ok(())
    }
}

/// Parcel emission from the ground (the `[emission]` table).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EmissionConfig {
    /// Whether the ground emits parcels at all.
    pub enabled: bool,
    /// Emission probability per unit time and area where the heat and
    /// humidity maps are 1 at solar noon. units: km⁻² h⁻¹
    pub rate_per_km2_per_h: f64,
    /// Radius of an emitted parcel. units: m
    pub radius_m: f64,
    /// Local solar time at t = 0. units: h
    pub start_hour: f64,
    /// Modulate the rate by the sun: sin(π (hour − 6)/12), zero at night.
    pub diurnal: bool,
    /// No emission while this many parcels are alive (counted).
    pub max_parcels: u32,
}

impl Default for EmissionConfig {
    fn default() -> Self {
        EmissionConfig {
            enabled: true,
            rate_per_km2_per_h: 50.0,
            radius_m: 150.0,
            start_hour: 12.0,
            diurnal: true,
            max_parcels: 1024,
        }
    }
}

impl EmissionConfig {
    /// Checks every field against its allowed range.
    pub fn validate(&self) -> Result<()> {
        check(
            "emission.rate_per_km2_per_h",
            self.rate_per_km2_per_h,
            0.0,
            1.0e5,
        )?;
        check("emission.radius_m", self.radius_m, 1.0, 5000.0)?;
        check("emission.start_hour", self.start_hour, 0.0, 24.0)?;
        if !(1..=1_000_000).contains(&self.max_parcels) {
            return Err(Error::invalid(
                "emission.max_parcels",
                self.max_parcels,
                "between 1 and 1000000",
            ));
        }
        Ok(())
    }
}

/// Wind profile (the `[wind]` table): linear from the surface value to the
/// value aloft at `aloft_z_m`, constant above.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WindConfig {
    /// Wind (x, y) at the ground. units: m s⁻¹
    pub surface_m_s: [f64; 2],
    /// Wind (x, y) at and above `aloft_z_m`. units: m s⁻¹
    pub aloft_m_s: [f64; 2],
    /// Height of the aloft value. units: m
    pub aloft_z_m: f64,
}

impl Default for WindConfig {
    fn default() -> Self {
        WindConfig {
            surface_m_s: [0.0, 0.0],
            aloft_m_s: [0.0, 0.0],
            aloft_z_m: 2000.0,
        }
    }
}

impl WindConfig {
    /// Checks every field against its allowed range.
    pub fn validate(&self) -> Result<()> {
        for (i, v) in self.surface_m_s.iter().enumerate() {
            check(&format!("wind.surface_m_s[{i}]"), *v, -100.0, 100.0)?;
        }
        for (i, v) in self.aloft_m_s.iter().enumerate() {
            check(&format!("wind.aloft_m_s[{i}]"), *v, -100.0, 100.0)?;
        }
        check("wind.aloft_z_m", self.aloft_z_m, 1.0, 100_000.0)?;
        Ok(())
    }

    /// Horizontal wind at height `z_m`. units: m → m s⁻¹ (z component 0)
    pub fn at(&self, z_m: f64) -> glam::DVec3 {
        let w = (z_m / self.aloft_z_m).clamp(0.0, 1.0);
        glam::DVec3::new(
            self.surface_m_s[0] + (self.aloft_m_s[0] - self.surface_m_s[0]) * w,
            self.surface_m_s[1] + (self.aloft_m_s[1] - self.surface_m_s[1]) * w,
            0.0,
        )
    }
}

/// Everything a [`ParcelWorld`](super::ParcelWorld) needs besides the environment.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct WorldConfig {
    pub physics: PhysicsConfig,
    pub ground: GroundConfig,
    pub emission: EmissionConfig,
    /// The scene's `[wind]` table: when present it drives the drag, even
    /// calm; absent, the environment's own profile (a sounding's DRCT/SKNT)
    /// does, else the air is calm.
    pub wind: Option<WindConfig>,
}

impl WorldConfig {
    /// The wind that drags the parcels at `z_m`: the `[wind]` table when
    /// the scene has one, else the environment's profile, else calm.
    /// units: m → m s⁻¹ (z component 0)
    pub fn wind_at(&self, env: &crate::atmosphere::Environment, z_m: f64) -> glam::DVec3 {
        match (&self.wind, env.wind_m_s(z_m)) {
            (Some(w), _) => w.at(z_m),
            (None, Some([u, v])) => glam::DVec3::new(u, v, 0.0),
            (None, None) => glam::DVec3::ZERO,
        }
    }
}

impl WorldConfig {
    /// Validates all four tables.
    pub fn validate(&self) -> Result<()> {
        self.physics.validate()?;
        self.ground.validate()?;
        self.emission.validate()?;
        self.wind.as_ref().map_or(Ok(()), WindConfig::validate)
    }
}
