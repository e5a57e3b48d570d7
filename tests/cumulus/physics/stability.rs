//! The quick stability matrix through the real binary, and the kinetic-energy
//! bound it is judged by against a CAPE worked out by hand.

use std::path::Path;

use cumulus::atmosphere::{EnvLevel, Environment, PressureModel, thermo};
use cumulus::physics::{ClampCounts, WorldConfig};
use cumulus::stability::{self, KE_RATIO_BOUND, Size};

use crate::common::cli;

/// `stability::run_matrix` with no progress, one call at a time.
/// run_matrix swaps the process's panic hook for a quiet one while it
/// runs and then puts back the one it found; all tests share this process,
/// so two calls at once could leave the quiet hook installed for good and
/// every later failing test of the binary would print no panic message.
fn run_matrix(cases: &[stability::Case]) -> Vec<stability::CaseResult> {
    static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    stability::run_matrix(cases, |_, _| {})
}

/// `cumulus stability --quick` runs every case to the end without NaN/Inf,
/// panic or kinetic energy beyond the bound, exits 0 and writes both reports.
#[test]
fn quick_matrix_is_stable() {
    let dir = tempfile::tempdir().unwrap();
    let out = cli::run_command(
        cli::command()
            .args(["stability", "--quick", "--out"])
            .arg(dir.path()),
    );
    // Exit 0 and no "panicked" on stderr.
    out.expect_success();
    let stdout = out.stdout();
    assert!(
        stdout.contains("| stiffness_1e6 |"),
        "table printed: {stdout}"
    );

    let md = std::fs::read_to_string(dir.path().join("stability.md")).unwrap();
    assert!(md.contains("failed") && md.contains("| case |"), "{md}");
    let mut rdr = csv::Reader::from_path(dir.path().join("stability.csv")).unwrap();
    let headers = rdr.headers().unwrap().clone();
    let col = |name: &str| headers.iter().position(|h| h == name).unwrap();
    let (case, completed, non_finite, ke_ratio, passed) = (
        col("case"),
        col("completed"),
        col("non_finite"),
        col("ke_ratio"),
        col("passed"),
    );
    let expected = stability::matrix(Size::Quick).unwrap();
    let mut rows = 0;
    for (rec, want) in rdr.records().map(Result::unwrap).zip(&expected) {
        rows += 1;
        assert_eq!(&rec[case], want.name);
        assert_eq!(&rec[completed], "true", "{}", &rec[case]);
        assert_eq!(&rec[non_finite], "0", "{}", &rec[case]);
        let r: f64 = rec[ke_ratio].parse().unwrap();
        assert!(r <= KE_RATIO_BOUND, "{}: KE ratio {r}", &rec[case]);
        assert_eq!(&rec[passed], "true", "{}", &rec[case]);
    }
    assert_eq!(rows, expected.len());
    // The matrix covers every kind of extreme the issue asks for.
    for group in ["stiffness", "dt", "count", "sounding", "wind", "emission"] {
        assert!(expected.iter().any(|c| c.group == group), "{group}");
    }
    for env in stability::ENVIRONMENTS {
        assert!(stability::environment(env).is_ok(), "{env}");
    }
}

/// For a dry parcel 2 K warmer than an isentropic dry atmosphere the bound is
/// exactly its CAPE, g·Δθ/θ·H (no wind, no downdraft, no water).
#[test]
fn energy_bound_is_the_cape_of_the_hottest_parcel() {
    let lv = |z_m| EnvLevel {
        z_m,
        theta_k: 300.0,
        qv_kg_per_kg: 0.0,
        pressure_pa: None,
    };
    let env = Environment::new(
        vec![lv(0.0), lv(10_000.0)],
        100_000.0,
        PressureModel::Hydrostatic,
    )
    .unwrap();
    let cfg = WorldConfig::default();
    let e = stability::specific_energy_bound(&env, &cfg, (300.0, 302.0), 0.0, 0.0);
    let cape = thermo::GRAVITY * 2.0 / 300.0 * 10_000.0;
    // The midpoint sum over 10 m cells of a constant integrand is exact to
    // rounding; 1e-9 relative allows for the summation order.
    assert!((e - cape).abs() < 1e-9 * cape, "{e} vs {cape}");

    // Wind adds ½|w|² and a cold start above the ground adds its fall.
    let mut windy = cfg.clone();
    windy.wind = Some(cumulus::physics::WindConfig {
        aloft_m_s: [30.0, 40.0],
        ..Default::default()
    });
    let e_wind = stability::specific_energy_bound(&env, &windy, (300.0, 302.0), 0.0, 0.0);
    assert!((e_wind - cape - 0.5 * 50.0 * 50.0).abs() < 1e-6 * cape);
    let e_cold = stability::specific_energy_bound(&env, &cfg, (297.0, 302.0), 0.0, 1000.0);
    let fall = thermo::GRAVITY * 3.0 / 300.0 * 1000.0;
    assert!((e_cold - cape - fall).abs() < 1e-6 * cape, "{e_cold}");
}

