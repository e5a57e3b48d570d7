"""Reference diagnostics for tests/cumulus/atmosphere/diagnostics.rs and
indices.rs, computed with MetPy 1.7.1 on the six test soundings and the
constructed capped one, written to diagnostics_reference.txt beside it
(`# sounding PATH` lines naming them, the list the Rust tests use, then
one `sounding key value` line each; `nan` where MetPy has no value).

Parcels as MetPy's `surface_based_cape_cin`, `mixed_layer_cape_cin` and
`most_unstable_cape_cin` build them, passed to `cape_cin` with
`which_lfc="most_cape"` (cumulus' default) and `"bottom"` (MetPy's).
Rows without a dewpoint get the one of cumulus' rule (the relative humidity
of the measured levels around them, held above the last), because MetPy
has no rule of its own; precipitable water uses measured levels only, as
MetPy's `precipitable_water` drops the missing ones. `*.cin_negative` is
CIN computed by hand: the negative part of the virtual-temperature
difference of MetPy's parcel, trapezoids in ln p with the zero crossings
inserted, from the start to the most_cape LFC. Lapse rates are by hand
from the table's temperatures and heights (linear in ln p at 700 and
500 hPa, linear in height at 3 km).

    python3 -m venv /tmp/metpyenv && /tmp/metpyenv/bin/pip install metpy==1.7.1
    /tmp/metpyenv/bin/python tests/reference/metpy/diagnostics_reference.py > tests/reference/metpy/diagnostics_reference.txt
"""
import math
import pathlib
import warnings

import metpy
import metpy.calc as mpcalc
import numpy as np
from metpy.units import units

ROOT = pathlib.Path(__file__).resolve().parents[3]
SOUNDINGS = [
    "profiles/soundings/oun-2011-05-22-12z.txt",
    "profiles/soundings/oun-1999-05-04-00z.txt",
    "tests/data/soundings/metpy-jan20.txt",
    "tests/data/soundings/metpy-nov11.txt",
    "tests/data/soundings/constructed-high-plains.txt",
    "tests/data/soundings/constructed-tropical.txt",
    "tests/data/soundings/constructed-capped.txt",
]


def read(path):
    """(p hPa, z m, T °C, Td °C or nan, direction °, speed kn) of rows with a
    temperature, by plain fixed 7-character columns."""
    rows = []
    for line in path.read_text().splitlines():
        f = [line[i * 7:(i + 1) * 7].strip() for i in range(11)]
        try:
            p, z, t = float(f[0]), float(f[1]), float(f[2])
        except ValueError:
            continue  # header, ruler, or a row without TEMP
        num = lambda s: float(s) if s else math.nan
        rows.append((p, z, t, num(f[3]), num(f[6]), num(f[7])))
    return [np.array(c) for c in zip(*rows)]


def parcels(p, t, td):
    """(key, p, t, td, parcel profile) as MetPy's sb/ml/mu functions build them."""
    yield ("sb",) + mpcalc.parcel_profile_with_lcl(p, t, td)
    depth = 100 * units.hPa
    mp, mt, mtd = mpcalc.mixed_parcel(p, t, td)
    above = p < (p[0] - depth)
    yield ("ml",) + mpcalc.parcel_profile_with_lcl(
        np.concatenate([np.atleast_1d(mp), p[above]]),
        np.concatenate([np.atleast_1d(mt), t[above]]),
        np.concatenate([np.atleast_1d(mtd), td[above]]))
    _, _, _, i = mpcalc.most_unstable_parcel(p, t, td)
    yield ("mu",) + mpcalc.parcel_profile_with_lcl(p[i:], t[i:], td[i:])


def cin_negative(p, t, td, prof, lfc_p):
    """Negative area of T_v,parcel - T_v,env from the start to lfc_p, by hand."""
    lcl_p, _ = mpcalc.lcl(p[0], t[0], td[0])
    w = np.where(p > lcl_p, mpcalc.saturation_mixing_ratio(p[0], td[0]),
                 mpcalc.saturation_mixing_ratio(p, prof))
    tv_parcel = mpcalc.virtual_temperature(prof, w).to("K").m
    tv_env = mpcalc.virtual_temperature_from_dewpoint(p, t, td).to("K").m
    x, y = np.log(p.m), tv_parcel - tv_env
    area = 0.0
    for k in range(len(x) - 1):
        x0, x1, y0, y1 = x[k], x[k + 1], y[k], y[k + 1]
        if p.m[k] <= lfc_p:
            break
        if p.m[k + 1] < lfc_p:  # cut the last segment at the LFC
            f = (math.log(lfc_p) - x0) / (x1 - x0)
            x1, y1 = x0 + f * (x1 - x0), y0 + f * (y1 - y0)
        if y0 <= 0 and y1 <= 0:
            area += 0.5 * (y0 + y1) * (x1 - x0)
        elif y0 < 0 or y1 < 0:
            neg = min(y0, y1)
            area += 0.5 * neg * neg / abs(y1 - y0) * (x1 - x0)
    return -287.04749097718457 * area


