//! `cumulus parcel`: single-parcel aerology on a sounding. Lifts the
//! surface-based, mixed-layer and most-unstable parcels with the simulation's
//! thermodynamics and reports their lifting condensation level (LCL), level
//! of free convection (LFC), equilibrium level (EL), CAPE and CIN, as a
//! table, as JSON, or as a Skew-T log-p diagram of the chosen one.

use std::io::Write as _;
use std::ops::RangeInclusive;
use std::path::PathBuf;

use anyhow::Context as _;
use cumulus::atmosphere::Sounding;
use cumulus::atmosphere::cape::{self, ParcelKind, ParcelReport};
use cumulus::atmosphere::indices;
use cumulus::atmosphere::lifting::{self, LfcChoice, LiftOptions, ParcelAscent, ParcelStart};
use cumulus::atmosphere::thermo::Thermo;

use super::parcel_report::{
    dynamic_json, index_rows, indices_json, report_json, summary_lines, to_json, write_dynamic,
    write_table,
};
use cumulus::physics::PhysicsConfig;
use cumulus::physics::single::{self, SingleRelease, SingleRun};
use cumulus::plots::skewt::{SkewT, write_skew_t_png};

/// Arguments of `cumulus parcel`.
#[derive(Debug, clap::Args)]
#[command(
    long_about = "Lift the surface-based, mixed-layer (lowest 100 hPa) and most-unstable (lowest \
300 hPa) parcels of a radiosonde sounding and report their lifting condensation level (LCL), \
level of free convection (LFC), equilibrium level (EL), CAPE and CIN (J/kg, virtual-temperature \
corrected as MetPy's cape_cin).\n\n\
By default (--thermo standard) the parcels are lifted as forecasters and MetPy 1.7 lift them: \
dry adiabatically to the LCL, then along the pseudo-adiabat (condensate falls out), with Ambaum's \
saturation vapour pressure; --thermo model lifts them with the cloud simulation's own reversible \
saturation adjustment (Tetens, latent-heat factor 1). LFC and EL are where the parcel's virtual \
temperature crosses the environment's (without the condensate's weight unless \
--condensate-loading); with several buoyant layers --lfc picks the LFC (most-cape by default), \
and CIN is all the negative area from the start to it. Rows without a dewpoint keep their \
temperature; above the last dewpoint the relative humidity of that level is held, and the output \
says so. Also reported: lifted index, K-index, precipitable water, lapse rates, bulk shear, \
Bunkers storm motion and storm-relative helicity ('no wind data' without wind). Heights are \
above the sounding's first usable level.",
    after_help = "Examples:\n  cumulus parcel --sounding profiles/soundings/oun-2011-05-22-12z.txt\n  \
cumulus parcel --sounding profiles/soundings/oun-1999-05-04-00z.txt --json\n  \
cumulus parcel --sounding profiles/soundings/oun-2011-05-22-12z.txt --parcel mu --plot mu.png\n  \
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
    /// Parcel thermodynamics: standard (the forecasters', as MetPy 1.7:
    /// pseudo-adiabatic ascent, Ambaum 2020 saturation pressure) or model
    /// (the cloud simulation's own: reversible ascent with Tetens, paper
    /// eq. 1-3). The output says which was used.
    #[arg(long, value_enum, default_value_t = ThermoChoice::Standard)]
    pub thermo: ThermoChoice,
    /// Which level of free convection CAPE and CIN use when the parcel is
    /// buoyant in more than one layer (MetPy's which_lfc): bottom (the
    /// lowest), top (the highest) or most-cape (the base of the layer with
    /// the most CAPE, so a strong cap counts as CIN).
    #[arg(long, value_enum, default_value_t = LfcArg::MostCape)]
    pub lfc: LfcArg,
    /// Count the condensed water's weight in the parcel's virtual temperature
    /// (lowers the EL; the simulation's `condensate_loading`, off by default there too).
    #[arg(long)]
    pub condensate_loading: bool,
    /// Print exactly one JSON object instead of the table: the surface
    /// parcel's lcl_hpa, lcl_m, lfc_hpa, lfc_m, el_hpa, el_m, cape_j_per_kg,
    /// cin_j_per_kg; `parcels` with the same keys and the start (start_hpa,
    /// start_m, start_t_c, start_td_c) for sb, ml and mu; `lifted_parcel`
    /// and the `levels` of the --parcel one.
    #[arg(long)]
    pub json: bool,
    /// Which parcel the table's levels, the diagram and --dynamic lift:
    /// sb (surface-based), ml (mean of the lowest 100 hPa) or mu (highest
    /// θe in the lowest 300 hPa). --surface-temp/--surface-dewpoint change sb only.
    #[arg(long, value_enum, default_value_t = ParcelChoice::Sb)]
    pub parcel: ParcelChoice,
    /// Also write a Skew-T log-p diagram (PNG, 900×1000) to this file; with
    /// --dynamic it also shows the released parcel's path.
    #[arg(long, value_name = "FILE.png")]
    pub plot: Option<PathBuf>,
    /// Also release one parcel from the surface with the full dynamics of the
    /// cloud simulation (buoyancy, drag, volume, condensation) and follow it:
    /// maximum altitude, equilibrium altitude, oscillation period, trajectory.
    #[arg(long)]
    pub dynamic: bool,
    /// With --dynamic: entrain and detrain environment air (the parcel loses
    /// water and decays, paper figs 3–4).
    #[arg(long, requires = "dynamic")]
    pub mixing: bool,
    /// With --dynamic: how long to follow the parcel, in seconds (0.001 to
    /// 1e7, at most 1e7 frames of --dt).
    #[arg(long, value_name = "S", default_value_t = 3600.0, requires = "dynamic",
          value_parser = duration_seconds)]
    pub duration: f64,
    /// With --dynamic: frame time step in seconds, 0.0001 to 600 (the
    /// integrator sub-steps it when the CFL or force limits ask for less).
    #[arg(long, value_name = "S", default_value_t = 1.0, requires = "dynamic",
          value_parser = step_seconds)]
    pub dt: f64,
    /// With --dynamic: temperature excess of the released parcel over the
    /// surface air, in K (a parcel at exactly the surface temperature is
    /// neutral and stays put; the parcel's temperature must stay within
    /// 150 to 400 K).
    #[arg(
        long,
        value_name = "K",
        default_value_t = 1.0,
        requires = "dynamic",
        allow_negative_numbers = true
    )]
    pub temp_excess: f64,
    /// With --dynamic: radius of the released parcel, in metres (5 to 3000,
    /// the simulation's parcel sizes).
    #[arg(long, value_name = "M", default_value_t = 150.0, requires = "dynamic",
          allow_negative_numbers = true, value_parser = radius_metres)]
    pub radius: f64,
    /// With --dynamic: write the whole trajectory (time, z, T, θ, θ_v of parcel
    /// and environment, q_v, q_l, radius, mass) to this CSV file.
    #[arg(long, value_name = "FILE.csv", requires = "dynamic")]
    pub csv: Option<PathBuf>,
}

