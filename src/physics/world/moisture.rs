//! Stages 2 and 7 and the end-of-frame thermodynamics: volume (eq 6),
//! condensation with latent heat (eqs 1, 3), the filling ratio and the
//! condensation plane.

use super::ClampCounts;
use crate::atmosphere::lifting::{
    condensation_level_m, saturation_excess, saturation_level_between,
};
use crate::atmosphere::{Environment, thermo};
use crate::physics::PhysicsConfig;
use crate::physics::parcel::{Parcel, sphere_radius_m, sphere_volume_m3};

/// eq 6 for one parcel: V₂ = V₁ (P₁/P₂)^{1/γ} (m₂/m₁), then r from V,
/// and the humidity guards.
pub(super) fn update_volume(p: &mut Parcel, c: &PhysicsConfig) -> ClampCounts {
    let mut clamps = ClampCounts::default();
    // Guard: no stage makes a mixing ratio negative (mixing scales,
    // exchange mixes convexly, condensation adjusts within the
    // parcel's water); rounding could, and is counted.
    if p.qv_kg_per_kg < 0.0 {
        p.qv_kg_per_kg = 0.0;
        clamps.negative_humidity += 1;
    }
    if p.ql_kg_per_kg < 0.0 {
        p.ql_kg_per_kg = 0.0;
        clamps.negative_humidity += 1;
    }
    let p2 = p.env_at_centre.0;
    let m2 = p.total_mass_kg();
    let (p1, m1) = p.volume_ref;
    if p1 != p2 {
        // P₁/P₂ = 1 + (P₁ − P₂)/P₂, one sub-step's change: within 1e-3 of 1.
        p.volume_m3 *= thermo::pow_1p((p1 - p2) / p2, 1.0 / c.gamma) * (m2 / m1);
        p.volume_ref = (p2, m2);
    } else if m1 != m2 {
        // Same pressure (the corrector's mass change): no power needed.
        p.volume_m3 *= m2 / m1;
        p.volume_ref = (p2, m2);
    }
    let r = sphere_radius_m(p.volume_m3);
    let rc = r.clamp(c.min_radius_m, c.max_radius_m);
    if rc != r || !r.is_finite() {
        let rc = if r.is_finite() { rc } else { c.min_radius_m };
        clamps.radius += 1;
        p.volume_m3 = sphere_volume_m3(rc);
        p.radius_m = rc;
    } else {
        p.radius_m = r;
    }
    clamps
}

/// Condensation/evaporation of one parcel at its pressure with latent heat
/// (α = latent_heat_alpha), by thermo's saturation adjustment.
///
/// The heat of the water condensed over the sub-step is that of
/// dθ = α L dq_l/(c_p Π) (first law for the moist parcel); Π changed over
/// the sub-step from Π₁ (last adjustment) to Π₂ (now). The adjustment at
/// the new pressure finds how much condenses; its heat is then given with
/// the mean 1/Π of the two ends (the trapezoidal rule) rather than with
/// 1/Π₂ alone, which is a first-order rule and made the whole physics first
/// order. The parcel's T then differs from the adjusted T by
/// α L c/c_p (Π₂/Π̄ − 1), O(dt²); the next adjustment takes it up.
pub(super) fn condense(p: &mut Parcel, alpha: f64) -> ClampCounts {
    let (pr, ex) = (p.env_at_centre.0, p.env_at_centre.2);
    let t = p.theta_k * ex;
    let a = thermo::saturation_adjust(t, p.qv_kg_per_kg, p.ql_kg_per_kg, pr, alpha);
    if a.condensed != 0.0 || a.ql != p.ql_kg_per_kg {
        // a.t_k − t = α L c/c_p: the latent heat, as a temperature.
        let mean_inv_exner = 0.5 * (1.0 / ex + 1.0 / p.exner_adjusted);
        p.theta_k += (a.t_k - t) * mean_inv_exner;
        p.qv_kg_per_kg = a.qv;
        p.ql_kg_per_kg = a.ql;
    }
    p.exner_adjusted = ex;
    ClampCounts {
        saturation_cap: a.clamped as u64,
        ..ClampCounts::default()
    }
}

/// Filling ratio f = liquid water content / opaque content (paper §6.1:
/// f = (ω − ω_s)/(V_1kg q_l0)). It grows with q_l and decays as the liquid
/// evaporates. Past the opaque content the parcel is fully opaque: f = 1
/// and `true` (counted as `opaque`; the physics keeps all the water).
pub(super) fn fill_ratio(p: &Parcel, opaque_lwc_kg_m3: f64) -> (f64, bool) {
    let f = p.ql_kg_per_kg.max(0.0) * p.dry_mass_kg / p.volume_m3 / opaque_lwc_kg_m3;
    if f > 1.0 { (1.0, true) } else { (f, false) }
}

/// Height where this parcel's own air saturates when lifted
/// dry-adiabatically: the level where ω_s(θ_l Π, P) equals its total
/// water. θ_l and q_t are conserved by motion and condensation, so the
/// plane is the base of its cloud and a cluster of the same air gets one
/// flat base; mixing and exchange move it. Searched below `z_max`. units: m
pub(super) fn condensation_plane_m(env: &Environment, z_max: f64, p: &Parcel) -> f64 {
    let qt = p.qv_kg_per_kg + p.ql_kg_per_kg;
    // Warm start: the plane moves little between frames, so a secant
    // iteration from the last plane usually converges in 2–4 steps to
    // 1e-4 m; otherwise bisect in a 64 m bracket around the last plane
    // (19 halvings to the same resolution), else over the whole column.
    let excess = |z: f64| saturation_excess(env, p.theta_l_k, qt, z);
    let (mut z0, mut z1) = (p.cond_plane_z_m, p.cond_plane_z_m + 1.0);
    if z0 > 1.0 && z1 < z_max - 1.0 {
        let (mut f0, mut f1) = (excess(z0), excess(z1));
        for _ in 0..6 {
            let slope = (f1 - f0) / (z1 - z0);
            // ω_s falls with height: a non-negative slope means trouble.
            if !(slope < 0.0) {
                break;
            }
            let z2 = z1 - f1 / slope;
            if !(z2 > 0.0 && z2 < z_max) {
                break;
            }
            if (z2 - z1).abs() < 1e-4 {
                return z2;
            }
            (z0, f0) = (z1, f1);
            (z1, f1) = (z2, excess(z2));
        }
    }
    let (lo, hi) = (p.cond_plane_z_m - 32.0, p.cond_plane_z_m + 32.0);
    if lo > 0.0 && hi < z_max && excess(lo) > 0.0 && !(excess(hi) > 0.0) {
        return saturation_level_between(env, p.theta_l_k, qt, lo, hi, 19);
    }
    condensation_level_m(env, p.theta_l_k, qt, z_max)
}
