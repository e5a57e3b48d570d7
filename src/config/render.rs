//! The `[render]` table: how the clouds are drawn and what a frame
//! contains (method, march, lighting and noise constants, terrain, the
//! sprite and slice methods' settings), its defaults and its validation.
//! Plain data: read by the scene loader, the renderer, the window and the
//! bench alike.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::check;
use super::method::{MarchPath, RenderMethod};
use crate::error::{Error, Result};
use crate::landscape::terrain::TerrainConfig;
use crate::sky::Sun;

/// The `[render.sprites]` table.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct SpritesConfig {
    /// Radius of the impostor ring; absent: no impostors (every sprite
    /// drawn directly). units: m
    pub impostor_radius_m: Option<f32>,
}

/// Smallest and largest ring radius: a 4 km cloud block must fit outside
/// it, and beyond 200 km nothing is left to impostor. units: m
const RADIUS_RANGE_M: (f32, f32) = (4000.0, 200_000.0);

impl SpritesConfig {
    pub fn validate(&self) -> Result<()> {
        if let Some(r) = self.impostor_radius_m
            && !(r.is_finite() && (RADIUS_RANGE_M.0..=RADIUS_RANGE_M.1).contains(&r))
        {
            return Err(Error::invalid(
                "render.sprites.impostor_radius_m",
                r,
                "4000 to 200000 m (leave it out for no impostors)",
            ));
        }
        Ok(())
    }
}

/// Scale of linear radiance before the filmic curve (common.wgsl
/// `tone_map`) at `exposure_ev` = 0: sunlit cloud domes (L ≈ 4–6) map to
/// 0.90–0.95, the meadows in the sun (Lambertian, L ≈ 0.7–1.2) to about
/// 0.2 (0.5 sRGB), the clear sky away from the sun (L ≈ 0.6) to a deep
/// blue. benches/pathtraced.py reads the scene's k from the export sidecar.
pub const TONE_EXPOSURE: f32 = 0.25;

/// Visibility of [`crate::sky::Atmosphere::EARTH`]'s clean air, the
/// default `[render] visibility_km` (217.4 km, rounded to the f32 the
/// setting holds). units: km
pub const DEFAULT_VISIBILITY_KM: f32 = 217.358_76;

/// `[render] temporal`: how many pixels the ray-march draws per frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum TemporalMode {
    /// Every pixel, every frame.
    Off,
    /// One pixel of each 2×2 block per frame.
    Block2,
    /// One pixel of each 4×4 block per frame (the window's default).
    #[default]
    Block4,
}

/// What `[render] temporal` accepts, for error messages.
const TEMPORAL_ALLOWED: &str = "\"off\", \"2x2\" or \"4x4\" (or false = \"off\", true = \"4x4\")";

impl TemporalMode {
    /// Every mode, in the order the window's selector lists them.
    pub const ALL: [TemporalMode; 3] = [
        TemporalMode::Block4,
        TemporalMode::Block2,
        TemporalMode::Off,
    ];

    /// Name in scene files.
    pub fn name(self) -> &'static str {
        match self {
            TemporalMode::Off => "off",
            TemporalMode::Block2 => "2x2",
            TemporalMode::Block4 => "4x4",
        }
    }

    /// Side of the block of which one pixel is marched per frame (None:
    /// off).
    pub fn block(self) -> Option<u32> {
        match self {
            TemporalMode::Off => None,
            TemporalMode::Block2 => Some(2),
            TemporalMode::Block4 => Some(4),
        }
    }

    /// The mode a scene file names (see [`TemporalMode::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }
}

impl From<bool> for TemporalMode {
    fn from(on: bool) -> Self {
        if on {
            TemporalMode::Block4
        } else {
            TemporalMode::Off
        }
    }
}

impl Serialize for TemporalMode {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for TemporalMode {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = TemporalMode;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(TEMPORAL_ALLOWED)
            }
            fn visit_bool<E: serde::de::Error>(
                self,
                on: bool,
            ) -> std::result::Result<Self::Value, E> {
                Ok(on.into())
            }
            fn visit_str<E: serde::de::Error>(
                self,
                name: &str,
            ) -> std::result::Result<Self::Value, E> {
                TemporalMode::from_name(name).ok_or_else(|| {
                    E::custom(format!(
                        "unknown temporal mode \"{name}\"; expected {TEMPORAL_ALLOWED}"
                    ))
                })
            }
        }
        d.deserialize_any(Visitor)
    }
}

