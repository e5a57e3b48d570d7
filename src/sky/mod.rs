//! The sky from an atmosphere model: the colour of the sun after the air it
//! crosses, the sky's radiance in every direction and the light the whole
//! sky sheds on an up-facing surface, for a sun at a given elevation and
//! an aerosol of a given visibility. Pure CPU arithmetic (no GPU, no
//! physics): the renderer computes it once per sun position and uploads it
//! in the frame uniform ([`SkyLight`], read by `sky_color` and
//! `sky_ambient` in shaders/common.wgsl); [`Sun`] is the sun as the
//! renderer's light, its sky cached per step of elevation
//! (src/sky/sun_light.rs).
//!
//! Model: Hillaire (2020, "A scalable and production ready sky and
//! atmosphere rendering technique") in a spherical, layered atmosphere with
//! the Earth parameters of Bruneton's 2017 reference implementation (which
//! Hillaire also uses): Rayleigh scattering (scale height 8 km), Mie
//! scattering and absorption (1.2 km, Cornette–Shanks phase with g = 0.8)
//! and an ozone layer (a tent 25 ± 15 km) that only absorbs. The RGB
//! channels stand for 680, 550 and 440 nm. Three look-up tables:
//! - transmittance to space over (height, view zenith cosine),
//!   [`TransmittanceLut`];
//! - multiple scattering Ψ_ms over (height, sun zenith cosine): the
//!   paper's isotropic second order, times the geometric series
//!   1/(1 − f_ms) of all higher orders, with a grey ground of albedo
//!   [`Atmosphere::ground_albedo`], [`MultipleScatteringLut`];
//! - the sky view over (azimuth from the sun, elevation), rebuilt when the
//!   sun moves, [`SkyLight`].
//!
//! The first two depend only on the atmosphere and are built once
//! ([`SkyLuts::new`]); the third is cheap. With the sky view comes the air
//! table of the aerial perspective ([`AirTable`]): the same source term
//! over height, for what the air adds between the eye and a hill or a
//! cloud. Not modelled: the sun's spectrum (the sun above the air is
//! white), the ground's single-scattered reflection in the sky view (the
//! terrain is drawn by the renderer).

mod air;
mod luts;
mod sun_light;
mod view;

use glam::DVec3;

pub use air::{AIR_HEIGHTS, AIR_STEPS, AIR_TOP_M, Air, AirTable, ray_height_m};
pub use luts::{
    MULTIPLE_SCATTERING_SIZE, MultipleScatteringLut, SkyLuts, TRANSMITTANCE_SIZE, TransmittanceLut,
};
pub use sun_light::Sun;
pub use view::{SKY_AZIMUTHS, SKY_ELEVATIONS, SKY_TEXELS, SkyLight};

/// The sun's colour above the atmosphere, in the renderer's units (linear
/// RGB; the cloud march's irradiance is 4π times it, see
/// src/export/sidecar.rs). White, and scaled so that the sun at 60°
/// elevation, (2.3, 2.1, 1.8), is close to the nominal daylight
/// irradiance (2.2, 2.1, 2.0) the exposure and the cloud lighting are set
/// for.
pub const SUN_ABOVE_AIR: f64 = 2.5;

/// ln 50: Koschmieder's visibility is where the contrast falls to 2 %.
pub const KOSCHMIEDER: f64 = 3.912_023;

/// The visibilities an atmosphere may be set to ([`Atmosphere::with_visibility_km`]):
/// from a thick haze (under 1 km it is mist or fog, the cloud deck's
/// business) to just short of what the air alone allows. units: km
pub const VISIBILITY_KM: std::ops::RangeInclusive<f64> = 1.0..=280.0;

/// A layered atmosphere over a spherical ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Atmosphere {
    /// units: m
    pub ground_radius_m: f64,
    /// Radius of the top of the atmosphere. units: m
    pub top_radius_m: f64,
    /// Rayleigh scattering at sea level (R, G, B = 680, 550, 440 nm). units: 1/m
    pub rayleigh_scattering_per_m: DVec3,
    /// units: m
    pub rayleigh_scale_height_m: f64,
    /// Mie scattering at sea level (grey). units: 1/m
    pub mie_scattering_per_m: f64,
    /// Mie extinction (scattering + absorption) at sea level. units: 1/m
    pub mie_extinction_per_m: f64,
    /// units: m
    pub mie_scale_height_m: f64,
    /// Asymmetry g of the Cornette–Shanks phase of the aerosols.
    pub mie_g: f64,
    /// Ozone absorption at the layer's peak. units: 1/m
    pub ozone_absorption_per_m: DVec3,
    /// Height of the ozone peak. units: m
    pub ozone_centre_m: f64,
    /// Half width of the ozone tent (density 0 this far from the peak). units: m
    pub ozone_half_width_m: f64,
    /// Lambertian albedo of the ground, in the multiple-scattering table
    /// only (light the ground sends back up into the air).
    pub ground_albedo: f64,
}