/// The reports are written whole: a report from an earlier run is replaced
/// atomically, never left half-written (write_atomic renames a complete file).
#[test]
fn reports_replace_old_ones_whole() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("stability.csv"), "old").unwrap();
    let cases: Vec<_> = stability::matrix(Size::Quick)
        .unwrap()
        .into_iter()
        .filter(|c| c.name == "parcels_10")
        .collect();
    let results = run_matrix(&cases);
    assert!(results[0].passed(), "{:?}", results[0].failures());
    let [md, csv] = stability::write_reports(dir.path(), &results, "t").unwrap();
    let text = std::fs::read_to_string(csv).unwrap();
    assert!(text.starts_with("case,group,"), "{text}");
    assert_eq!(text.lines().count(), 2);
    assert!(Path::new(&md).exists());
}

/// What fails a case: a NaN/Inf, kinetic energy beyond the bound, a caught
/// panic, a setup error, a clamp kind it does not declare; escapes,
/// declared clamps alone do not.
#[test]
fn failure_criteria() {
    let cases: Vec<_> = stability::matrix(Size::Quick)
        .unwrap()
        .into_iter()
        .filter(|c| c.name == "parcels_10")
        .collect();
    let ok = run_matrix(&cases).remove(0);
    assert!(ok.passed(), "{:?}", ok.failures());

    let mut r = ok.clone();
    r.escaped_sides = 5;
    assert!(r.passed(), "escapes are reported, not failures");
    r.clamps.speed = 100;
    assert!(
        !r.passed(),
        "speed clamps the case does not declare fail it"
    );
    assert!(
        r.failures()[0].contains("undeclared clamps: speed 100"),
        "{:?}",
        r.failures()
    );
    r.declared_clamps = vec!["speed"];
    assert!(r.passed(), "declared clamps are reported, not failures");

    let mut r = ok.clone();
    r.non_finite = 1;
    assert!(!r.passed());
    let mut r = ok.clone();
    r.ke_ratio = KE_RATIO_BOUND * 1.01;
    assert!(!r.passed());
    let mut r = ok.clone();
    r.ke_ratio = f64::NAN;
    assert!(!r.passed(), "a NaN ratio is not within the bound");
    let mut r = ok.clone();
    r.atm_work_share = 1.01;
    assert!(
        r.failures()[0].contains("a-priori bound E_cap"),
        "cap work above its a-priori bound fails: {:?}",
        r.failures()
    );
    let mut r = ok.clone();
    r.panic = Some("boom".into());
    r.completed = false;
    assert!(r.failures()[0].contains("boom"));
    let mut r = ok.clone();
    r.error = Some("bad".into());
    r.completed = false;
    assert!(!r.passed());

    // The table says so, and so does the CSV.
    let md = stability::to_markdown(&[ok.clone(), r.clone()], "t");
    assert!(
        md.contains("1 failed") && md.contains("**FAIL**: setup error: bad"),
        "{md}"
    );
    let csv = stability::to_csv(&[ok, r]);
    assert!(
        csv.lines()
            .nth(2)
            .unwrap()
            .contains(",false,\"setup error: bad\""),
        "{csv}"
    );
}

