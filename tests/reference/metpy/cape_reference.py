"""Reference CAPE and CIN for tests/cumulus/atmosphere/cape.rs, computed with MetPy.

For the surface-based, mixed-layer (lowest 100 hPa) and most-unstable
(lowest 300 hPa) parcels of the two shipped soundings, prints the parcel's
start (pressure, temperature, dewpoint), MetPy's CAPE and CIN (`cape_cin`
corrects both profiles to virtual temperature) and its LCL, as Rust array
literals to paste into the test. The soundings are read with the same plain
fixed-width reader as parcel_reference.py (independent of the Rust one).

    python3 -m venv /tmp/metpyenv && /tmp/metpyenv/bin/pip install metpy==1.7.1
    /tmp/metpyenv/bin/python tests/reference/metpy/cape_reference.py > tests/reference/metpy/cape_reference.txt
"""
import metpy
import metpy.calc as mpcalc
import numpy as np

from parcel_reference import ROOT, SOUNDINGS, read


def parcels(p, t, td):
    """(key, start p, start T, start Td, CAPE, CIN) of MetPy's three parcels."""
    sb = mpcalc.surface_based_cape_cin(p, t, td)
    yield "sb", p[0], t[0], td[0], *sb
    ml_p, ml_t, ml_td = mpcalc.mixed_parcel(p, t, td)
    yield "ml", ml_p, ml_t, ml_td, *mpcalc.mixed_layer_cape_cin(p, t, td)
    mu_p, mu_t, mu_td, _ = mpcalc.most_unstable_parcel(p, t, td)
    yield "mu", mu_p, mu_t, mu_td, *mpcalc.most_unstable_cape_cin(p, t, td)


def main():
    print(f"# MetPy {metpy.__version__}, numpy {np.__version__}")
    print("# (sounding, parcel, start_hpa, start_t_c, start_td_c, lcl_hpa, cape_j_per_kg, cin_j_per_kg)")
    for name in SOUNDINGS:
        p, t, td = read(ROOT / "profiles" / "soundings" / name)
        for key, sp, st, std, cape, cin in parcels(p, t, td):
            lcl_p, _ = mpcalc.lcl(sp, st, std)
            print(
                f'    ("{name}", "{key}", {sp.to("hPa").m:.2f}, {st.to("degC").m:.3f}, '
                f'{std.to("degC").m:.3f}, {lcl_p.to("hPa").m:.2f}, '
                f'{cape.to("J/kg").m:.1f}, {cin.to("J/kg").m:.1f}),'
            )


if __name__ == "__main__":
    main()