/// Render settings and feature switches (the `[render]` table).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RenderConfig {
    /// How the clouds are drawn: "baked" (the default: macro field baked
    /// into a 3D texture, cost flat in the parcel count), "exact" (the
    /// paper's per-sample union; at most 1024 condensed parcels),
    /// "sprites" (Wang 2003 sprite clouds of the parcels; see
    /// `[render.sprites]`) or "slices" (Schpok 2003 slicing planes of the
    /// authored ellipsoids and the parcels; see `[render.slices]`).
    pub method: RenderMethod,
    /// Shader stage of the ray-march: "fragment", "compute" or "auto" (the
    /// default: the faster on this adapter, measured in the first frames).
    pub march: MarchPath,
    /// Ray-march the clouds at all (off = landscape only).
    pub clouds: bool,
    /// Cloud shadows on the terrain (needs terrain and clouds).
    pub shadows: bool,
    /// Aerial perspective: the air between the eye and the terrain,
    /// clouds and sprites dims them and adds its own light, from the sky's
    /// atmosphere model (src/sky/air.rs). Off only for comparisons with
    /// renderers that have no air (benches/pathtraced.py).
    pub aerial_perspective: bool,
    /// Finite-difference normals of the density for extra shading (paper
    /// "with FDM normals"; slower).
    pub normals: bool,
    /// Debug: the ray-march writes, instead of its colour, the number of
    /// march iterations each pixel took (samples and empty-space jumps) as
    /// opaque grey radiance, so `render --out steps.exr` holds iterations
    /// per pixel (the bench's landscape section reads them). Off in every
    /// ordinary frame: the shader's branch is a pipeline constant
    /// (`MARCH_STEPS` of shaders/raymarch/clouds.wgsl), compiled out.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub debug_march_steps: bool,
    /// Temporal upscaling of the ray-march: "4x4" marches one pixel in 16
    /// per frame, "2x2" one in 4, the rest reprojected from earlier frames
    /// with the motion at the clouds' depth and clipped to the fresh
    /// samples around them (see src/methods/raymarch/temporal.rs); "off"
    /// marches every pixel. `true` is "4x4", `false` "off". Unset: "4x4"
    /// in the window, off headless, where `render --accumulate N` turns
    /// it on (N frames drawn before the one written).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub temporal: Option<TemporalMode>,
    /// Evaluate only the parcels listed in a sample's grid cell (paper §6.2);
    /// off = every parcel at every sample (brute force, for the bench).
    pub grid_culling: bool,
    /// Ray-march step along view rays. units: m
    pub step_m: f32,
    /// Most steps per view ray.
    pub max_steps: u32,
    /// Samples of the short light march toward the sun (0 = no self-shadowing).
    pub light_steps: u32,
    /// Step of the light march. units: m
    pub light_step_m: f32,
    /// Octaves of the 3D noise summed per sample (each one texture fetch).
    pub noise_octaves: u32,
    /// Noise amplitude k of paper eq. 18 (dimensionless).
    pub noise_amplitude: f32,
    /// Size of the largest noise feature (one texture tile). units: m
    pub noise_scale_m: f32,
    /// Rendered sphere radius over the physical parcel radius (paper §6.1
    /// draws spheres larger than the SPH kernels so neighbours merge).
    pub radius_scale: f32,
    /// Thickness of the soft shell of the sphere, over which the
    /// pseudo-distance d goes from 0 to 1 (the condensation plane's shell is
    /// 0.3× this; see shaders/raymarch/density.wgsl). units: m
    pub shell_m: f32,
    /// Extinction coefficient of fully dense cloud. units: m^-1
    pub extinction_per_m: f32,
    /// Stop a view ray when its transmittance falls below this (0 = never).
    pub early_exit_transmittance: f32,
    /// Henyey–Greenstein asymmetry g of the phase function.
    pub phase_g: f32,
    /// Exposure compensation of the one display transform, in stops
    /// (photographic EV: −1 halves the light before the tone curve). 0 keeps
    /// the curve that the fair-weather scenes and the path-tracer
    /// comparison use; a scene of big sunlit towers is exposed lower so that
    /// their tops do not all sit on the curve's shoulder (docs/rendering.md).
    pub exposure_ev: f32,
    /// Meteorological visibility at the ground (the distance at which a
    /// dark hill fades to 2 % contrast against the horizon): sets the
    /// aerosol of the atmosphere model, and with it the sky's whiteness
    /// near the horizon, the sun's colour and the haze over distant
    /// ground and clouds ([`crate::sky::Atmosphere::with_visibility_km`]).
    /// The default, [`DEFAULT_VISIBILITY_KM`], is the clean air of
    /// Bruneton's and Hillaire's Earth; humid summer days with cumulus
    /// see 20–50 km. units: km
    pub visibility_km: f32,
    /// Sun azimuth, clockwise from +y (north) toward +x (east). units: degrees
    pub sun_azimuth_deg: f32,
    /// Sun elevation above the horizon. units: degrees
    pub sun_elevation_deg: f32,
    /// Side of the 3D noise texture in texels (power of two, 64 to 256):
    /// octaves 1–4 in its RGBA channels, with a full mip chain.
    pub noise_texels: u32,
    /// Side of the 2D cloud-shadow texture in texels.
    pub shadow_texels: u32,
    /// Terrain settings.
    pub terrain: TerrainConfig,
    /// The `slices` method's qualitative controls and noise tiers.
    pub slices: crate::config::slices::SlicesConfig,
    /// The `sprites` method's settings (`[render.sprites]`).
    pub sprites: SpritesConfig,
}