/// The `--thermo` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ThermoChoice {
    /// The forecasters' (MetPy's): pseudo-adiabatic, Ambaum saturation pressure.
    Standard,
    /// The cloud simulation's: reversible, Tetens saturation pressure.
    Model,
}

/// The `--lfc` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum LfcArg {
    /// The lowest LFC.
    Bottom,
    /// The highest LFC.
    Top,
    /// The base of the buoyant layer with the most CAPE.
    MostCape,
}

/// The `--parcel` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ParcelChoice {
    /// Surface-based.
    Sb,
    /// Mixed layer: mean θ and q_v of the lowest 100 hPa.
    Ml,
    /// Most unstable: highest θe in the lowest 300 hPa.
    Mu,
}

impl ParcelChoice {
    fn kind(self) -> ParcelKind {
        match self {
            ParcelChoice::Sb => ParcelKind::Surface,
            ParcelChoice::Ml => ParcelKind::MixedLayer,
            ParcelChoice::Mu => ParcelKind::MostUnstable,
        }
    }
}

/// A number within `range` (the bounds the release itself checks, so the
/// option's message is the real range), in `unit`.
fn number_in(s: &str, range: RangeInclusive<f64>, unit: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if v.is_finite() && range.contains(&v) {
        Ok(v)
    } else {
        // 1e7 rather than 10000000.
        let show = |v: f64| match v {
            v if v >= 1e5 => format!("{v:e}"),
            v => v.to_string(),
        };
        Err(format!(
            "{s} {unit} is not allowed: give a finite number from {} to {} {unit}",
            show(*range.start()),
            show(*range.end())
        ))
    }
}

