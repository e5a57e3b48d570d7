//! `--hour` and `--date`: move a scene's `[sun]` clock so that the frame at
//! simulated time `time_s` shows that local time and date. The scene's table
//! is rewritten, so the ground's heating (the emission clock) moves with the sun.

use anyhow::{bail, ensure};
use cumulus::config::RenderConfig;
use cumulus::scene::SceneProfile;
use cumulus::sky::Sun;
use cumulus::sun::SolarClock;

/// Applies `--hour`/`--date` to `scene` (the frame at `time_s` shows them),
/// prints where the sun stands then, and returns the clock (None when the
/// scene pins the sun).
pub fn apply(
    scene: &mut SceneProfile,
    hour: Option<f64>,
    date: Option<&str>,
    time_s: f64,
) -> anyhow::Result<Option<SolarClock>> {
    let Some(table) = &scene.sun else {
        if hour.is_some() || date.is_some() {
            bail!(
                "--hour and --date move the scene's [sun] clock, and this scene has no [sun] table: \
                 it pins the sun with [render] sun_azimuth_deg/sun_elevation_deg. Add a [sun] table \
                 (latitude_deg, longitude_deg, date = \"YYYY-MM-DD\", time_h)"
            );
        }
        return Ok(None);
    };
    let mut clock = table.clock()?;
    if let Some(h) = hour {
        ensure!(
            h.is_finite() && (0.0..24.0).contains(&h),
            "invalid --hour {h}: a local clock time from 0 up to (not including) 24"
        );
        clock = clock.with_local_time_at(h, time_s);
    }
    if let Some(d) = date {
        let days = cumulus::sun::parse_date(d, "--date")?;
        clock = clock.with_date_at(days, time_s);
    }
    scene.sun = Some(clock.to_config());
    let p = clock.position(time_s);
    let local = clock.local_time_h(time_s);
    let minutes = (local * 60.0).round() as u32 % 1440;
    eprintln!(
        "sun: azimuth {:.1}°, elevation {:.1}° on {} at {:02}:{:02} local (solar time {:.2} h){}",
        p.azimuth_deg,
        p.elevation_deg,
        clock.local_date(time_s),
        minutes / 60,
        minutes % 60,
        clock.solar_time_h(time_s),
        if p.elevation_deg < cumulus::sun::MIN_LIGHT_ELEVATION_DEG {
            format!(
                "; below {}°: the light is held there and dimmed",
                cumulus::sun::MIN_LIGHT_ELEVATION_DEG
            )
        } else {
            String::new()
        }
    );
    Ok(Some(clock))
}

/// The sun of the frame at simulated time `t_s`.
pub fn frame_sun(clock: Option<&SolarClock>, cfg: &RenderConfig, t_s: f64) -> Sun {
    cumulus::scene::render_sun(clock, cfg, t_s).0
}