impl Default for RenderConfig {
    fn default() -> Self {
        Self {
            method: RenderMethod::default(),
            march: MarchPath::default(),
            clouds: true,
            shadows: true,
            aerial_perspective: true,
            normals: false,
            debug_march_steps: false,
            temporal: None,
            grid_culling: true,
            step_m: 40.0,
            max_steps: 160,
            light_steps: 4,
            light_step_m: 90.0,
            noise_octaves: 4,
            noise_amplitude: 1.4,
            noise_scale_m: 900.0,
            radius_scale: 2.5,
            shell_m: 280.0,
            extinction_per_m: 0.03,
            early_exit_transmittance: 0.02,
            phase_g: 0.8,
            exposure_ev: 0.0,
            visibility_km: DEFAULT_VISIBILITY_KM,
            sun_azimuth_deg: 100.0,
            sun_elevation_deg: 30.0,
            noise_texels: 64,
            shadow_texels: 256,
            terrain: TerrainConfig::default(),
            slices: Default::default(),
            sprites: Default::default(),
        }
    }
}

impl RenderConfig {
    /// Scale k of linear radiance before the filmic tone curve (common.wgsl
    /// `tone_map`): the base exposure times 2^`exposure_ev`.
    pub fn tone_exposure(&self) -> f32 {
        TONE_EXPOSURE * self.exposure_ev.exp2()
    }

