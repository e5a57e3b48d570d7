#!/usr/bin/env python3
"""Every render method against the path tracer on several frames.

Runs benches/pathtraced.py (`--settings default`, every `--method`) on each
frame at each size and gathers the default setting's rows into

  error_by_method.csv   frame,width,height,method,mean_flip,rmse,time_ms
  error_by_method.md    rows frame x size, one column of mean FLIP per method

plus one folder per frame and size (FRAME_WxH/) with pathtraced.py's own
output (error_vs_pathtraced.csv, pathtraced.png, the methods' PNGs, ...).

The frames: the fair-weather and towering-cumulus scenes at 1800 s (their
[simulation] start_s) and the two hand-made cloud fields of benches/fields/
(a tower and a deck; make_fields.py), drawn in the fair-weather scene.
Samples per pixel and the Mitsuba variant are what pathtraced.py picks for
the size: at 160x120 its --quick (scalar_rgb, 16 spp), at any other size
its default (256 spp, cuda_ad_rgb where it loads, else scalar_rgb).
`--quick` runs 160x120 only. `--methods` and `--reuse-reference` are passed
to pathtraced.py (measure some methods; reuse the path-traced images of an
earlier run into the same --out).

Usage: python3 benches/pathtraced_frames.py [--quick] --out DIR [--cumulus BIN]
"""

import argparse
import csv
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

# name -> pathtraced.py arguments of the frame.
FRAMES = {
    "fair_weather": ["--scene", os.path.join(ROOT, "profiles", "fair_weather.toml"), "--time", "1800"],
    "towering_cumulus": ["--scene", os.path.join(ROOT, "profiles", "towering_cumulus.toml"), "--time", "1800"],
    "tower": [
        "--scene",
        os.path.join(ROOT, "profiles", "fair_weather.toml"),
        "--parcels",
        os.path.join(HERE, "fields", "tower.csv"),
    ],
    "deck": [
        "--scene",
        os.path.join(ROOT, "profiles", "fair_weather.toml"),
        "--parcels",
        os.path.join(HERE, "fields", "deck.csv"),
    ],
}
SIZES = [(160, 120), (320, 240)]
# The size at which pathtraced.py's --quick settings (scalar_rgb, 16 spp) apply.
QUICK_SIZE = (160, 120)


def fail(msg):
    print(f"pathtraced_frames.py: error: {msg}", file=sys.stderr)
    sys.exit(1)


def write_atomic(path, text):
    tmp = os.path.join(os.path.dirname(path), "." + os.path.basename(path) + ".tmp")
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, path)


def parse_size(s):
    try:
        w, h = (int(v) for v in s.lower().split("x"))
    except ValueError:
        fail(f"--sizes: {s!r} is not WIDTHxHEIGHT")
    return w, h


def method_rows(csv_path):
    """(method, mean_flip, rmse, time_ms) of the `default method=X` rows."""
    out = []
    with open(csv_path, encoding="utf-8") as f:
        for row in csv.DictReader(f):
            setting = row["setting"]
            if setting == "default" or setting.startswith("default method="):
                method = setting.split("=", 1)[1] if "=" in setting else "default"
                out.append((method, float(row["mean_flip"]), float(row["rmse"]), float(row["time_ms"])))
    return out


def markdown(rows, methods):
    lines = ["| frame | size | " + " | ".join(methods) + " |", "|---|---|" + "---:|" * len(methods)]
    table = {}
    for frame, w, h, method, mean, _rmse, _ms in rows:
        table.setdefault((frame, w, h), {})[method] = mean
    for (frame, w, h), by in table.items():
        cells = [f"{by[m]:.3f}" if m in by else "–" for m in methods]
        lines.append(f"| {frame} | {w}×{h} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", required=True, help="output folder")
    ap.add_argument("--quick", action="store_true", help="160x120 only")
    ap.add_argument("--cumulus", help="the cumulus binary (default target/release/cumulus)")
    ap.add_argument("--frames", default=",".join(FRAMES), help=f"comma-separated subset of {', '.join(FRAMES)}")
    ap.add_argument("--sizes", help="comma-separated WIDTHxHEIGHT (default 160x120,320x240)")
    ap.add_argument("--spp", type=int, help="path-traced samples per pixel (default: pathtraced.py's for the size)")
    ap.add_argument("--variant", help="Mitsuba variant (default: pathtraced.py's for the size)")
    ap.add_argument("--max-depth", type=int, help="most scattering events per path (default: pathtraced.py's)")
    ap.add_argument("--voxel", type=float, help="export voxel (m); default: cumulus's")
    ap.add_argument("--methods", help="comma-separated render methods (default: every one)")
    ap.add_argument("--reuse-reference", action="store_true", help="reuse earlier path-traced images in --out")
    a = ap.parse_args()

    frames = [f.strip() for f in a.frames.split(",") if f.strip()]
    for f in frames:
        if f not in FRAMES:
            fail(f"--frames: no frame {f!r} (there are {', '.join(FRAMES)})")
    if a.sizes:
        sizes = [parse_size(s) for s in a.sizes.split(",")]
    else:
        sizes = [QUICK_SIZE] if a.quick else SIZES
    os.makedirs(a.out, exist_ok=True)

    rows, methods = [], []
    t_all = time.time()
    for frame in frames:
        for w, h in sizes:
            out = os.path.join(a.out, f"{frame}_{w}x{h}")
            cmd = [sys.executable, os.path.join(HERE, "pathtraced.py"), "--out", out, "--settings", "default"]
            cmd += FRAMES[frame] + ["--width", str(w), "--height", str(h)]
            cmd += ["--quick"] if (w, h) == QUICK_SIZE else []
            cmd += ["--cumulus", a.cumulus] if a.cumulus else []
            cmd += ["--spp", str(a.spp)] if a.spp else []
            cmd += ["--variant", a.variant] if a.variant else []
            cmd += ["--max-depth", str(a.max_depth)] if a.max_depth else []
            cmd += ["--voxel", str(a.voxel)] if a.voxel else []
            cmd += ["--methods", a.methods] if a.methods else []
            cmd += ["--reuse-reference"] if a.reuse_reference else []
            t0 = time.time()
            p = subprocess.run(cmd, capture_output=True, text=True)
            if p.returncode != 0:
                fail(f"{frame} {w}x{h}: {' '.join(cmd)} failed:\n{p.stderr}")
            for method, mean, rmse, ms in method_rows(os.path.join(out, "error_vs_pathtraced.csv")):
                rows.append((frame, w, h, method, mean, rmse, ms))
                if method not in methods:
                    methods.append(method)
            summary = ", ".join(f"{r[3]} {r[4]:.3f}" for r in rows if r[:3] == (frame, w, h))
            print(f"{frame} {w}x{h} ({time.time() - t0:.0f} s): mean FLIP {summary}", file=sys.stderr)

    text = "frame,width,height,method,mean_flip,rmse,time_ms\n"
    text += "".join(f"{f},{w},{h},{m},{mean:.6f},{rmse:.6f},{ms:.3f}\n" for f, w, h, m, mean, rmse, ms in rows)
    write_atomic(os.path.join(a.out, "error_by_method.csv"), text)
    write_atomic(os.path.join(a.out, "error_by_method.md"), markdown(rows, methods))
    print(f"wrote {os.path.join(a.out, 'error_by_method.csv')} and .md ({time.time() - t_all:.0f} s)", file=sys.stderr)


if __name__ == "__main__":
    main()