impl Atmosphere {
    /// The Earth (Bruneton 2017, `demo.cc`; Hillaire 2020, table 1).
    pub const EARTH: Self = Self {
        ground_radius_m: 6_360_000.0,
        top_radius_m: 6_460_000.0,
        rayleigh_scattering_per_m: DVec3::new(5.802e-6, 13.558e-6, 33.1e-6),
        rayleigh_scale_height_m: 8_000.0,
        mie_scattering_per_m: 3.996e-6,
        mie_extinction_per_m: 4.440e-6,
        mie_scale_height_m: 1_200.0,
        mie_g: 0.8,
        ozone_absorption_per_m: DVec3::new(0.650e-6, 1.881e-6, 0.085e-6),
        ozone_centre_m: 25_000.0,
        ozone_half_width_m: 15_000.0,
        ground_albedo: 0.1,
    };

    /// Meteorological visibility at sea level: the distance at which a
    /// black object's contrast against the horizon sky falls to 2 %
    /// (Koschmieder: ln 50 over the extinction, at 550 nm, the G channel).
    /// About 217 km for [`Self::EARTH`]'s clean air. units: km
    pub fn visibility_km(&self) -> f64 {
        let (_, _, ozone) = self.densities(0.0);
        let extinction = self.rayleigh_scattering_per_m.y
            + self.mie_extinction_per_m
            + self.ozone_absorption_per_m.y * ozone;
        KOSCHMIEDER / extinction / 1000.0
    }

    /// The same atmosphere with as much aerosol at sea level as makes the
    /// visibility `visibility_km` (see [`Self::visibility_km`]): the Mie
    /// extinction is what the visibility leaves over the Rayleigh
    /// scattering, and the aerosols keep their single-scattering albedo,
    /// scale height and phase. `visibility_km` must lie in
    /// [`VISIBILITY_KM`] (the air alone, with no aerosol, sees about 288
    /// km); the renderer's settings check it.
    pub fn with_visibility_km(&self, visibility_km: f64) -> Self {
        let (_, _, ozone) = self.densities(0.0);
        let air = self.rayleigh_scattering_per_m.y + self.ozone_absorption_per_m.y * ozone;
        let extinction = (KOSCHMIEDER / (visibility_km * 1000.0) - air).max(0.0);
        let albedo = self.mie_scattering_per_m / self.mie_extinction_per_m;
        Self {
            mie_extinction_per_m: extinction,
            mie_scattering_per_m: extinction * albedo,
            ..*self
        }
    }

    /// Relative densities (Rayleigh, Mie, ozone) at height `h_m`.
    fn densities(&self, h_m: f64) -> (f64, f64, f64) {
        let ozone = (1.0 - (h_m - self.ozone_centre_m).abs() / self.ozone_half_width_m).max(0.0);
        (
            (-h_m / self.rayleigh_scale_height_m).exp(),
            (-h_m / self.mie_scale_height_m).exp(),
            ozone,
        )
    }

    /// Extinction at height `h_m`. units: 1/m
    fn extinction(&self, h_m: f64) -> DVec3 {
        self.medium(h_m).extinction
    }

    /// Extinction and scattering at height `h_m`.
    fn medium(&self, h_m: f64) -> Medium {
        let (r, m, o) = self.densities(h_m);
        let rayleigh = self.rayleigh_scattering_per_m * r;
        Medium {
            extinction: rayleigh
                + DVec3::splat(self.mie_extinction_per_m * m)
                + self.ozone_absorption_per_m * o,
            rayleigh,
            mie: DVec3::splat(self.mie_scattering_per_m * m),
        }
    }

    /// Whether a ray from radius `r_m` with cosine `mu` to the vertical
    /// meets the ground.
    fn hits_ground(&self, r_m: f64, mu: f64) -> bool {
        mu < 0.0 && r_m * r_m * (mu * mu - 1.0) + self.ground_radius_m * self.ground_radius_m >= 0.0
    }

