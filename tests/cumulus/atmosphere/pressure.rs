//! The hydrostatic pressure needs no floor (issue 12, item 7): a profile too
//! cold for its height is an error, and above its table the pressure decays
//! isothermally, staying positive, continuous and decreasing.

use cumulus::atmosphere::{EnvLevel, Environment, PressureModel};

fn cold(top_m: f64) -> Result<Environment, cumulus::Error> {
    // θ = 150 K, the coldest a level may have: Π falls by g/(c_p θ) ≈ 6.5e-5
    // per metre and reaches 0 near 15.4 km from 1000 hPa.
    let level = |z_m| EnvLevel {
        z_m,
        theta_k: 150.0,
        qv_kg_per_kg: 0.0,
        pressure_pa: None,
    };
    Environment::new(
        vec![level(0.0), level(top_m)],
        100_000.0,
        PressureModel::Hydrostatic,
    )
}

#[test]
fn a_profile_too_cold_for_its_height_is_an_error() {
    let e = cold(20_000.0).expect_err("zero pressure below the top");
    let msg = e.to_string();
    assert!(msg.contains("hydrostatic pressure"), "{msg}");
    assert!(msg.contains("below the top at 20000 m"), "{msg}");
}

#[test]
fn pressure_above_the_table_stays_positive_and_continuous() {
    // Top at 12 km: Π reaches 0 inside the 10 km margin above it, where the
    // table stops and the isothermal continuation takes over.
    let env = cold(12_000.0).unwrap();
    let mut prev = env.pressure_pa(0.0);
    let mut z = 0.0;
    while z < 60_000.0 {
        z += 1.0;
        let p = env.pressure_pa(z);
        assert!(p > 0.0 && p.is_finite(), "P({z} m) = {p}");
        assert!(p < prev, "P must fall with height: P({z} m) = {p} ≥ {prev}");
        // Continuity: 1 m of a hydrostatic column changes P by ρg ≈ 0.2 Pa at
        // most here (0.1 kg m⁻³ is the densest air above 12 km, and below
        // it 1000 hPa at 150 K gives 2.3 kg m⁻³: 23 Pa); a jump at the table's
        // end would be larger than 30 Pa or, near its tiny values, a ratio.
        assert!(
            prev - p < 30.0 && p > 0.5 * prev,
            "jump at {z} m: {prev} → {p}"
        );
        prev = p;
    }
}
