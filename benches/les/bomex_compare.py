#!/usr/bin/env python3
"""Runs profiles/bomex.toml for 6 simulated hours with each entrainment
model and prints, hour by hour and over the LES's windows (hours 3-6, the
quasi-steady state; hour 5-6, the averaging hour of Siebesma et al. 2003's
profiles), the means of cloud base, cloud top, cloud cover and liquid
water path (Markdown),
and the time of the first cloud: the numbers of docs/les.md. Base is the
lowest condensation plane of any cloudy parcel, top the highest sphere top,
cover the fraction of the ground under cloud seen from above (the
simulate CSV's columns), each averaged over the frames of the window.

    cargo build --release
    python3 benches/les/bomex_compare.py [--bin target/release/cumulus] [--out bomex-out]
"""
import argparse
import csv
import os
import subprocess

MODELS = ["paper", "plume", "observed"]
HOURS = 6
DT_S = 5
# Hour by hour (the time series), then the LES's quasi-steady window.
WINDOWS = [(h, h + 1) for h in range(HOURS)] + [(3, 6)]


def simulate(bin_path, scene, hours, out_path, model):
    """`cumulus simulate` of `scene` for `hours` with entrainment `model`
    (seed 1, DT_S steps) to the CSV `out_path`; returns the path."""
    subprocess.run(
        [bin_path, "simulate", scene, "--duration", str(hours * 3600),
         "--dt", str(DT_S), "--seed", "1", "--set", f'physics.entrainment_model="{model}"',
         "--out", out_path],
        check=True, stderr=subprocess.DEVNULL)
    return out_path


def run(bin_path, out_dir, model):
    return simulate(bin_path, "profiles/bomex.toml", HOURS, os.path.join(out_dir, f"bomex_{model}.csv"), model)


def windowed(path):
    rows = list(csv.DictReader(open(path)))
    out = []
    for h0, h1 in WINDOWS:
        sel = [r for r in rows if h0 * 3600 < float(r["time_s"]) <= h1 * 3600]
        cloudy = [r for r in sel if r["cloud_base_m"]]
        mean = lambda xs: sum(xs) / len(xs) if xs else float("nan")
        out.append(((h0, h1),
            mean([float(r["cloud_base_m"]) for r in cloudy]),
            mean([float(r["cloud_top_m"]) for r in cloudy]),
            mean([float(r["cloud_cover"]) for r in sel]),
            mean([float(r["condensed_parcels"]) for r in sel]),
            mean([float(r["liquid_water_path_kg_m2"]) for r in sel]),
        ))
    first = next((float(r["time_s"]) for r in rows if r["cloud_base_m"]), float("nan"))
    return out, first


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default="target/release/cumulus")
    ap.add_argument("--out", default="bomex-out")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    print("| model | hours | cloud base (m) | cloud top (m) | cloud cover (%) | LWP (g/m²) | condensed parcels |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    firsts = []
    for m in MODELS:
        rows, first = windowed(run(args.bin, args.out, m))
        firsts.append((m, first))
        for (h0, h1), base, top, cover, n, lwp in rows:
            label = f"**{h0}–{h1}**" if h1 - h0 > 1 else f"{h0}–{h1}"
            print(f"| {m} | {label} | {base:.0f} | {top:.0f} | {100 * cover:.1f} "
                  f"| {1e3 * lwp:.1f} | {n:.0f} |")
    print()
    for m, first in firsts:
        print(f"first cloud, {m}: {first / 60:.1f} min")


if __name__ == "__main__":
    main()
