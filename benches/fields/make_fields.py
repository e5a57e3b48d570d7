#!/usr/bin/env python3
"""Writes the hand-made cloud fields of the path-traced comparison
(benches/pathtraced_frames.py), deterministically (fixed seeds):

  tower.csv   one towering cumulus: a column about 2 km wide from a flat
              base at 1.2 km to a billowy top near 7.5 km
  deck.csv    a stratocumulus-like deck: cells about 1.2 km apart over
              10 x 10 km, 1.1-1.9 km high, with gaps, the camera under
              its southern edge

Both are placed for the fair-weather scene's camera (profiles/fair_weather.toml:
8.5 km south of the centre, 600 m up, looking north), which draws parcels at
2.5 times their radius. Parcel radii follow the towering-cumulus scene's
saved field at 1800 s (`cumulus render profiles/towering_cumulus.toml
--save-parcels`): about 166 m at 1.5 km falling to 99 m at 8.5 km; fill 1
except near the base; each parcel's condensation plane at the cloud base for
the lowest ones (the flat base), and well below the parcel higher up.

The format is cumulus's cloud-field file (src/physics/cloud_file.rs):
id,x_m,y_m,z_m,radius_m,fill,cond_plane_z_m

Usage: python3 benches/fields/make_fields.py   (rewrites both files next to it)
"""

import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
HEADER = "id,x_m,y_m,z_m,radius_m,fill,cond_plane_z_m"


def radius_at(z):
    """Parcel radius (m) at height z (m): the towering-cumulus field's fit."""
    return 180.0 - 0.0096 * z


def plane_for(z, base, rng):
    """Condensation plane (m): the cloud base (a little jitter) for parcels
    near it, rising with height above (as the saved field's, which lie
    1-3.5 km below their parcels)."""
    if z < base + 600.0:
        return base + rng.uniform(-20.0, 20.0)
    return base + 0.6 * (z - base)


def tower(rng):
    """A column centred at (1500, 4000) m: flat base 1.2 km, the body
    widening from 0.85 to 1.0 km radius, a dome from 5.5 km with four
    turrets to about 7.5 km."""
    cx, cy, base = 1500.0, 4000.0, 1200.0
    rows = []

    def add(x, y, z, fill):
        rows.append((x, y, z, radius_at(z) * rng.uniform(0.9, 1.1), fill, plane_for(z, base, rng)))

    # The body: uniform in the column, radius R(z).
    while len(rows) < 320:
        z = rng.uniform(base + 150.0, 6300.0)
        grow = min(1.0, (z - base) / 2500.0)
        top = max(0.0, (z - 5500.0) / 1000.0)  # the dome narrows it
        R = (850.0 + 150.0 * grow) * np.sqrt(max(0.0, 1.0 - top * top * 0.6))
        r, a = R * np.sqrt(rng.uniform()), rng.uniform(0.0, 2.0 * np.pi)
        fill = rng.uniform(0.6, 1.0) if z < base + 400.0 else 1.0
        add(cx + r * np.cos(a), cy + r * np.sin(a), z, fill)
    # The turrets: clusters of parcels rising out of the dome.
    for k, (dx, dy, top) in enumerate([(-350, 150, 7300), (300, -250, 7000), (100, 400, 6800), (450, 350, 6600)]):
        for _ in range(22):
            z = rng.uniform(6000.0, top)
            s = 380.0 * (1.0 - 0.5 * (z - 6000.0) / (top - 6000.0))
            add(cx + dx + rng.normal(0.0, s / 2), cy + dy + rng.normal(0.0, s / 2), z, 1.0)
    return rows


def deck(rng):
    """Cells on a jittered 1.2 km grid over 10 x 10 km centred at
    (-1500, 5000) m, so that the camera, 8.5 km south of the domain centre,
    sees the deck from a distance: its front edge, its underside receding
    to the horizon and its top beyond; about a
    quarter of them left out (the gaps); each cell 5-10 parcels with
    centres 1.3-1.65 km (a layer 1.1 to about 1.9-2.0 km: the drawn spheres
    reach 2.5 radii out), the base flat at 1.1 km."""
    base = 1100.0
    rows = []
    for gx in np.arange(-4800.0, 4801.0, 1200.0):
        for gy in np.arange(-4800.0, 4801.0, 1200.0):
            if rng.uniform() < 0.25:
                continue
            cx, cy = -1500.0 + gx + rng.uniform(-250, 250), 5000.0 + gy + rng.uniform(-250, 250)
            for _ in range(rng.integers(5, 11)):
                z = rng.uniform(1300.0, 1650.0)
                x, y = cx + rng.normal(0.0, 280.0), cy + rng.normal(0.0, 280.0)
                fill = rng.uniform(0.5, 1.0) if z < 1400.0 else 1.0
                r = radius_at(z) * rng.uniform(0.85, 1.05)
                rows.append((x, y, z, r, fill, base + rng.uniform(-15.0, 15.0)))
    return rows


def write(name, rows, comment):
    path = os.path.join(HERE, name)
    lines = [f"# {comment}", HEADER]
    for i, (x, y, z, r, fill, plane) in enumerate(rows):
        lines.append(f"{i},{x:.1f},{y:.1f},{z:.1f},{r:.1f},{fill:.3f},{plane:.1f}")
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")
    os.replace(tmp, path)
    print(f"{path}: {len(rows)} parcels")


def main():
    t = tower(np.random.default_rng(32))
    write("tower.csv", t, f"benches/fields/make_fields.py: one towering cumulus, {len(t)} parcels")
    d = deck(np.random.default_rng(33))
    write("deck.csv", d, f"benches/fields/make_fields.py: a stratocumulus-like deck, {len(d)} parcels")


if __name__ == "__main__":
    main()
