//! What `cumulus parcel` prints and draws: the text table, the JSON object,
//! the Skew-T's summary box and the released parcel's report. The numbers
//! come from `atmosphere::cape` and `atmosphere::indices`; this only
//! formats them.

use cumulus::atmosphere::Sounding;
use cumulus::atmosphere::cape::{ParcelKind, ParcelReport};
use cumulus::atmosphere::indices::Indices;
use cumulus::atmosphere::lifting::{LevelMark, ParcelAscent};
use cumulus::atmosphere::wind::direction_from_components;
use cumulus::physics::single::SingleRun;

use super::parcel::Args;

/// The side panel's lines: CAPE and CIN of each parcel (the drawn one
/// marked), the thermodynamics and LFC choice, and the indices.
pub(super) fn summary_lines(
    reports: &[ParcelReport],
    kind: ParcelKind,
    thermo_and_lfc: &str,
    idx: &Indices,
) -> Vec<String> {
    let mut lines: Vec<String> = reports
        .iter()
        .map(|r| {
            format!(
                "{} {}: CAPE {:.0} J/kg, CIN {:.0} J/kg",
                if r.kind == kind { ">" } else { " " },
                r.kind.key().to_uppercase(),
                r.cape_j_per_kg,
                r.cin_j_per_kg
            )
        })
        .collect();
    lines.push(thermo_and_lfc.to_string());
    lines.extend(
        index_rows(idx)
            .into_iter()
            .map(|(k, v)| format!("{k}: {v}")),
    );
    lines
}

/// The indices as (short name, value with its unit) rows: the text
/// table's and the Skew-T box's. An index the data cannot give says why.
pub(super) fn index_rows(idx: &Indices) -> Vec<(&'static str, String)> {
    let or = |v: Option<f64>, fmt: &dyn Fn(f64) -> String, why: &str| match v {
        Some(v) => fmt(v),
        None => format!("n/a ({why})"),
    };
    let mut rows = vec![
        (
            "lifted index",
            or(
                idx.lifted_index_k,
                &|v| format!("{v:+.1} K"),
                "data end below 500 hPa",
            ),
        ),
        (
            "K-index",
            or(
                idx.k_index_c,
                &|v| format!("{v:.1} °C"),
                "needs 850-500 hPa",
            ),
        ),
        (
            "precipitable water",
            format!("{:.1} mm", idx.precipitable_water_mm),
        ),
        (
            "lapse rate 0-3 km",
            or(
                idx.lapse_0_3km_k_per_km,
                &|v| format!("{v:.1} K/km"),
                "data end below 3 km",
            ),
        ),
        (
            "lapse rate 700-500 hPa",
            or(
                idx.lapse_700_500_k_per_km,
                &|v| format!("{v:.1} K/km"),
                "needs 700-500 hPa",
            ),
        ),
    ];
    let Some(w) = &idx.wind else {
        rows.push(("wind indices", "no wind data".to_string()));
        return rows;
    };
    let why = format!("wind data end at {:.0} m", w.top_m);
    let ms = |v: f64| format!("{v:.1} m/s");
    let motion = |m: [f64; 2]| {
        let (from, speed) = direction_from_components(m[0], m[1]);
        format!("{from:.0}° {speed:.1} m/s")
    };
    let srh = |v: f64| format!("{v:.0} m²/s²");
    let or_motion = |m: Option<[f64; 2]>| m.map_or(format!("n/a ({why})"), motion);
    rows.extend([
        ("bulk shear 0-1 km", or(w.shear_0_1km_m_s, &ms, &why)),
        ("bulk shear 0-6 km", or(w.shear_0_6km_m_s, &ms, &why)),
        ("Bunkers right mover", or_motion(w.bunkers_right_m_s)),
        ("Bunkers left mover", or_motion(w.bunkers_left_m_s)),
        (
            "SRH 0-1 km (right mover)",
            or(w.srh_0_1km_m2_s2, &srh, &why),
        ),
        (
            "SRH 0-3 km (right mover)",
            or(w.srh_0_3km_m2_s2, &srh, &why),
        ),
    ]);
    rows
}

/// The JSON `indices` object: null where the data cannot give an index,
/// `wind` null with `wind_note` "no wind data" without wind.
pub(super) fn indices_json(idx: &Indices) -> serde_json::Value {
    let uv = |m: Option<[f64; 2]>| m.map(|m| serde_json::json!({"u_m_s": m[0], "v_m_s": m[1]}));
    let wind = idx.wind.as_ref().map(|w| {
        serde_json::json!({
            "top_m": w.top_m,
            "bulk_shear_0_1km_m_s": w.shear_0_1km_m_s,
            "bulk_shear_0_6km_m_s": w.shear_0_6km_m_s,
            "bunkers_right": uv(w.bunkers_right_m_s),
            "bunkers_left": uv(w.bunkers_left_m_s),
            "srh_0_1km_m2_s2": w.srh_0_1km_m2_s2,
            "srh_0_3km_m2_s2": w.srh_0_3km_m2_s2,
        })
    });
    serde_json::json!({
        "lifted_index_k": idx.lifted_index_k,
        "k_index_c": idx.k_index_c,
        "precipitable_water_mm": idx.precipitable_water_mm,
        "lapse_rate_0_3km_k_per_km": idx.lapse_0_3km_k_per_km,
        "lapse_rate_700_500hpa_k_per_km": idx.lapse_700_500_k_per_km,
        "wind_note": if idx.wind.is_none() { Some("no wind data") } else { None },
        "wind": wind,
    })
}