    /// Distance from radius `r_m` along a ray with cosine `mu` to the
    /// vertical to the top of the atmosphere, or None when the ray meets
    /// the ground first. units: m
    fn distance_to_top(&self, r_m: f64, mu: f64) -> Option<f64> {
        if self.hits_ground(r_m, mu) {
            return None;
        }
        let disc_top = r_m * r_m * (mu * mu - 1.0) + self.top_radius_m * self.top_radius_m;
        Some((-r_m * mu + disc_top.max(0.0).sqrt()).max(0.0))
    }

    /// Distance to where the ray ends (the top or the ground) and whether
    /// it ends on the ground. units: m
    fn distance_to_end(&self, r_m: f64, mu: f64) -> (f64, bool) {
        match self.distance_to_top(r_m, mu) {
            Some(d) => (d, false),
            None => {
                let disc =
                    r_m * r_m * (mu * mu - 1.0) + self.ground_radius_m * self.ground_radius_m;
                ((-r_m * mu - disc.max(0.0).sqrt()).max(0.0), true)
            }
        }
    }

    /// Samples of a ray from `origin` (relative to the Earth's centre)
    /// along unit `dir` over `length`: midpoint rule in s with t = L·s²
    /// (steps short near the start, where the air is densest). Calls
    /// `visit(point, medium there, dt, transmittance from the origin)`.
    fn march(
        &self,
        origin: DVec3,
        dir: DVec3,
        length: f64,
        steps: u32,
        mut visit: impl FnMut(DVec3, &Medium, f64, DVec3),
    ) {
        let mut depth = DVec3::ZERO;
        let mut t_prev = 0.0;
        for i in 0..steps {
            let s = (i as f64 + 0.5) / steps as f64;
            let t = length * s * s;
            let dt = 2.0 * length * s / steps as f64;
            let p = origin + dir * t;
            let h = p.length() - self.ground_radius_m;
            // Optical depth from the origin to this sample.
            let medium = self.medium(h);
            depth += medium.extinction * (t - t_prev);
            t_prev = t;
            visit(p, &medium, dt, (-depth).exp());
        }
    }

    /// Optical depth from height `h_m` to space along a ray whose cosine
    /// to the vertical is `mu`; None when the ground is in the way.
    /// Midpoint rule in s with t = T·s², `steps` samples.
    pub fn optical_depth(&self, h_m: f64, mu: f64, steps: u32) -> Option<DVec3> {
        let r = self.ground_radius_m + h_m;
        let length = self.distance_to_top(r, mu)?;
        Some(self.column(r, mu, length, steps))
    }

    /// Optical depth over `length_m` from radius `r_m` along a ray with
    /// cosine `mu` to the vertical (midpoint rule in s, t = L·s²).
    fn column(&self, r_m: f64, mu: f64, length_m: f64, steps: u32) -> DVec3 {
        let mut sum = DVec3::ZERO;
        for i in 0..steps {
            let s = (i as f64 + 0.5) / steps as f64;
            let t = length_m * s * s;
            let dt = 2.0 * length_m * s / steps as f64;
            let height = (r_m * r_m + t * t + 2.0 * r_m * mu * t).sqrt() - self.ground_radius_m;
            sum += self.extinction(height) * dt;
        }
        sum
    }

    /// Transmittance of the air from the ground to the sun at
    /// `elevation_rad` (0 when the sun is below the horizon), by direct
    /// integration (the renderer reads [`TransmittanceLut`]).
    pub fn sun_transmittance(&self, elevation_rad: f64) -> DVec3 {
        self.optical_depth(0.0, elevation_rad.sin(), SUN_STEPS)
            .map_or(DVec3::ZERO, |od| (-od).exp())
    }

    /// Phase-free single-scattered sky radiance toward unit `view` from
    /// the ground (x, y horizontal, z up), per unit irradiance of a sun
    /// toward unit `sun`: (Rayleigh, Mie) parts, each to be multiplied by
    /// its phase function of view·sun. units: 1/sr per 1/sr of phase.
    /// Brute force (an optical depth toward the sun at every sample): the
    /// reference the sky-view table is tested against.
    pub fn inscattering(&self, view: DVec3, sun: DVec3) -> (DVec3, DVec3) {
        let to_sun = |r: f64, mu: f64| {
            self.optical_depth(r - self.ground_radius_m, mu, SUN_STEPS)
                .map_or(DVec3::ZERO, |od| (-od).exp())
        };
        let [rayleigh, mie, _] = self.scattered_along(view, sun, to_sun, |_, _| DVec3::ZERO);
        (rayleigh, mie)
    }