def interp_lnp(p, v, at):
    order = np.argsort(np.log(p))
    return float(np.interp(math.log(at), np.log(p)[order], v[order]))


def out(name, key, value):
    v = value.m if hasattr(value, "m") else value
    print(f"{name} {key} {float(v):.4f}")


def main():
    warnings.simplefilter("ignore")
    print(f"# MetPy {metpy.__version__}, numpy {np.__version__}")
    for rel in SOUNDINGS:
        print(f"# sounding {rel}")
    for rel in SOUNDINGS:
        name = pathlib.Path(rel).name
        ph, z, tc, tdc, wdir, wkn = read(ROOT / rel)
        measured = ~np.isnan(tdc)
        # Fill missing dewpoints by cumulus' rule, in height.
        w_sat = mpcalc.saturation_mixing_ratio(ph * units.hPa, tc * units.degC).m
        rh = (mpcalc.saturation_mixing_ratio(ph[measured] * units.hPa,
                                             tdc[measured] * units.degC).m / w_sat[measured])
        w = np.interp(z, z[measured], rh) * w_sat
        e = mpcalc.vapor_pressure(ph * units.hPa, w)
        tdc = np.where(measured, tdc, mpcalc.dewpoint(e).to("degC").m)
        p, t, td = ph * units.hPa, tc * units.degC, tdc * units.degC
        for key, pp, tt, dd, prof in parcels(p, t, td):
            for which in ["most_cape", "bottom"]:
                cape, cin = mpcalc.cape_cin(pp, tt, dd, prof, which_lfc=which)
                suffix = "" if which == "most_cape" else ".bottom"
                out(name, f"{key}.cape{suffix}", cape.to("J/kg"))
                out(name, f"{key}.cin{suffix}", cin.to("J/kg"))
            # cape_cin's own LFC: its parcel and environment in virtual temperature.
            lcl_p, _ = mpcalc.lcl(pp[0], tt[0], dd[0])
            wp = np.where(pp > lcl_p, mpcalc.saturation_mixing_ratio(pp[0], dd[0]),
                          mpcalc.saturation_mixing_ratio(pp, prof))
            lfc_p, _ = mpcalc.lfc(pp, mpcalc.virtual_temperature_from_dewpoint(pp, tt, dd), dd,
                                  parcel_temperature_profile=mpcalc.virtual_temperature(prof, wp),
                                  which="most_cape")
            if not np.isnan(lfc_p.m):
                out(name, f"{key}.lfc_hpa", lfc_p.to("hPa"))
                out(name, f"{key}.cin_negative", cin_negative(pp, tt, dd, prof, lfc_p.to("hPa").m))
        sb_prof = mpcalc.parcel_profile(p, t[0], td[0])
        out(name, "lifted_index", mpcalc.lifted_index(p, t, sb_prof)[0].to("delta_degC"))
        out(name, "k_index", mpcalc.k_index(p, t, td).to("degC"))
        pw = mpcalc.precipitable_water(p[measured], td[measured]).to("mm")
        out(name, "precipitable_water_mm", pw)
        zt = np.interp(z[0] + 3000.0, z, tc)
        out(name, "lapse_0_3km_k_per_km", (tc[0] - zt) / 3.0)
        t7, t5 = interp_lnp(ph, tc, 700.0), interp_lnp(ph, tc, 500.0)
        z7, z5 = interp_lnp(ph, z, 700.0), interp_lnp(ph, z, 500.0)
        if ph[0] >= 700.0:
            out(name, "lapse_700_500_k_per_km", (t7 - t5) / ((z5 - z7) / 1000.0))
        wind = ~np.isnan(wkn)
        if not wind.any():
            continue
        u, v = mpcalc.wind_components(wkn[wind] * units.knot, wdir[wind] * units.deg)
        u, v = u.to("m/s"), v.to("m/s")
        pw_, zw = p[wind], (z[wind] - z[0]) * units.m
        zmsl = z[wind] * units.m
        for top in [1000, 6000]:
            try:
                su, sv = mpcalc.bulk_shear(pw_, u, v, height=zmsl, depth=top * units.m)
                out(name, f"shear_0_{top // 1000}km_m_s", np.hypot(su, sv).to("m/s"))
            except ValueError:
                out(name, f"shear_0_{top // 1000}km_m_s", math.nan)
        try:
            rm, lm, mean = mpcalc.bunkers_storm_motion(pw_, u, v, zmsl)
        except ValueError:
            continue
        out(name, "bunkers_right_u", rm[0].to("m/s"))
        out(name, "bunkers_right_v", rm[1].to("m/s"))
        out(name, "bunkers_left_u", lm[0].to("m/s"))
        out(name, "bunkers_left_v", lm[1].to("m/s"))
        for top in [1000, 3000]:
            _, _, srh = mpcalc.storm_relative_helicity(
                zw, u, v, depth=top * units.m, storm_u=rm[0], storm_v=rm[1])
            out(name, f"srh_0_{top // 1000}km_m2_s2", srh.to("m^2/s^2"))


if __name__ == "__main__":
    main()
