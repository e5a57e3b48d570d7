"""Writes the constructed test soundings of tests/data/soundings/ (run by hand).

Each is a list of (pressure hPa, temperature °C, dewpoint °C or None, wind
direction °, wind speed kn or None) chosen by hand to be realistic for its
kind, with levels every 10 hPa between them; heights come from the hypsometric equation with MetPy's virtual
temperature (missing dewpoints count as dry there), so the file is
hydrostatically consistent. Output is the University of Wyoming text table
(PRES HGHT TEMP DWPT ... DRCT SKNT; the derived columns are left blank).

    python3 -m venv /tmp/metpyenv && /tmp/metpyenv/bin/pip install metpy==1.7.1
    /tmp/metpyenv/bin/python tests/reference/metpy/constructed_soundings.py
"""
import math
import pathlib

import metpy.calc as mpcalc
import metpy.constants as mpconsts
from metpy.units import units

ROOT = pathlib.Path(__file__).resolve().parents[3]
OUT = ROOT / "tests" / "data" / "soundings"

# High plains afternoon (a station near 1.5 km, surface 842 hPa): a deep
# well-mixed boundary layer under moist south-easterlies, veering westerlies aloft.
HIGH_PLAINS = ("High plains afternoon, constructed (surface 842 hPa)", 1520.0, [
    (842.0, 33.0, 13.0, 140, 15), (800.0, 28.6, 12.0, 160, 20),
    (750.0, 23.4, 10.0, 190, 22), (700.0, 18.0, 4.0, 220, 25),
    (650.0, 13.0, -3.0, 240, 30), (600.0, 8.0, -8.0, 250, 35),
    (550.0, 2.5, -14.0, 255, 40), (500.0, -3.5, -20.0, 260, 45),
    (450.0, -9.5, -27.0, 265, 52), (400.0, -16.5, -33.0, 265, 60),
    (350.0, -24.5, -40.0, 270, 68), (300.0, -33.5, -48.0, 270, 75),
    (250.0, -43.5, -57.0, 270, 80), (200.0, -54.0, -66.0, 270, 78),
    (150.0, -58.0, -75.0, 270, 65), (100.0, -63.0, -82.0, 270, 45),
])

# Tropical maritime (a Caribbean island, after Jordan's mean hurricane-season
# sounding): no wind columns, and the humidity sensor's data end at 400 hPa.
TROPICAL = ("Tropical maritime, constructed (no dewpoints above 400 hPa, no wind)", 10.0, [
    (1010.0, 28.5, 24.0, None, None), (1000.0, 27.5, 23.2, None, None),
    (950.0, 24.0, 21.0, None, None), (900.0, 20.8, 18.0, None, None),
    (850.0, 17.6, 14.5, None, None), (800.0, 14.6, 10.5, None, None),
    (750.0, 11.6, 6.0, None, None), (700.0, 8.7, 1.5, None, None),
    (650.0, 5.6, -2.5, None, None), (600.0, 2.2, -6.0, None, None),
    (550.0, -1.6, -10.5, None, None), (500.0, -5.9, -15.5, None, None),
    (450.0, -10.8, -21.0, None, None), (400.0, -16.5, -27.0, None, None),
    (350.0, -23.2, None, None, None), (300.0, -31.4, None, None, None),
    (250.0, -41.2, None, None, None), (200.0, -53.1, None, None, None),
    (175.0, -60.1, None, None, None), (150.0, -67.2, None, None, None),
    (125.0, -73.4, None, None, None), (100.0, -75.5, None, None, None),
])

# Capped: a moist surface parcel buoyant through a superadiabatic surface
# layer and past its LCL, a strong inversion at 900-860 hPa, then a steep
# elevated mixed layer and the main buoyant layer above about 650 hPa.
CAPPED = ("Capped, constructed (buoyant surface layer, cap at 900-860 hPa)", 100.0, [
    (1000.0, 30.0, 24.0, 170, 12), (985.0, 27.8, 23.4, 180, 20),
    (950.0, 24.6, 22.2, 190, 28), (925.0, 22.9, 21.0, 200, 32),
    (900.0, 21.2, 19.5, 205, 34), (880.0, 27.0, 10.0, 210, 35),
    (860.0, 29.5, 2.0, 215, 36), (800.0, 22.6, -1.0, 225, 38),
    (750.0, 17.6, -4.0, 235, 40), (700.0, 12.2, -8.0, 240, 42),
    (650.0, 6.6, -12.0, 245, 45), (600.0, 0.8, -16.0, 250, 48),
    (550.0, -5.0, -20.0, 250, 52), (500.0, -11.0, -25.0, 255, 56),
    (400.0, -24.0, -36.0, 260, 65), (300.0, -40.0, -50.0, 260, 75),
    (250.0, -49.5, -58.0, 260, 80), (200.0, -57.0, -66.0, 260, 75),
    (150.0, -61.0, -74.0, 260, 60), (100.0, -64.0, -80.0, 260, 40),
])

FILES = {
    "constructed-high-plains.txt": HIGH_PLAINS,
    "constructed-tropical.txt": TROPICAL,
    "constructed-capped.txt": CAPPED,
}


def densify(rows, step=10.0):
    """The hand-picked points and levels every `step` hPa between them, T, Td
    and wind linear in ln p (a radiosonde reports many levels; coarse ones
    leave the curve between them to the reader's interpolation)."""
    out = []
    for a, b in zip(rows, rows[1:]):
        out.append(a)
        p = a[0] - step
        while p > b[0] + 0.5 * step:
            f = math.log(a[0] / p) / math.log(a[0] / b[0])
            lin = lambda x, y, r: None if x is None or y is None else round(x + (y - x) * f, r)
            out.append((round(p, 1), lin(a[1], b[1], 1), lin(a[2], b[2], 1),
                        lin(a[3], b[3], 0), lin(a[4], b[4], 0)))
            p -= step
    out.append(rows[-1])
    return [(p, t, td, None if d is None else int(d), None if s is None else int(s))
            for p, t, td, d, s in out]


def heights(z0, rows):
    """Hypsometric heights of the rows (virtual temperature, dry where Td is missing)."""
    rd, g = mpconsts.nounit.Rd, mpconsts.nounit.g
    out = [z0]
    tv = []
    for p, t, td, _, _ in rows:
        w = 0.0 if td is None else mpcalc.saturation_mixing_ratio(
            p * units.hPa, td * units.degC).m
        tv.append(mpcalc.virtual_temperature(t * units.degC, w).to("K").m)
    for i in range(1, len(rows)):
        dz = rd * 0.5 * (tv[i - 1] + tv[i]) / g * math.log(rows[i - 1][0] / rows[i][0])
        out.append(out[-1] + dz)
    return out


def field(v, fmt):
    return " " * 7 if v is None else format(fmt.format(v), ">7")


def main():
    for name, (station, z0, rows) in FILES.items():
        rows = densify(rows)
        lines = [station, "",
                 "-" * 77,
                 "   PRES   HGHT   TEMP   DWPT   RELH   MIXR   DRCT   SKNT   THTA   THTE   THTV",
                 "    hPa     m      C      C      %    g/kg    deg   knot     K      K      K ",
                 "-" * 77]
        for (p, t, td, d, s), z in zip(rows, heights(z0, rows)):
            lines.append((field(p, "{:.1f}") + field(round(z), "{:d}") + field(t, "{:.1f}")
                          + field(td, "{:.1f}") + " " * 14 + field(d, "{:d}")
                          + field(s, "{:d}")).rstrip())
        (OUT / name).write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
