#!/usr/bin/env python3
"""Runs tests/data/les/arm_sgp.toml from 11:30 UTC to 01:30 UTC (14 simulated
hours) with each entrainment model and prints, hour by hour, our cloud
cover, base and top beside the eight LES of Brown et al. 2002
(tests/data/les/arm_sgp_les_hourly.csv: mean and range over the models):
the table of docs/les.md. Cover is the mean over all frames, base and top
the means over the frames with cloud (the simulate CSV's columns: the
lowest condensation plane and the highest sphere top of any cloudy
parcel); the first-cloud time of each model follows.

    cargo build --release
    python3 benches/les/arm_sgp_compare.py [--bin target/release/cumulus] [--out arm-out]
"""
import argparse
import csv
import os

from bomex_compare import simulate

MODELS = ["paper", "plume", "observed"]
HOURS = 14
LES = "tests/data/les/arm_sgp_les_hourly.csv"


def run(bin_path, out_dir, model):
    scene = "tests/data/les/arm_sgp.toml"
    return simulate(bin_path, scene, HOURS, os.path.join(out_dir, f"arm_sgp_{model}.csv"), model)


def hourly(path):
    rows = list(csv.DictReader(open(path)))
    mean = lambda xs: sum(xs) / len(xs) if xs else None
    out = []
    for h in range(HOURS):
        sel = [r for r in rows if h * 3600 < float(r["time_s"]) <= (h + 1) * 3600]
        cloudy = [r for r in sel if r["cloud_base_m"]]
        out.append((mean([float(r["cloud_cover"]) for r in sel]),
                    mean([float(r["cloud_base_m"]) for r in cloudy]),
                    mean([float(r["cloud_top_m"]) for r in cloudy])))
    first = next((float(r["time_s"]) for r in rows if r["cloud_base_m"]), None)
    return out, first


def les():
    rows = [l for l in open(LES) if not l.startswith("#")]
    return list(csv.DictReader(rows))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default="target/release/cumulus")
    ap.add_argument("--out", default="arm-out")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    ours = {m: hourly(run(args.bin, args.out, m)) for m in MODELS}
    fmt = lambda v, f: f.format(v) if v is not None else "–"
    for what, i, key, f in [("cloud cover (%)", 0, "cover", "{:.1f}"),
                            ("cloud base (m)", 1, "base", "{:.0f}"),
                            ("cloud top (m)", 2, "top", "{:.0f}")]:
        print(f"\n{what}\n")
        print("| UTC | LES mean (range) | " + " | ".join(MODELS) + " |")
        print("|---|---:|" + "---:|" * len(MODELS))
        for h, row in enumerate(les()):
            scale = 100 if key == "cover" else 1
            get = lambda s: float(row[f"{key}_{s}{'' if key == 'cover' else '_m'}"]) * scale \
                if row[f"{key}_{s}{'' if key == 'cover' else '_m'}"] else None
            les_cell = (f"{fmt(get('mean'), f)} ({fmt(get('min'), f)}–{fmt(get('max'), f)})"
                        if get("mean") is not None else "–")
            t0 = 11.5 + h
            utc = f"{int(t0) % 24:02d}:30–{int(t0 + 1) % 24:02d}:30"
            cells = [fmt(None if ours[m][0][h][i] is None else ours[m][0][h][i] * scale, f)
                     for m in MODELS]
            print(f"| {utc} | {les_cell} | " + " | ".join(cells) + " |")
    print()
    for m in MODELS:
        first = ours[m][1]
        print(f"first cloud, {m}: " + ("none" if first is None else
                                      f"{first / 3600:.2f} h after 11:30 UTC"))


if __name__ == "__main__":
    main()