    /// Light scattered toward the eye (on the ground) along unit `view`,
    /// per unit irradiance of a sun toward unit `sun`: [Rayleigh, Mie,
    /// multiple]. The first two are phase-free (times their phase of
    /// view·sun later); the third has its isotropic phase inside Ψ_ms.
    /// `to_sun(r, mu)` is the transmittance toward the sun from radius r
    /// at cosine mu to the vertical, `psi(r, mu)` Ψ_ms there.
    fn scattered_along(
        &self,
        view: DVec3,
        sun: DVec3,
        to_sun: impl Fn(f64, f64) -> DVec3,
        psi: impl Fn(f64, f64) -> DVec3,
    ) -> [DVec3; 3] {
        let r = self.ground_radius_m + EYE_HEIGHT_M;
        let Some(length) = self.distance_to_top(r, view.z) else {
            return [DVec3::ZERO; 3];
        };
        let (light, _) =
            self.scattered_segment(EYE_HEIGHT_M, view, length, VIEW_STEPS, sun, to_sun, psi);
        light
    }

    /// Light scattered toward an eye at height `eye_m` along unit `view`
    /// by the air of the first `length_m` of the ray (parts as in
    /// [`Self::scattered_along`]), and that stretch's transmittance;
    /// `steps` samples, the Earth's curvature exact.
    #[allow(clippy::too_many_arguments)]
    fn scattered_segment(
        &self,
        eye_m: f64,
        view: DVec3,
        length_m: f64,
        steps: u32,
        sun: DVec3,
        to_sun: impl Fn(f64, f64) -> DVec3,
        psi: impl Fn(f64, f64) -> DVec3,
    ) -> ([DVec3; 3], DVec3) {
        let origin = DVec3::new(0.0, 0.0, self.ground_radius_m + eye_m);
        let mut out = [DVec3::ZERO; 3];
        self.march(origin, view, length_m, steps, |p, medium, dt, seen| {
            let r = p.length();
            let source = medium.source(r, p.dot(sun) / r, &to_sun, &psi);
            for (o, s) in out.iter_mut().zip(source) {
                *o += s * seen * dt;
            }
        });
        let depth = self.column(origin.z, view.z, length_m, steps);
        (out, (-depth).exp())
    }
}

/// The air at one height. units: 1/m
struct Medium {
    extinction: DVec3,
    /// Rayleigh scattering.
    rayleigh: DVec3,
    /// Mie scattering.
    mie: DVec3,
}

impl Medium {
    /// What this air scatters per metre toward any direction, per unit
    /// irradiance of a sun at cosine `mu_sun` to the vertical at radius
    /// `r_m`: [Rayleigh, Mie] per unit phase (the sun's transmittance
    /// `to_sun(r, mu)` times the scattering) and the multiple-scattered
    /// part (the scattering times Ψ_ms, `psi(r, mu)`, isotropic). The one
    /// source term of the sky view and of the aerial perspective.
    fn source(
        &self,
        r_m: f64,
        mu_sun: f64,
        to_sun: impl Fn(f64, f64) -> DVec3,
        psi: impl Fn(f64, f64) -> DVec3,
    ) -> [DVec3; 3] {
        let lit = to_sun(r_m, mu_sun);
        [
            self.rayleigh * lit,
            self.mie * lit,
            (self.rayleigh + self.mie) * psi(r_m, mu_sun),
        ]
    }
}

/// Height of the eye above the ground for the sky (1 m: on the ground).
const EYE_HEIGHT_M: f64 = 1.0;
/// Samples of one optical depth toward the sun.
const SUN_STEPS: u32 = 32;
/// Samples along one view ray of the sky table.
const VIEW_STEPS: u32 = 32;

/// Rayleigh phase function. units: 1/sr
pub fn rayleigh_phase(mu: f32) -> f32 {
    3.0 / (16.0 * std::f32::consts::PI) * (1.0 + mu * mu)
}

/// Cornette–Shanks phase function (Mie). units: 1/sr
pub fn mie_phase(mu: f32, g: f32) -> f32 {
    let g2 = g * g;
    3.0 / (8.0 * std::f32::consts::PI) * (1.0 - g2) * (1.0 + mu * mu)
        / ((2.0 + g2) * (1.0 + g2 - 2.0 * g * mu).max(1e-6).powf(1.5))
}