/// One parcel of the JSON `parcels` object.
pub(super) fn report_json(r: &ParcelReport) -> serde_json::Value {
    let hpa = |m: Option<LevelMark>| m.map(|m| m.p_pa / 100.0);
    let z = |m: Option<LevelMark>| m.map(|m| m.z_m);
    let a = &r.ascent;
    serde_json::json!({
        "start_hpa": r.start_p_pa / 100.0, "start_m": r.start.z_m,
        "start_t_c": r.start.t_k - 273.15, "start_td_c": r.start.td_k - 273.15,
        "lcl_hpa": hpa(a.lcl), "lcl_m": z(a.lcl),
        "lfc_hpa": hpa(r.lfc), "lfc_m": z(r.lfc),
        "el_hpa": hpa(r.el), "el_m": z(r.el),
        "cape_j_per_kg": r.cape_j_per_kg, "cin_j_per_kg": r.cin_j_per_kg,
    })
}

pub(super) fn dynamic_json(run: &SingleRun) -> serde_json::Value {
    serde_json::json!({
        "max_altitude_m": run.max_altitude_m,
        "equilibrium_altitude_m": run.equilibrium_altitude_m,
        "period_s": run.period_s,
        "ended_early": run.ended_early,
        "trajectory": run.trajectory.iter().map(|p| serde_json::json!({
            "time_s": p.time_s, "z_m": p.z_m, "t_k": p.t_k, "theta_k": p.theta_k,
            "theta_v_k": p.theta_v_k, "env_t_k": p.env_t_k, "env_theta_k": p.env_theta_k,
            "env_theta_v_k": p.env_theta_v_k, "qv_gkg": p.qv_kg_per_kg * 1000.0,
            "ql_gkg": p.ql_kg_per_kg * 1000.0, "radius_m": p.radius_m, "mass_kg": p.mass_kg,
        })).collect::<Vec<_>>(),
    })
}

pub(super) fn write_dynamic(
    out: &mut impl std::io::Write,
    args: &Args,
    run: &SingleRun,
) -> std::io::Result<()> {
    writeln!(out)?;
    writeln!(
        out,
        "released parcel ({} K excess, radius {} m, mixing {}), followed {} s:",
        args.temp_excess,
        args.radius,
        if args.mixing { "on" } else { "off" },
        run.trajectory.last().map(|p| p.time_s).unwrap_or(0.0)
    )?;
    writeln!(out, "  maximum altitude      {:8.0} m", run.max_altitude_m)?;
    writeln!(
        out,
        "  equilibrium altitude  {:8.0} m (mean of the last third)",
        run.equilibrium_altitude_m
    )?;
    match run.period_s {
        Some(p) => writeln!(out, "  oscillation period    {p:8.0} s")?,
        None => writeln!(
            out,
            "  oscillation period        none (fewer than 3 crossings of the equilibrium)"
        )?,
    }
    if run.ended_early {
        writeln!(out, "  the parcel died or left the domain before the end")?;
    }
    writeln!(out)?;
    writeln!(
        out,
        "  time(s)    z(m)  T(°C)   θ(K)  θv(K) envθv(K)  qv(g/kg) ql(g/kg)  r(m)   mass(kg)"
    )?;
    // About 40 rows; the CSV has every step.
    let every = (run.trajectory.len() / 40).max(1);
    for p in run.trajectory.iter().step_by(every) {
        writeln!(
            out,
            "{:9.0} {:7.0} {:6.1} {:6.1} {:6.1} {:8.1} {:9.2} {:8.2} {:5.0} {:10.3e}",
            p.time_s,
            p.z_m,
            p.t_k - 273.15,
            p.theta_k,
            p.theta_v_k,
            p.env_theta_v_k,
            p.qv_kg_per_kg * 1000.0,
            p.ql_kg_per_kg * 1000.0,
            p.radius_m,
            p.mass_kg
        )?;
    }
    if let Some(path) = &args.csv {
        writeln!(out, "trajectory written to {}", path.display())?;
    }
    Ok(())
}

pub(super) fn to_json(a: &ParcelAscent) -> serde_json::Value {
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

pub(super) fn write_table(
    out: &mut impl std::io::Write,
    s: &Sounding,
    a: &ParcelAscent,
    reports: &[ParcelReport],
    kind: ParcelKind,
) -> std::io::Result<()> {
    if let Some(st) = &s.station {
        writeln!(out, "{st}")?;
    }
    writeln!(
        out,
        "{:<38} {:>6} {:>7} {:>6} {:>8} {:>8} {:>8} {:>10} {:>9}",
        "parcel", "hPa", "T(°C)", "Td(°C)", "LCL hPa", "LFC hPa", "EL hPa", "CAPE J/kg", "CIN J/kg"
    )?;
    let hpa = |m: Option<LevelMark>| match m {
        Some(m) => format!("{:8.1}", m.p_pa / 100.0),
        None => format!("{:>8}", "none"),
    };
    for r in reports {
        writeln!(
            out,
            "{:<38} {:6.1} {:7.1} {:6.1} {} {} {} {:10.0} {:9.0}",
            r.kind.name(),
            r.start_p_pa / 100.0,
            r.start.t_k - 273.15,
            r.start.td_k - 273.15,
            hpa(r.ascent.lcl),
            hpa(r.lfc),
            hpa(r.el),
            r.cape_j_per_kg,
            r.cin_j_per_kg
        )?;
    }
    writeln!(out)?;
    let first = &a.levels[0];
    writeln!(
        out,
        "{} parcel: {:.1} hPa, T {:.1} °C, q_v {:.2} g/kg (station {:.0} m MSL)",
        kind.name(),
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