/// `--duration`: [`single::DURATION_S`].
fn duration_seconds(s: &str) -> Result<f64, String> {
    number_in(s, single::DURATION_S, "s")
}

/// `--dt`: [`single::DT_S`].
fn step_seconds(s: &str) -> Result<f64, String> {
    number_in(s, single::DT_S, "s")
}

/// `--radius`: the simulation's parcel radii (its default `[physics]`).
fn radius_metres(s: &str) -> Result<f64, String> {
    let p = PhysicsConfig::default();
    number_in(s, p.min_radius_m..=p.max_radius_m, "m")
}

/// Checks the `--dynamic` release of `start` (the chosen parcel at the
/// ground) against [`single::release`]'s bounds, in terms of the options
/// that set them; `p0` is the ground's pressure. units: Pa
fn check_release(
    args: &Args,
    kind: ParcelKind,
    start: &ParcelStart,
    p0: f64,
) -> anyhow::Result<()> {
    anyhow::ensure!(
        single::frames(args.duration, args.dt).is_some(),
        "--duration {} s with --dt {} s makes {:.0} frames: at most {:e} are allowed (use a larger --dt)",
        args.duration,
        args.dt,
        args.duration / args.dt,
        single::MAX_FRAMES
    );
    let t = &single::SURFACE_T_K;
    let (lo, hi) = (t.start() - start.t_k, t.end() - start.t_k);
    anyhow::ensure!(
        args.temp_excess.is_finite() && (lo..=hi).contains(&args.temp_excess),
        "invalid --temp-excess {} K: the released parcel starts at the {} parcel's {:.2} °C \
         plus the excess, and its temperature must stay within {} to {} K: give an excess \
         from {lo:.2} to {hi:.2} K",
        args.temp_excess,
        kind.name(),
        start.t_k - 273.15,
        t.start(),
        t.end()
    );
    let qv = Thermo::Model.mixing_ratio_from_dewpoint(start.td_k, p0);
    if !single::SURFACE_QV.contains(&qv) {
        let q_max = *single::SURFACE_QV.end();
        let td_max = Thermo::Model.dewpoint_from_mixing_ratio_k(q_max, p0) - 273.15;
        let dewpoint = match (args.surface_dewpoint, kind) {
            (Some(td), ParcelKind::Surface) => format!("--surface-dewpoint {td}"),
            _ => format!(
                "the {} parcel's dewpoint {:.2}",
                kind.name(),
                start.td_k - 273.15
            ),
        };
        anyhow::bail!(
            "invalid {dewpoint} °C with --dynamic: the released parcel's vapour mixing ratio \
             would be {:.0} g/kg, and the dynamics take at most {:.0} g/kg: a dewpoint up to \
             {td_max:.2} °C at {:.0} hPa",
            qv * 1000.0,
            q_max * 1000.0,
            p0 / 100.0
        );
    }
    Ok(())
}

/// Releases the surface parcel with the full dynamics (`--dynamic`).
/// The parcel starts from `start`'s temperature and dewpoint, its vapour
/// from the dewpoint by the simulation's own saturation formula (the
/// environment `env` is the simulation's too), whatever `--thermo`.
fn release_dynamic(
    args: &Args,
    env: &cumulus::atmosphere::Environment,
    kind: ParcelKind,
    start: &ParcelStart,
) -> anyhow::Result<SingleRun> {
    let p0 = env.pressure_pa(start.z_m);
    check_release(args, kind, start, p0)?;
    let run = single::release(
        env.clone(),
        &PhysicsConfig::default(),
        SingleRelease {
            surface_t_k: start.t_k + args.temp_excess,
            surface_qv: Thermo::Model.mixing_ratio_from_dewpoint(start.td_k, p0),
            radius_m: args.radius,
            mixing: args.mixing,
            duration_s: args.duration,
            dt_s: args.dt,
        },
    )?;
    if let Some(path) = &args.csv {
        write_trajectory_csv(path, &run)?;
    }
    Ok(run)
}