    /// Checks every field; the error names the field and its allowed range.
    pub fn validate(&self) -> Result<()> {
        let r = self;
        check(
            "render.step_m",
            r.step_m,
            r.step_m >= 1.0 && r.step_m <= 1000.0,
            "1 to 1000 m",
        )?;
        if !(1..=4096).contains(&r.max_steps) {
            return Err(Error::invalid("render.max_steps", r.max_steps, "1 to 4096"));
        }
        if r.light_steps > 64 {
            return Err(Error::invalid(
                "render.light_steps",
                r.light_steps,
                "0 to 64",
            ));
        }
        check(
            "render.light_step_m",
            r.light_step_m,
            r.light_step_m >= 1.0 && r.light_step_m <= 2000.0,
            "1 to 2000 m",
        )?;
        if !(1..=6).contains(&r.noise_octaves) {
            return Err(Error::invalid(
                "render.noise_octaves",
                r.noise_octaves,
                "1 to 6",
            ));
        }
        check(
            "render.noise_amplitude",
            r.noise_amplitude,
            (0.0..=2.0).contains(&r.noise_amplitude),
            "0 to 2",
        )?;
        check(
            "render.noise_scale_m",
            r.noise_scale_m,
            r.noise_scale_m >= 10.0,
            "≥ 10 m",
        )?;
        check("render.shell_m", r.shell_m, r.shell_m >= 1.0, "≥ 1 m")?;
        check(
            "render.radius_scale",
            r.radius_scale,
            (0.1..=10.0).contains(&r.radius_scale),
            "0.1 to 10",
        )?;
        check(
            "render.extinction_per_m",
            r.extinction_per_m,
            r.extinction_per_m > 0.0 && r.extinction_per_m <= 10.0,
            "more than 0 and at most 10 m^-1",
        )?;
        check(
            "render.early_exit_transmittance",
            r.early_exit_transmittance,
            (0.0..1.0).contains(&r.early_exit_transmittance),
            "0 (off) to below 1",
        )?;
        check(
            "render.phase_g",
            r.phase_g,
            r.phase_g > -0.99 && r.phase_g < 0.99,
            "between -0.99 and 0.99",
        )?;
        check(
            "render.exposure_ev",
            r.exposure_ev,
            (-8.0..=8.0).contains(&r.exposure_ev),
            "-8 to 8 stops",
        )?;
        let v = crate::sky::VISIBILITY_KM;
        check(
            "render.visibility_km",
            r.visibility_km,
            v.contains(&(r.visibility_km as f64)),
            &format!(
                "{} to {} km (mist and fog start under {0} km; the air alone sees about 288 km)",
                v.start(),
                v.end()
            ),
        )?;
        check(
            "render.sun_azimuth_deg",
            r.sun_azimuth_deg,
            (-360.0..=360.0).contains(&r.sun_azimuth_deg),
            "-360 to 360 degrees",
        )?;
        check(
            "render.sun_elevation_deg",
            r.sun_elevation_deg,
            r.sun_elevation_deg >= 2.0 && r.sun_elevation_deg <= 90.0,
            "2 to 90 degrees (the shadow pass needs the sun above the horizon)",
        )?;
        if !r.noise_texels.is_power_of_two()
            || !(crate::noise::MIN_TEXELS..=256).contains(&r.noise_texels)
        {
            return Err(Error::invalid(
                "render.noise_texels",
                r.noise_texels,
                "a power of two from 64 to 256 (the finest of the four octaves in the \
                 texture has 32 lattice cells per tile, two texels each)",
            ));
        }
        if !(16..=4096).contains(&r.shadow_texels) {
            return Err(Error::invalid(
                "render.shadow_texels",
                r.shadow_texels,
                "16 to 4096",
            ));
        }
        r.sprites.validate()?;
        let t = &r.terrain;
        check(
            "render.terrain.height_scale_m",
            t.height_scale_m,
            (0.0..=5000.0).contains(&t.height_scale_m),
            "0 to 5000 m",
        )?;
        check(
            "render.terrain.extent_m",
            t.extent_m,
            t.extent_m >= 100.0 && t.extent_m <= 1.0e6,
            "100 m to 1000 km",
        )?;
        if let Some(level) = t.water_level_m {
            check(
                "render.terrain.water_level_m",
                level,
                (0.0..=t.height_scale_m).contains(&level),
                "0 m to render.terrain.height_scale_m (the highest terrain point)",
            )?;
        }
        if !(2..=1024).contains(&t.resolution) {
            return Err(Error::invalid(
                "render.terrain.resolution",
                t.resolution,
                "2 to 1024",
            ));
        }
        Ok(())
    }

    /// Unit vector toward the sun (z up, azimuth clockwise from +y).
    pub fn sun_direction(&self) -> Vec3 {
        let az = self.sun_azimuth_deg.to_radians();
        let el = self.sun_elevation_deg.to_radians();
        Vec3::new(az.sin() * el.cos(), az.cos() * el.cos(), el.sin())
    }

    /// Makes a relative heightmap path relative to `base_dir` (the scene
    /// file's directory).
    pub fn resolve_paths(&mut self, base_dir: &std::path::Path) {
        if let Some(h) = &self.terrain.heightmap
            && h.is_relative()
        {
            self.terrain.heightmap = Some(base_dir.join(h));
        }
    }

    /// The sun described by this configuration.
    pub fn sun(&self) -> Sun {
        Sun::from_sky(self.sun_direction(), 1.0, self.visibility_km)
    }
}

