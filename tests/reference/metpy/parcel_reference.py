"""Reference values for tests/cumulus/atmosphere/metpy.rs, computed with MetPy.

Reads the two shipped soundings with a plain fixed-width reader (independent
of the Rust one), lifts the surface parcel with MetPy's `lcl` and
`parcel_profile` (dry adiabat to the LCL, pseudo-adiabat above), and prints
Rust array literals to paste into the test.

    python3 -m venv /tmp/metpyenv && /tmp/metpyenv/bin/pip install metpy
    /tmp/metpyenv/bin/python tests/reference/metpy/parcel_reference.py > tests/reference/metpy/parcel_reference.txt
"""
import pathlib

import metpy
import metpy.calc as mpcalc
import numpy as np
from metpy.units import units

ROOT = pathlib.Path(__file__).resolve().parents[3]
SOUNDINGS = ["oun-2011-05-22-12z.txt", "oun-1999-05-04-00z.txt"]


def read(path):
    p, t, td = [], [], []
    for line in path.read_text().splitlines():
        f = [line[i * 7:(i + 1) * 7].strip() for i in range(11)]
        try:
            vals = [float(x) for x in f[:4]]
        except ValueError:
            continue  # header, ruler, or a row without TEMP/DWPT
        p.append(vals[0])
        t.append(vals[2])
        td.append(vals[3])
    return np.array(p) * units.hPa, np.array(t) * units.degC, np.array(td) * units.degC


def main():
    print(f"# MetPy {metpy.__version__}, numpy {np.__version__}")
    for name in SOUNDINGS:
        p, t, td = read(ROOT / "profiles" / "soundings" / name)
        lcl_p, lcl_t = mpcalc.lcl(p[0], t[0], td[0])
        prof = mpcalc.parcel_profile(p, t[0], td[0]).to("K")
        print(f"# {name}: surface {p[0]:~P}, {t[0]:~P}, {td[0]:~P}")
        print(f"LCL_HPA = {lcl_p.to('hPa').m:.3f}; LCL_T_K = {lcl_t.to('K').m:.3f}")
        # MetPy's LFC/EL compare plain temperatures of a pseudo-adiabatic parcel
        # (no virtual correction, no condensate): for context, not equality.
        lfc_p, _ = mpcalc.lfc(p, t, td, prof, which="bottom")
        el_p, _ = mpcalc.el(p, t, td, prof)
        print(f"LFC_HPA = {lfc_p.to('hPa').m:.3f}; EL_HPA = {el_p.to('hPa').m:.3f}")
        print("LEVELS (p_hpa, parcel_t_k) = [")
        for pp, tt in zip(p.to("hPa").m, prof.m):
            print(f"    ({pp:.1f}, {tt:.3f}),")
        print("]")


if __name__ == "__main__":
    main()