fn write_trajectory_csv(path: &std::path::Path, run: &SingleRun) -> anyhow::Result<()> {
    cumulus::output::write_atomic_with(path, |w| {
        let mut c = csv::Writer::from_writer(w);
        c.write_record([
            "time_s",
            "z_m",
            "w_m_s",
            "t_k",
            "theta_k",
            "theta_v_k",
            "env_t_k",
            "env_theta_k",
            "env_theta_v_k",
            "qv_gkg",
            "ql_gkg",
            "radius_m",
            "mass_kg",
            "water_kg",
        ])?;
        for p in &run.trajectory {
            c.write_record(
                [
                    p.time_s,
                    p.z_m,
                    p.w_m_s,
                    p.t_k,
                    p.theta_k,
                    p.theta_v_k,
                    p.env_t_k,
                    p.env_theta_k,
                    p.env_theta_v_k,
                    p.qv_kg_per_kg * 1000.0,
                    p.ql_kg_per_kg * 1000.0,
                    p.radius_m,
                    p.mass_kg,
                    p.water_kg,
                ]
                .map(|v| v.to_string()),
            )?;
        }
        c.flush()
    })?;
    Ok(())
}

/// Runs `cumulus parcel`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if let Some(path) = &args.plot {
        super::output_extension("--plot", path, &[("png", "")])?;
        super::writable_output("--plot", path)?;
    }
    if let Some(path) = &args.csv {
        super::writable_output("--csv", path)?;
    }
    let sounding = Sounding::load(&args.sounding)?;
    let thermo = match args.thermo {
        ThermoChoice::Standard => Thermo::Standard,
        ThermoChoice::Model => Thermo::Model,
    };
    let env = sounding
        .to_environment_with(thermo)
        .with_context(|| format!("building the environment of {}", args.sounding.display()))?;
    let opts = LiftOptions {
        alpha: 1.0,
        surface_t_k: args.surface_temp.map(|c| c + 273.15),
        surface_td_k: args.surface_dewpoint.map(|c| c + 273.15),
        condensate_loading: args.condensate_loading,
        thermo,
        lfc: match args.lfc {
            LfcArg::Bottom => LfcChoice::Bottom,
            LfcArg::Top => LfcChoice::Top,
            LfcArg::MostCape => LfcChoice::MostCape,
        },
    };
    let reports = ParcelKind::ALL
        .iter()
        .map(|&k| cape::parcel_report(&env, k, &opts))
        .collect::<cumulus::Result<Vec<ParcelReport>>>()?;
    let kind = args.parcel.kind();
    let chosen = reports
        .iter()
        .find(|r| r.kind == kind)
        .expect("every kind is reported");
    if args.dynamic && chosen.start.z_m > 0.0 {
        anyhow::bail!(
            "--dynamic releases a parcel from the ground, but the {} parcel starts at {:.0} m: use --parcel sb or ml",
            kind.name(),
            chosen.start.z_m
        );
    }
    // The chosen parcel at the sounding's own levels, against the observed
    // environment, for the table and the JSON `levels`.
    let heights: Vec<f64> = env.levels().iter().map(|l| l.z_m).collect();
    let levels = lifting::lift_from(&env, &opts, &chosen.start, &heights)?.levels;
    let ascent = ParcelAscent {
        levels,
        lfc: chosen.lfc,
        el: chosen.el,
        ..chosen.ascent.clone()
    };
    let dynamic = if args.dynamic {
        // The simulation runs on its own thermodynamics' environment.
        let sim_env = sounding.to_environment()?;
        Some(release_dynamic(&args, &sim_env, kind, &chosen.start)?)
    } else {
        None
    };
    let idx = indices::indices(&env, &reports[0].ascent.levels);
    let thermo_and_lfc = format!("thermo {}, LFC {}", thermo.key(), opts.lfc.key());
    if let Some(path) = &args.plot {
        let dynamic_path: Option<Vec<(f64, f64)>> = dynamic.as_ref().map(|run| {
            run.trajectory
                .iter()
                .map(|p| (env.pressure_pa(p.z_m), p.t_k))
                .collect()
        });
        // 100 m spacing draws a smooth curve; finer steps make the thick line
        // jagged (each short segment is rounded to whole pixels).
        let step = 100.0;
        let n = ((env.top_m() - chosen.start.z_m) / step).ceil() as usize;
        let curve_heights: Vec<f64> = (0..=n)
            .map(|i| (chosen.start.z_m + i as f64 * step).min(env.top_m()))
            .collect();
        let curve = lifting::lift_from(&env, &opts, &chosen.start, &curve_heights)?;
        let title = format!(
            "{} — {} parcel",
            sounding.station.clone().unwrap_or_else(|| args
                .sounding
                .file_name()
                .map(|f| f.to_string_lossy().into_owned())
                .unwrap_or_default()),
            kind.name()
        );
        write_skew_t_png(
            path,
            &SkewT {
                title,
                env: &env,
                ascent: &ascent,
                parcel_curve: &curve.levels,
                dynamic_path: dynamic_path.as_deref(),
                wind: env.wind(),
                summary: &summary_lines(&reports, kind, &thermo_and_lfc, &idx),
            },
            900 + cumulus::plots::skewt::SIDE_PANEL_PX,
            1000,
        )?;
    }
    let mut out = std::io::stdout().lock();
    if args.json {
        let mut json = to_json(&ascent);
        let sb = &reports[0];
        json["cape_j_per_kg"] = sb.cape_j_per_kg.into();
        json["cin_j_per_kg"] = sb.cin_j_per_kg.into();
        // The top level is the surface parcel (the --surface-* options apply).
        for (key, m) in [("lcl", sb.ascent.lcl), ("lfc", sb.lfc), ("el", sb.el)] {
            json[format!("{key}_hpa")] = m.map(|m| m.p_pa / 100.0).into();
            json[format!("{key}_m")] = m.map(|m| m.z_m).into();
        }
        json["lifted_parcel"] = kind.key().into();
        json["thermo"] = thermo.key().into();
        json["lfc_choice"] = opts.lfc.key().into();
        json["humidity_top_hpa"] = env
            .humidity_top_m()
            .map(|z| env.pressure_pa(z) / 100.0)
            .into();
        json["indices"] = indices_json(&idx);
        json["parcels"] = reports
            .iter()
            .map(|r| (r.kind.key().to_string(), report_json(r)))
            .collect::<serde_json::Map<_, _>>()
            .into();
        if let Some(run) = &dynamic {
            json["dynamic"] = dynamic_json(run);
        }
        serde_json::to_writer(&mut out, &json)?;
        writeln!(out)?;
    } else {
        write_table(&mut out, &sounding, &ascent, &reports, kind)?;
        writeln!(
            out,
            "thermodynamics: {}; LFC: {}",
            thermo.describe(),
            opts.lfc.key()
        )?;
        if let Some(z) = env.humidity_top_m() {
            writeln!(
                out,
                "humidity: no dewpoint above {:.0} hPa ({z:.0} m): missing, not zero; the environment holds that level's relative humidity above it",
                env.pressure_pa(z) / 100.0
            )?;
        }
        writeln!(out)?;
        for (name, value) in index_rows(&idx) {
            writeln!(out, "{name:<26} {value}")?;
        }
        match env.wind() {
            Some(w) => writeln!(
                out,
                "wind: {} levels from DRCT/SKNT; it drives the parcels' drag unless a scene sets [wind]",
                w.levels().len(),
            )?,
            None => writeln!(
                out,
                "wind: none in the sounding (DRCT/SKNT blank): scenes on it are calm unless they set [wind]"
            )?,
        }
        if let Some(run) = &dynamic {
            write_dynamic(&mut out, &args, run)?;
        }
        if let Some(path) = &args.plot {
            writeln!(out, "Skew-T diagram written to {}", path.display())?;
        }
    }
    Ok(())
}