impl Default for Sun {
    /// The sun of the default `[render]` table.
    fn default() -> Self {
        RenderConfig::default().sun()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    use crate::config::CameraConfig;

    #[test]
    fn defaults_validate() {
        RenderConfig::default().validate().unwrap();
        CameraConfig::default().validate().unwrap();
    }

    #[test]
    fn bad_fields_are_named() {
        let cfg = RenderConfig {
            step_m: 0.0,
            ..RenderConfig::default()
        };
        let msg = cfg.validate().unwrap_err().to_string();
        assert!(msg.contains("render.step_m"), "{msg}");
        let cam = CameraConfig {
            vfov_deg: 200.0,
            ..CameraConfig::default()
        };
        assert!(cam.validate().unwrap_err().to_string().contains("vfov"));
    }

    #[test]
    fn water_above_the_highest_terrain_is_refused() {
        let mut cfg = RenderConfig::default();
        cfg.terrain.water_level_m = Some(cfg.terrain.height_scale_m + 1.0);
        let msg = cfg.validate().unwrap_err().to_string();
        assert!(msg.contains("render.terrain.water_level_m"), "{msg}");
        cfg.terrain.water_level_m = Some(100.0);
        cfg.validate().unwrap();
    }

    #[test]
    fn render_table_parses_with_terrain_subtable() {
        let cfg: RenderConfig =
            toml::from_str("normals = true\n[terrain]\nheightmap = \"h.png\"\n").unwrap();
        assert!(cfg.normals);
        assert_eq!(cfg.terrain.heightmap, Some(PathBuf::from("h.png")));
        assert!(toml::from_str::<RenderConfig>("bogus = 1\n").is_err());
    }

    #[test]
    fn configs_round_trip_through_toml() {
        // The window saves scenes with toml::to_string_pretty.
        let mut cfg = RenderConfig::default();
        let text = toml::to_string_pretty(&cfg).unwrap();
        assert_eq!(toml::from_str::<RenderConfig>(&text).unwrap(), cfg);
        cfg.terrain.heightmap = Some(PathBuf::from("maps/h.png"));
        let text = toml::to_string_pretty(&cfg).unwrap();
        assert_eq!(toml::from_str::<RenderConfig>(&text).unwrap(), cfg);
        let cam = CameraConfig::default();
        let text = toml::to_string_pretty(&cam).unwrap();
        assert_eq!(toml::from_str::<CameraConfig>(&text).unwrap(), cam);
    }

    #[test]
    fn temporal_takes_modes_and_booleans_and_names_what_is_allowed() {
        let parse = |v: &str| toml::from_str::<RenderConfig>(&format!("temporal = {v}\n"));
        for (v, mode) in [
            ("\"4x4\"", TemporalMode::Block4),
            ("\"2x2\"", TemporalMode::Block2),
            ("\"off\"", TemporalMode::Off),
            ("true", TemporalMode::Block4),
            ("false", TemporalMode::Off),
        ] {
            assert_eq!(parse(v).unwrap().temporal, Some(mode), "{v}");
        }
        for bad in ["\"3x3\"", "4"] {
            let msg = parse(bad).unwrap_err().to_string();
            assert!(
                msg.contains("\"2x2\"") && msg.contains("\"4x4\""),
                "{bad}: {msg}"
            );
        }
        // Saved scenes keep the mode by name.
        let cfg = RenderConfig {
            temporal: Some(TemporalMode::Block2),
            ..RenderConfig::default()
        };
        let text = toml::to_string_pretty(&cfg).unwrap();
        assert!(text.contains("temporal = \"2x2\""), "{text}");
        assert_eq!(toml::from_str::<RenderConfig>(&text).unwrap(), cfg);
    }

    #[test]
    fn sun_from_the_east_is_up() {
        let d = RenderConfig::default().sun_direction();
        assert!((d.length() - 1.0).abs() < 1e-5);
        assert!(d.x > 0.5 && d.z > 0.3);
    }

    #[test]
    fn radius_is_validated_and_named() {
        assert!(SpritesConfig::default().validate().is_ok());
        let ok = SpritesConfig {
            impostor_radius_m: Some(20_000.0),
        };
        assert!(ok.validate().is_ok());
        for bad in [100.0, f32::NAN, 1.0e6] {
            let e = SpritesConfig {
                impostor_radius_m: Some(bad),
            }
            .validate()
            .unwrap_err()
            .to_string();
            assert!(e.contains("render.sprites.impostor_radius_m"), "{e}");
        }
    }
}
