//! `cumulus parcel`: single-parcel aerology on a sounding. Lifts the surface
//! parcel with the simulation's thermodynamics and reports its lifting
//! condensation level (LCL), level of free convection (LFC) and equilibrium
//! level (EL), as a table, as JSON, or as a Skew-T log-p diagram.

use std::io::Write as _;
use std::path::PathBuf;

use anyhow::Context as _;
use cumulus::atmosphere::Sounding;
use cumulus::atmosphere::lifting::{self, LevelMark, LiftOptions, ParcelAscent};
use cumulus::plots::skewt::{SkewT, write_skew_t_png};

/// Arguments of `cumulus parcel`.
#[derive(Debug, clap::Args)]
#[command(
    long_about = "Lift the surface parcel of a radiosonde sounding and report its lifting \
condensation level (LCL), level of free convection (LFC) and equilibrium level (EL).\n\n\
The parcel conserves potential temperature and total water and is brought to saturation \
equilibrium at every height with the same saturation adjustment the cloud simulation uses \
(latent-heat factor 1); LFC and EL are where the parcel's virtual temperature crosses the \
environment's (without the condensate's weight unless --condensate-loading). Heights are above the sounding's first usable level.",
    after_help = "Examples:\n  cumulus parcel --sounding profiles/soundings/oun-2011-05-22-12z.txt\n  \
cumulus parcel --sounding profiles/soundings/oun-1999-05-04-00z.txt --json\n  \
cumulus parcel --sounding profiles/soundings/oun-2011-05-22-12z.txt --surface-temp 30 --plot skewt.png"
)]
pub struct Args {
    /// Sounding in the University of Wyoming text format
    /// (PRES HGHT TEMP DWPT RELH MIXR DRCT SKNT THTA THTE THTV).
    #[arg(long, value_name = "FILE")]
    pub sounding: PathBuf,
    /// Surface parcel temperature instead of the sounding's, in °C.
    #[arg(long, value_name = "C", allow_negative_numbers = true)]
    pub surface_temp: Option<f64>,
    /// Surface parcel dewpoint instead of the sounding's, in °C (at most the temperature).
    #[arg(long, value_name = "C", allow_negative_numbers = true)]
    pub surface_dewpoint: Option<f64>,
    /// Count the condensed water's weight in the parcel's virtual temperature
    /// (lowers the EL; the simulation's `condensate_loading`, off by default there too).
    #[arg(long)]
    pub condensate_loading: bool,
    /// Print exactly one JSON object (lcl_hpa, lcl_m, lfc_hpa, lfc_m, el_hpa, el_m, levels) instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Also write a Skew-T log-p diagram (PNG, 900×1000) to this file.
    #[arg(long, value_name = "FILE.png")]
    pub plot: Option<PathBuf>,
}

/// Runs `cumulus parcel`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let sounding = Sounding::load(&args.sounding)?;
    let env = sounding
        .to_environment()
        .with_context(|| format!("building the environment of {}", args.sounding.display()))?;
    let opts = LiftOptions {
        alpha: 1.0,
        surface_t_k: args.surface_temp.map(|c| c + 273.15),
        surface_td_k: args.surface_dewpoint.map(|c| c + 273.15),
        condensate_loading: args.condensate_loading,
    };
    let ascent = lifting::lift_surface_parcel(&env, &opts)?;
    if let Some(path) = &args.plot {
        // 100 m spacing draws a smooth curve; finer steps make the thick line
        // jagged (each short segment is rounded to whole pixels).
        let n = (env.top_m() / 100.0).ceil() as usize + 1;
        let curve = lifting::surface_parcel_curve(&env, &opts, n)?;
        let title = format!(
            "{} — surface parcel",
            sounding.station.clone().unwrap_or_else(|| args
                .sounding
                .file_name()
                .map(|f| f.to_string_lossy().into_owned())
                .unwrap_or_default())
        );
        write_skew_t_png(
            path,
            &SkewT {
                title,
                env: &env,
                ascent: &ascent,
                parcel_curve: &curve.levels,
            },
            900,
            1000,
        )?;
    }
    let mut out = std::io::stdout().lock();
    if args.json {
        serde_json::to_writer(&mut out, &to_json(&ascent))?;
        writeln!(out)?;
    } else {
        write_table(&mut out, &sounding, &ascent)?;
        if let Some(path) = &args.plot {
            writeln!(out, "Skew-T diagram written to {}", path.display())?;
        }
    }
    Ok(())
}

fn to_json(a: &ParcelAscent) -> serde_json::Value {
    let hpa = |m: Option<LevelMark>| m.map(|m| m.p_pa / 100.0);
    let z = |m: Option<LevelMark>| m.map(|m| m.z_m);
    serde_json::json!({
        "lcl_hpa": hpa(a.lcl), "lcl_m": z(a.lcl),
        "lfc_hpa": hpa(a.lfc), "lfc_m": z(a.lfc),
        "el_hpa": hpa(a.el), "el_m": z(a.el),
        "levels": a.levels.iter().map(|l| serde_json::json!({
            "p_hpa": l.p_pa / 100.0,
            "z_m": l.z_m,
            "t_k": l.t_k,
            "tv_k": l.tv_k,
            "env_t_k": l.env_t_k,
            "env_tv_k": l.env_tv_k,
            "qv_gkg": l.qv * 1000.0,
            "ql_gkg": l.ql * 1000.0,
        })).collect::<Vec<_>>(),
    })
}

fn write_table(
    out: &mut impl std::io::Write,
    s: &Sounding,
    a: &ParcelAscent,
) -> std::io::Result<()> {
    if let Some(st) = &s.station {
        writeln!(out, "{st}")?;
    }
    let first = &a.levels[0];
    writeln!(
        out,
        "surface parcel: {:.1} hPa, T {:.1} °C, q_v {:.2} g/kg (station {:.0} m MSL)",
        first.p_pa / 100.0,
        first.t_k - 273.15,
        first.qv * 1000.0,
        s.surface_msl_m()
    )?;
    for (name, m, none) in [
        ("LCL", a.lcl, "none (the parcel never saturates)"),
        ("LFC", a.lfc, "none (never buoyant above the LCL)"),
        ("EL", a.el, "none (no LFC, or still buoyant at the top)"),
    ] {
        match m {
            Some(m) => writeln!(
                out,
                "{name:>4}: {:7.1} hPa  {:7.0} m above the surface",
                m.p_pa / 100.0,
                m.z_m
            )?,
            None => writeln!(out, "{name:>4}: {none}")?,
        }
    }
    writeln!(out)?;
    writeln!(
        out,
        "  p(hPa)    z(m)  T(°C)  Tv(°C)  envT(°C) envTv(°C)  qv(g/kg) ql(g/kg)  buoyancy"
    )?;
    for l in &a.levels {
        let b = l.tv_k - l.env_tv_k;
        writeln!(
            out,
            "{:8.1} {:7.0} {:6.1} {:7.1} {:9.1} {:9.1} {:9.2} {:8.2}  {:+6.1} K",
            l.p_pa / 100.0,
            l.z_m,
            l.t_k - 273.15,
            l.tv_k - 273.15,
            l.env_t_k - 273.15,
            l.env_tv_k - 273.15,
            l.qv * 1000.0,
            l.ql * 1000.0,
            b
        )?;
    }
    Ok(())
}