/// The cap force's work is bounded a priori (E_cap, src/stability/run.rs):
/// a tight cluster of overlapping parcels in neutral air, at the largest
/// weight the physics allows (10: ten times the overlap's own Archimedes
/// force), sinks under nothing but that force, and its measured work stays
/// under E_cap — and is a real part of it, so the bound is not vacuous.
#[test]
fn cap_work_stays_under_its_a_priori_bound() {
    let lv = |z_m| EnvLevel {
        z_m,
        theta_k: 300.0,
        qv_kg_per_kg: 0.0,
        pressure_pa: None,
    };
    let env = Environment::new(
        vec![lv(0.0), lv(10_000.0)],
        100_000.0,
        PressureModel::Hydrostatic,
    )
    .unwrap();
    let mut config = WorldConfig::default();
    config.physics.mixing = false;
    config.physics.atm_pressure_weight = 10.0;
    config.emission.enabled = false;
    let case = stability::Case {
        name: "cap_sink".into(),
        group: "test",
        note: "overlapping parcels sink under the cap force".into(),
        env,
        config,
        frame_dt_s: 1.0,
        frames: 60,
        cluster: Some(stability::Cluster {
            count: 8,
            base_m: glam::DVec3::new(0.0, 0.0, 3000.0),
            spacing_m: 120.0,
            radius_m: 150.0,
            theta_excess_k: 0.0,
            qv_excess: 0.0,
        }),
        seed: 1,
        // Ten times the lens's weight drags the cluster past the speed cap.
        declared_clamps: vec!["atm_force", "speed"],
    };
    let r = stability::run_case(&case, |_| {});
    eprintln!(
        "W_atm {:.3e} J, share of E_cap {:.4}, KE ratio {:.4}, failures {:?}",
        r.atm_work_j,
        r.atm_work_share,
        r.ke_ratio,
        r.failures()
    );
    assert!(r.atm_work_j > 0.0, "the cap force must do work here");
    // passed() includes W_atm ≤ E_cap (0.43 of it is used here).
    assert!(r.passed(), "{:?}", r.failures());
    // A 3 km fall of a 10 km column's bound, slowed by drag and the speed
    // cap, uses 0.43 of E_cap: above 0.1 shows the bound is within an order
    // of magnitude of what the force does, so it still polices a blow-up.
    assert!(
        r.atm_work_share > 0.1,
        "E_cap is vacuous: {}",
        r.atm_work_share
    );
}

/// The gate can fail: a deliberately unstable case (the stiffest SPH the
/// physics allows, K = 1e6, in a tightly packed cluster, forced through
/// one sub-step per 2 s frame where the sound-speed limit asks for
/// many) blows up without the speed cap: measured KE ratio 1363, parcels
/// at 173 km/s. With the cap its KE ratio is 5e-4 (the cap alone bounds
/// it: ½M(80 m/s)² is far below the SPH energy the packing stores), so
/// only the uncapped rerun shows the blow-up, and it fails the case.
#[test]
fn the_uncapped_rerun_fails_a_case_the_cap_would_pass() {
    let env = stability::environment("fair_weather").unwrap();
    let mut config = WorldConfig::default();
    config.emission.enabled = false;
    config.physics.stiffness = 1.0e6;
    config.physics.max_substeps = 1;
    let h = config.physics.support_radius_m;
    let case = stability::Case {
        name: "overlong_substeps".into(),
        group: "test",
        note: "K = 1e6, one sub-step per 2 s frame".into(),
        env,
        config,
        frame_dt_s: 2.0,
        frames: 60,
        cluster: Some(stability::Cluster {
            count: 27,
            base_m: glam::DVec3::new(0.0, 0.0, 3000.0),
            spacing_m: 0.5 * h,
            radius_m: 0.5 * h,
            theta_excess_k: 0.0,
            qv_excess: 0.0,
        }),
        seed: 5,
        // Declared so that only the energy and the NaN/Inf checks judge it.
        declared_clamps: ClampCounts::default().kinds().map(|(k, _)| k).to_vec(),
    };
    let r = stability::run_case(&case, |_| {});
    let u = r
        .uncapped
        .clone()
        .expect("a case declaring `speed` is rerun uncapped");
    eprintln!(
        "capped: KE ratio {:.3e}, max speed {:.1} m/s, clamps {}; uncapped: {u:?}; failures {:?}",
        r.ke_ratio,
        r.max_speed_m_s,
        r.clamps,
        r.failures()
    );
    let mut capped_only = r.clone();
    capped_only.uncapped = None;
    assert!(
        capped_only.passed(),
        "the capped run alone must pass, or this does not show what the gate adds: {:?}",
        capped_only.failures()
    );
    assert!(
        !u.failures().is_empty(),
        "the uncapped run must blow up: {u:?}"
    );
    assert!(!r.passed());
    assert!(
        r.failures()
            .iter()
            .all(|f| f.starts_with("without the speed cap")),
        "{:?}",
        r.failures()
    );
}
