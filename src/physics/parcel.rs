//! One parcel (a thermal, paper §4): the state the physics integrates, and
//! the spec from which tests, benches and the ground create parcels.

use glam::DVec3;

use crate::atmosphere::thermo;

/// A parcel's full state. Mixing ratios are per kg of dry air.
#[derive(Debug, Clone, PartialEq)]
pub struct Parcel {
    /// Stable identity: the world's spawn count when it was made, never
    /// reused, unchanged while it lives (seeds what the renderer draws of it).
    pub id: u64,
    /// Centre. units: m
    pub position_m: DVec3,
    /// Velocity (the full-step value between frames). units: m s⁻¹
    pub velocity_m_s: DVec3,
    /// Acceleration at the current position (leapfrog's stored force). units: m s⁻²
    pub accel_m_s2: DVec3,
    /// Dry-air mass. units: kg
    pub dry_mass_kg: f64,
    /// Vapour mixing ratio. units: kg/kg
    pub qv_kg_per_kg: f64,
    /// Liquid (condensed) water mixing ratio. units: kg/kg
    pub ql_kg_per_kg: f64,
    /// Potential temperature. units: K
    pub theta_k: f64,
    /// Liquid-water potential temperature θ_l = θ − α L q_l/(c_p Π): the θ
    /// the air would have with all its liquid evaporated. Phase changes and
    /// motion leave it alone; entrainment mixes it like θ (eq 14). Together
    /// with the total water it fixes the condensation plane. units: K
    pub theta_l_k: f64,
    /// Volume (eq 6). units: m³
    pub volume_m3: f64,
    /// Radius of the sphere of that volume. units: m
    pub radius_m: f64,
    /// Height at which this parcel's own air (its liquid-water potential
    /// temperature and total water) saturates: the flat base of its cloud. units: m
    pub cond_plane_z_m: f64,
    /// Filling ratio f ∈ [0, 1] (paper §6.1). units: 1
    pub fill: f64,
    /// Time since emission. units: s
    pub age_s: f64,
    /// False once the parcel has died or left the domain (it is then removed).
    pub alive: bool,
    /// Whether the parcel has ever held liquid water.
    pub was_cloudy: bool,
    /// θ of the air when it was created. units: K
    pub origin_theta_k: f64,
    /// q_v of the air when it was created. units: kg/kg
    pub origin_qv_kg_per_kg: f64,
    /// SPH density (eq 7). units: kg m⁻³
    pub sph_density_kg_m3: f64,
    /// SPH pressure (eq 8). units: Pa
    pub sph_pressure_pa: f64,
    /// Area in contact with the environment (18 × 9 tessellation). units: m²
    pub exposed_area_m2: f64,
    /// Atmospheric-pressure force on the hidden part (§5.1). units: N
    pub atm_force_n: DVec3,
    /// Rate of entrained mass (air and vapour), for momentum dilution. units: kg s⁻¹
    pub entrain_rate_kg_s: f64,
    /// Pressure and total mass at the last volume update (eq 6's state 1).
    pub(crate) volume_ref: (f64, f64),
    /// Environment pressure, density and Exner function Π at the centre,
    /// refreshed once per sub-step after the drift (they cost several powers
    /// each). units: Pa, kg m⁻³, 1
    pub(crate) env_at_centre: (f64, f64, f64),
    /// Rates of the mixing processes at the last evaluation (the Heun
    /// predictor's slope): d/dt of dry mass, q_v, q_l, θ, θ_l.
    /// units: kg s⁻¹, s⁻¹, s⁻¹, K s⁻¹, K s⁻¹
    pub(crate) mix_rate: [f64; 5],
    /// Exner function Π at the last saturation adjustment (the latent heat
    /// of the next one uses the mean 1/Π of the sub-step). units: 1
    pub(crate) exner_adjusted: f64,
}

impl Parcel {
    /// Total mass: dry air, vapour and liquid. units: kg
    pub fn total_mass_kg(&self) -> f64 {
        self.dry_mass_kg * (1.0 + self.qv_kg_per_kg + self.ql_kg_per_kg)
    }

    /// Water (vapour + liquid) carried. units: kg
    pub fn water_kg(&self) -> f64 {
        self.dry_mass_kg * (self.qv_kg_per_kg + self.ql_kg_per_kg)
    }

    /// Whether the parcel holds condensed water.
    pub fn is_condensed(&self) -> bool {
        self.fill > 0.0
    }
}

/// How to create a parcel: position, velocity and air properties. Its mass
/// is the ideal-gas mass of a sphere of `radius_m` at the environment
/// pressure at its height.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParcelSpec {
    /// Centre. units: m
    pub position_m: DVec3,
    /// Initial velocity. units: m s⁻¹
    pub velocity_m_s: DVec3,
    /// Potential temperature. units: K
    pub theta_k: f64,
    /// Vapour mixing ratio. units: kg/kg
    pub qv_kg_per_kg: f64,
    /// Liquid water mixing ratio. units: kg/kg
    pub ql_kg_per_kg: f64,
    /// Radius. units: m
    pub radius_m: f64,
}

impl ParcelSpec {
    /// A parcel at rest at `position_m` with the environment's air plus a θ and q_v excess.
    pub fn from_environment(
        env: &crate::atmosphere::Environment,
        position_m: DVec3,
        theta_excess_k: f64,
        qv_excess: f64,
        radius_m: f64,
    ) -> Self {
        ParcelSpec {
            position_m,
            velocity_m_s: DVec3::ZERO,
            theta_k: env.theta_k(position_m.z) + theta_excess_k,
            qv_kg_per_kg: env.qv(position_m.z) + qv_excess,
            ql_kg_per_kg: 0.0,
            radius_m,
        }
    }

    /// Dry-air mass of this parcel at pressure `p_pa`. units: Pa → kg
    pub(crate) fn dry_mass_kg(&self, p_pa: f64) -> f64 {
        let t = thermo::temperature_from_theta_k(self.theta_k, p_pa);
        let v = sphere_volume_m3(self.radius_m);
        // ρ = P/(R_d T_v) is the moist density; dry mass = total/(1 + q_v + q_l).
        let rho = p_pa
            / (thermo::R_DRY
                * thermo::virtual_temperature_k(t, self.qv_kg_per_kg, self.ql_kg_per_kg));
        rho * v / (1.0 + self.qv_kg_per_kg + self.ql_kg_per_kg)
    }
}

/// Volume of a sphere of radius `r_m`: 4/3 π r³. units: m → m³
pub fn sphere_volume_m3(r_m: f64) -> f64 {
    4.0 / 3.0 * std::f64::consts::PI * r_m.powi(3)
}

/// Radius of a sphere of volume `v_m3` (the inverse of [`sphere_volume_m3`]). units: m³ → m
pub fn sphere_radius_m(v_m3: f64) -> f64 {
    (3.0 * v_m3 / (4.0 * std::f64::consts::PI)).cbrt()
}
