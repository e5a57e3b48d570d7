#!/usr/bin/env python3
"""Error of cumulus's real-time picture against a path-traced reference.

Exports one fixed frame with `cumulus export` (the density of eq. 18 on a
grid plus a JSON sidecar), path-traces it with Mitsuba 3's `volpath`
(multiple scattering, the renderer's two-lobe Henyey-Greenstein phase,
albedo 1, the same sun and a sky environment map of the same sky-view table),
renders the same frame with `cumulus render` at each setting of the error
sweep (and each `--method` the binary offers), and writes

  error_vs_pathtraced.csv   setting,time_ms,mean_flip,rmse
  pathtraced.png            the path tracer, tone-mapped like ours
  pathtraced.exr            its linear radiance (before the tone map)
  ours.png                  cumulus at the default setting
  flip.png                  FLIP error map of ours against pathtraced.png
  side_by_side.png          the three above, left to right

Exposure is matched by construction: the path-traced radiance goes through
the renderer's own tone curve, display = filmic(k L) then sRGB, with k from
the sidecar; mean FLIP (flip-evaluator, LDR) and RMSE compare the displayed
sRGB values on 0..1 (ours exists only as 8-bit display values).

Terrain is switched off in both (Mitsuba gets no ground): the comparison is
clouds against sky. `--quick` uses a CPU variant at a small size.
`--methods slices,baked` renders only those methods. `--reuse-reference`
takes the path-traced radiance from an earlier run into the same --out
(pathtraced.npy) when its key (pathtraced.key: a hash of the exported
grid, its sidecar and the path tracer's settings) is the same, so methods
can be re-measured without path tracing again. With `--cloud-only` it also
prints the floor of that measure: the error of the reference against
itself box-blurred over 3, 5 and 7 pixels, which an image with the
reference's shading but none of its detail finer than that would score.

Usage: python3 benches/pathtraced.py [--quick] --out DIR [--cumulus BIN]
Requirements: pip install -r benches/requirements.txt
"""

import argparse
import json
import math
import os
import re
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

# Growth of the light-march steps (shaders/raymarch/lighting.wgsl LIGHT_GROWTH).
LIGHT_GROWTH = 1.6

# `--cloud-only`: a pixel has cloud when the exported density lets less
# than this through along its ray (2 % extinction: the faintest wisp a
# display shows over the sky, about 1/255 of its brightness or more).
CLOUD_ONLY_T = 0.98

# Albedo of the `--ground` plane: the mean of the terrain's meadow (0.06,
# 0.10, 0.035) and field (0.10, 0.13, 0.05) albedos (shaders/terrain.wgsl
# `ground`), which its noise mixes about half and half.
GROUND_ALBEDO = [0.08, 0.115, 0.0425]


def sweep_settings(scene_path):
    """The error sweep's settings as `[render]` overrides of the scene: the
    quick plan of src/bench/mod.rs, with the view march covering the same
    length at another step and the light-step rows keeping the scene's light
    march length (first step from the geometric series, at least 1 m, as
    src/bench/accuracy.rs `with_step` and `with_light_steps` do)."""
    import tomllib

    with open(scene_path, "rb") as f:
        r = tomllib.load(f).get("render", {})
    step, max_steps = r.get("step_m", 40.0), r.get("max_steps", 160)
    n0, first0 = r.get("light_steps", 4), r.get("light_step_m", 90.0)
    reach = first0 * (LIGHT_GROWTH**n0 - 1) / (LIGHT_GROWTH - 1)
    octaves = r.get("noise_octaves", 4)
    out = [("default", {})]
    for f in (2.0, 0.5):
        s = step * f
        out.append((f"step_m={s:g}", {"step_m": s, "max_steps": min(4096, math.ceil(step * max_steps / s))}))
    for o in sorted({2, 6} - {octaves}):
        out.append((f"noise_octaves={o}", {"noise_octaves": o}))
    for n in sorted({1, 2, 8} - {n0}):
        first = max(1.0, reach * (LIGHT_GROWTH - 1) / (LIGHT_GROWTH**n - 1))
        out.append((f"light_steps={n}", {"light_steps": n, "light_step_m": round(first, 3)}))
    out.append(("early_exit_transmittance=0", {"early_exit_transmittance": 0.0}))
    return out


def fail(msg):
    print(f"pathtraced.py: error: {msg}", file=sys.stderr)
    sys.exit(1)


def find_cumulus(given):
    path = given or os.path.join(ROOT, "target", "release", "cumulus")
    if not os.access(path, os.X_OK):
        fail(f"{path}: no cumulus binary (build it: cargo build --release, or pass --cumulus)")
    return path


def scene_text(base_scene, overrides, terrain):
    """The scene TOML with `[render]` keys replaced by `overrides`, the
    terrain switched on or off ("flat": on, flat at z = 0, no lake), and no
    aerial perspective: Mitsuba's scene has no air between the eye and the
    clouds (only the sky's radiance at infinity), so ours leaves it out too."""
    with open(base_scene, encoding="utf-8") as f:
        lines = f.read().splitlines()
    out, table = [], None
    extra = {"aerial_perspective": "false", **overrides}
    ground = {"enabled": str(bool(terrain)).lower()}
    if terrain == "flat":
        ground["height_scale_m"] = "0.0"
    dropped = set(ground) | ({"water_level_m"} if terrain == "flat" else set())
    ground_lines = "".join(f"\n{k} = {v}" for k, v in ground.items())
    base_dir = os.path.dirname(os.path.abspath(base_scene))
    for line in lines:
        # The copy is written elsewhere: a sounding named relative to the
        # scene's folder is named by its absolute path.
        s = re.match(r'^(\s*sounding\s*=\s*)"([^"]+)"(.*)$', line)
        if s and not os.path.isabs(s.group(2)):
            line = f'{s.group(1)}"{os.path.join(base_dir, s.group(2))}"{s.group(3)}'
        m = re.match(r"^\s*\[([^\]]+)\]\s*$", line)
        if m:
            table = m.group(1).strip()
            out.append(line)
            if table == "render":
                out += [f"{k} = {v}" for k, v in extra.items()]
            continue
        key = line.split("=")[0].strip() if "=" in line else None
        if table == "render" and key in extra:
            continue
        if table == "render.terrain" and key in dropped:
            continue
        out.append(line)
    text = "\n".join(out) + "\n"
    if "[render.terrain]" in text:
        text = text.replace("[render.terrain]", "[render.terrain]" + ground_lines, 1)
    else:
        text += "\n[render.terrain]" + ground_lines + "\n"
    return text


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        fail(f"{' '.join(cmd)} failed:\n{p.stderr}")
    return p.stderr


def render_methods(cumulus):
    """Values of `cumulus render --method`, or [None] when it has none: the
    help's `[possible values: ...]` list where clap prints one, else the
    names the error for an unknown method lists (`one of "baked", ...`)."""
    p = subprocess.run([cumulus, "render", "--help"], capture_output=True, text=True)
    help_text = p.stdout + p.stderr
    if "--method" not in help_text:
        return [None]
    m = re.search(r"--method[^\[\n]*\[possible values: ([^\]]+)\]", help_text)
    if m:
        return [v.strip() for v in m.group(1).split(",")]
    p = subprocess.run([cumulus, "render", "--method", "?", "none.toml"], capture_output=True, text=True)
    m = re.search(r"one of ((?:\"[a-z_]+\"(?:, )?)+)", p.stderr)
    if not m:
        fail(f"cannot tell the values of `{cumulus} render --method`:\n{p.stderr}")
    return re.findall(r'"([a-z_]+)"', m.group(1))


def frame_ms(stderr):
    """Upload + pass times from `cumulus render`'s line for the frame."""
    line = [l for l in stderr.splitlines() if " ms" in l and "t = " in l][-1]
    passes = line.split("; ", 1)[1]
    return sum(float(x) for x in re.findall(r"([0-9.]+) ms", passes))


def srgb_encode(x):
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)


def tone_map(radiance, exposure):
    """The renderer's display transform (common.wgsl `tone_map`, applied once to the HDR scene)."""
    x = exposure * np.maximum(radiance, 0.0)
    # Narkowicz's ACES fit, clamped to [0, 1] (srgb_encode clamps).
    return srgb_encode(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14))


def sky_color(d, sun, sky):
    """Sky radiance along unit directions d (..., 3), z up, from the
    sidecar's sky-view table (the atmosphere model of src/sky). Mirrors
    `sky_color` in shaders/common.wgsl and `SkyLight::radiance` in src/sky/view.rs."""
    na, ne = sky["azimuths"], sky["elevations"]
    parts = [np.asarray(sky[k], dtype=float).reshape(ne, na, 3) for k in ("rayleigh_rgb", "mie_rgb", "multiple_rgb")]
    g = sky["mie_g"]
    up = np.clip(d[..., 2], -1.0, 1.0)
    y = np.sqrt(np.arcsin(np.clip(up, 0.0, 1.0)) / (0.5 * math.pi)) * (ne - 1)
    e = np.minimum(np.floor(y).astype(int), ne - 2)
    fe = (y - e)[..., None]
    lens = np.hypot(d[..., 0], d[..., 1]) * math.hypot(sun[0], sun[1])
    dot = d[..., 0] * sun[0] + d[..., 1] * sun[1]
    cos_az = np.where(lens > 1e-6, dot / np.maximum(lens, 1e-12), 1.0)
    x = np.arccos(np.clip(cos_az, -1.0, 1.0)) / math.pi * (na - 1)
    a = np.minimum(np.floor(x).astype(int), na - 2)
    fa = (x - a)[..., None]

    def lerp2(t):
        lo = t[e, a] * (1.0 - fa) + t[e, a + 1] * fa
        hi = t[e + 1, a] * (1.0 - fa) + t[e + 1, a + 1] * fa
        return lo * (1.0 - fe) + hi * fe

    r, m, ms = (lerp2(t) for t in parts)
    mu = (d * sun).sum(-1, keepdims=True)
    p_r = 3.0 / (16.0 * math.pi) * (1.0 + mu * mu)
    p_m = (
        3.0 / (8.0 * math.pi) * (1.0 - g * g) * (1.0 + mu * mu)
        / ((2.0 + g * g) * np.power(np.maximum(1.0 + g * g - 2.0 * g * mu, 1e-6), 1.5))
    )
    return (r * p_r + m * p_m + ms) * (1.0 - 0.4 * np.clip(-3.0 * up[..., None], 0.0, 1.0))


def sky_envmap(sun, sky, width=512):
    """Lat-long bitmap in Mitsuba's envmap frame (y up), to be placed with a
    +90 degree rotation about x so that its y becomes our z."""
    h = width // 2
    v = (np.arange(h) + 0.5) / h
    u = (np.arange(width) + 0.5) / width
    theta = v[:, None] * math.pi
    phi = u[None, :] * 2.0 * math.pi
    local = np.stack(
        [np.sin(phi) * np.sin(theta), np.cos(theta) * np.ones_like(phi), -np.cos(phi) * np.sin(theta)], -1
    )
    # Rotation about x by +90 degrees: (x, y, z) -> (x, -z, y).
    world = np.stack([local[..., 0], -local[..., 2], local[..., 1]], -1)
    return sky_color(world, np.asarray(sun), sky).astype(np.float32)


def path_trace(side, vol_path, size, spp, variant, max_depth, ground_extent=None):
    import mitsuba as mi

    mi.set_variant(variant)
    T = mi.ScalarTransform4f
    cam, light, med, vol = side["camera"], side["light"], side["medium"], side["volume"]
    lo = np.array(vol["bounds_min_m"], dtype=float)
    hi = np.array(vol["bounds_max_m"], dtype=float)
    medium = {
        "type": "heterogeneous",
        "sigma_t": {
            "type": "gridvolume",
            "filename": vol_path,
            "to_world": T().translate(lo.tolist()) @ T().scale((hi - lo).tolist()),
        },
        "scale": med["extinction_scale_per_m"],
        "albedo": med["albedo"],
        "phase": {
            "type": "blendphase",
            # weight = share of the second lobe.
            "weight": med["phase_back_weight"],
            "phase1": {"type": "hg", "g": med["phase_g_forward"]},
            "phase2": {"type": "hg", "g": med["phase_g_back"]},
        },
    }
    scene = {
        "type": "scene",
        "integrator": {"type": "volpath", "max_depth": max_depth, "rr_depth": max_depth},
        "sensor": {
            "type": "perspective",
            "fov_axis": "y",
            "fov": cam["vfov_deg"],
            "near_clip": cam["near_m"],
            "far_clip": cam["far_m"],
            "to_world": T().look_at(origin=cam["position_m"], target=cam["target_m"], up=cam["up"]),
            "sampler": {"type": "independent", "sample_count": spp, "seed": 1},
            "film": {
                "type": "hdrfilm",
                "width": size[0],
                "height": size[1],
                "rfilter": {"type": "box"},
                "pixel_format": "rgb",
            },
        },
        "sun": {
            "type": "directional",
            "direction": [-x for x in light["sun_direction"]],
            "irradiance": {"type": "rgb", "value": light["sun_irradiance_rgb"]},
        },
        "sky": {
            "type": "envmap",
            "bitmap": mi.Bitmap(sky_envmap(light["sun_direction"], light["sky"])),
            "to_world": T().rotate([1, 0, 0], 90),
        },
        "clouds": {
            "type": "cube",
            "to_world": T().translate(((lo + hi) / 2).tolist()) @ T().scale(((hi - lo) / 2).tolist()),
            "bsdf": {"type": "null"},
            "interior": medium,
        },
    }
    if ground_extent:
        # The flat terrain: a Lambertian square at z = 0, as large as ours.
        half = ground_extent / 2.0
        scene["ground"] = {
            "type": "rectangle",
            "to_world": T().scale([half, half, 1.0]),
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": GROUND_ALBEDO}},
        }
    img = mi.render(mi.load_dict(scene))
    return np.array(img, dtype=np.float64)[..., :3]


def camera_rays(cam, size):
    """Origin and unit directions (height, width, 3) of the renderer's
    pinhole camera (the sidecar's `camera`), rows top first."""
    w, h = size
    pos, tgt, up = (np.asarray(cam[k], dtype=float) for k in ("position_m", "target_m", "up"))
    f = (tgt - pos) / np.linalg.norm(tgt - pos)
    r = np.cross(f, up)
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    t = math.tan(math.radians(cam["vfov_deg"]) / 2.0)
    y = (1.0 - 2.0 * (np.arange(h) + 0.5) / h) * t
    x = (2.0 * (np.arange(w) + 0.5) / w - 1.0) * t * w / h
    d = f + x[None, :, None] * r + y[:, None, None] * u
    return pos, d / np.linalg.norm(d, axis=-1, keepdims=True)


def read_vol(path):
    """(dims x, y, z, min, max, values[z, y, x]) of a float32 VOL v3."""
    with open(path, "rb") as f:
        b = f.read()
    if b[:3] != b"VOL" or b[3] != 3:
        fail(f"{path}: not a VOL v3 file")
    dims = np.frombuffer(b, "<i4", 3, 8)
    box = np.frombuffer(b, "<f4", 6, 24).astype(np.float64)
    vals = np.frombuffer(b, "<f4", int(np.prod(dims)), 48).reshape(dims[2], dims[1], dims[0])
    return dims, box[:3], box[3:], vals


def transmittance(vol, side, size):
    """Transmittance of the exported density `vol` (read_vol) along each
    camera ray of the sidecar `side`: trilinear between cell centres, steps
    of a quarter voxel through the grid's box. (height, width)"""
    dims, lo, hi, rho = vol
    sigma = side["medium"]["extinction_scale_per_m"]
    voxel = (hi[0] - lo[0]) / dims[0]
    origin, d = camera_rays(side["camera"], size)
    inv = 1.0 / np.where(np.abs(d) < 1e-12, 1e-12, d)
    t0 = np.maximum.reduce(np.minimum((lo - origin) * inv, (hi - origin) * inv), axis=-1)
    t1 = np.minimum.reduce(np.maximum((lo - origin) * inv, (hi - origin) * inv), axis=-1)
    t0 = np.maximum(t0, 0.0)
    step = 0.25 * voxel
    tau = np.zeros(d.shape[:2])
    padded = np.pad(rho, 1)  # zero outside: trilinear fades to the box's edge
    n = int(np.ceil(np.max(np.where(t1 > t0, t1 - t0, 0.0)) / step))
    for k in range(n):
        t = t0 + (k + 0.5) * step
        live = t < t1
        if not live.any():
            break
        p = origin + t[..., None] * d
        g = (p - lo) / voxel + 0.5  # padded cell-centre coordinates, x y z
        i0 = np.floor(g).astype(int)
        fr = g - i0
        acc = np.zeros(tau.shape)
        for corner in range(8):
            o = np.array([(corner >> a) & 1 for a in range(3)])
            idx = i0 + o
            ok = np.all((idx >= 0) & (idx < np.array(padded.shape[::-1])), axis=-1)
            wgt = np.prod(np.where(o == 1, fr, 1.0 - fr), axis=-1)
            ix, iy, iz = (np.clip(idx[..., a], 0, padded.shape[2 - a] - 1) for a in range(3))
            acc += np.where(ok, wgt * padded[iz, iy, ix], 0.0)
        tau += np.where(live, acc * sigma * step, 0.0)
    return np.exp(-tau)


def above_horizon(cam, size):
    """Pixels (height, width) whose camera ray points above the horizon."""
    return camera_rays(cam, size)[1][..., 2] > 0.0


def flip(ref, test):
    import flip_evaluator as flip_eval

    err_map, mean, _ = flip_eval.evaluate(ref.astype(np.float32), test.astype(np.float32), "LDR")
    return err_map, float(mean)


def box_blur(img, r):
    """Mean over the (2r + 1)² pixels around each pixel, edges repeated."""
    h, w = img.shape[:2]
    pad = np.pad(img, ((r, r), (r, r), (0, 0)), mode="edge")
    out = sum(pad[dy : dy + h, dx : dx + w] for dy in range(2 * r + 1) for dx in range(2 * r + 1))
    return out / (2 * r + 1) ** 2


def load_png(path):
    import mitsuba as mi

    a = np.array(mi.Bitmap(path), dtype=np.float64)
    return a[..., :3] / (255.0 if a.max() > 1.0 else 1.0)


def reference_key(vol_path, side, settings):
    """A hash of what the path-traced image depends on: the exported grid's
    bytes, its sidecar and the path tracer's settings."""
    import hashlib

    h = hashlib.sha256()
    with open(vol_path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    h.update(json.dumps(side, sort_keys=True).encode())
    h.update(repr(settings).encode())
    return h.hexdigest()


def save_exr(path, rgb):
    import mitsuba as mi

    mi.Bitmap(np.ascontiguousarray(rgb, dtype=np.float32), pixel_format=mi.Bitmap.PixelFormat.RGB).write(path)


def save_png(path, rgb01):
    import mitsuba as mi

    u8 = np.clip(np.round(rgb01 * 255.0), 0, 255).astype(np.uint8)
    mi.Bitmap(u8, pixel_format=mi.Bitmap.PixelFormat.RGB).write(path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", required=True, help="output folder")
    ap.add_argument("--quick", action="store_true", help="CPU variant, small size, few samples")
    ap.add_argument("--cumulus", help="the cumulus binary (default target/release/cumulus)")
    ap.add_argument("--scene", default=os.path.join(ROOT, "profiles", "fair_weather.toml"))
    ap.add_argument("--time", type=float, default=1800.0, help="simulated time of the frame (s)")
    ap.add_argument("--stand-in", action="store_true", help="the stand-in cloud field (no physics)")
    ap.add_argument("--parcels", help="a cloud-field CSV (cumulus render --save-parcels) instead of simulating")
    ap.add_argument("--width", type=int)
    ap.add_argument("--height", type=int)
    ap.add_argument("--spp", type=int, help="path-traced samples per pixel")
    ap.add_argument("--voxel", type=float, help="export voxel (m); default: cumulus's")
    ap.add_argument("--max-depth", type=int, default=256, help="most scattering events per path")
    ap.add_argument("--variant", help="Mitsuba variant (default: scalar_rgb with --quick, else cuda_ad_rgb if it loads, else scalar_rgb)")
    ap.add_argument("--settings", default="all", help="'all' or 'default' (only the default setting)")
    ap.add_argument(
        "--ground",
        action="store_true",
        help="a flat Lambertian ground on both sides (Mitsuba: a square of the terrain's extent and "
        "GROUND_ALBEDO at z = 0; ours: the terrain flat), so both light the cloud bases from the same "
        "lower hemisphere; the errors are then taken over the pixels above the horizon only",
    )
    ap.add_argument(
        "--cloud-only",
        action="store_true",
        help="take the errors over the pixels where the exported density has cloud (its "
        f"transmittance along the pixel's ray under {CLOUD_ONLY_T}) only",
    )
    ap.add_argument("--methods", help="comma-separated render methods to measure (default: every one)")
    ap.add_argument(
        "--reuse-reference",
        action="store_true",
        help="reuse the path-traced radiance of an earlier run into --out when its key matches",
    )
    a = ap.parse_args()

    import mitsuba as mi

    width = a.width or (160 if a.quick else 640)
    height = a.height or (120 if a.quick else 360)
    spp = a.spp or (16 if a.quick else 256)
    if width < 8 or height < 8 or spp < 1:
        fail("--width and --height must be at least 8, --spp at least 1")
    if a.variant:
        variant = a.variant
    elif a.quick:
        variant = "scalar_rgb"
    else:
        variant = "cuda_ad_rgb"
        try:
            mi.set_variant(variant)
            mi.load_dict({"type": "constvolume"})
        except Exception:
            # Not llvm_ad_rgb: with some system LLVM builds its JIT aborts
            # ("Cannot select fminimum"); the scalar variant always works.
            variant = "scalar_rgb"
    if variant not in mi.variants():
        fail(f"--variant {variant}: this Mitsuba has {', '.join(mi.variants())}")
    cumulus = find_cumulus(a.cumulus)
    os.makedirs(a.out, exist_ok=True)

    common = ["--time", str(a.time)] + (["--stand-in"] if a.stand_in else [])
    common += ["--parcels", os.path.abspath(a.parcels)] if a.parcels else []
    terrain = "flat" if a.ground else False
    base = scene_text(a.scene, {}, terrain=terrain)
    scene_path = os.path.join(a.out, "scene.toml")
    with open(scene_path, "w", encoding="utf-8") as f:
        f.write(base)

    vol = os.path.abspath(os.path.join(a.out, "clouds.vol"))
    cmd = [cumulus, "export", scene_path, "--out", vol] + common
    if a.voxel:
        cmd += ["--voxel", str(a.voxel)]
    print(run(cmd).strip().splitlines()[-2], file=sys.stderr)
    with open(os.path.join(a.out, "clouds.json"), encoding="utf-8") as f:
        side = json.load(f)

    t0 = time.time()
    extent = None
    if a.ground:
        import tomllib

        with open(a.scene, "rb") as f:
            extent = tomllib.load(f).get("render", {}).get("terrain", {}).get("extent_m", 40000.0)
    key = reference_key(vol, side, (width, height, spp, variant, a.max_depth, extent))
    cached = os.path.join(a.out, "pathtraced.npy")
    key_path = os.path.join(a.out, "pathtraced.key")
    reuse = a.reuse_reference and os.path.exists(cached) and os.path.exists(key_path)
    if reuse:
        with open(key_path, encoding="utf-8") as f:
            reuse = f.read().strip() == key
    if reuse:
        hdr = np.load(cached)
        print("path-traced radiance reused (same key)", file=sys.stderr)
    else:
        hdr = path_trace(side, vol, (width, height), spp, variant, a.max_depth, extent)
        np.save(cached, np.asarray(hdr, dtype=np.float32))
        with open(key_path, "w", encoding="utf-8") as f:
            f.write(key + "\n")
    # Where the error is taken: everywhere, or above the horizon with a ground
    # (the two grounds' textures differ; the clouds are above it).
    sky = above_horizon(side["camera"], (width, height)) if a.ground else np.ones((height, width), bool)
    if a.cloud_only:
        sky &= transmittance(read_vol(vol), side, (width, height)) < CLOUD_ONLY_T
        print(f"errors over the {int(sky.sum())} pixels with cloud", file=sys.stderr)
    pt_ms = (time.time() - t0) * 1e3
    exposure = side["light"]["tone_exposure"]
    pt = tone_map(hdr, exposure)
    save_png(os.path.join(a.out, "pathtraced.png"), pt)
    save_exr(os.path.join(a.out, "pathtraced.exr"), hdr)
    print(f"path traced {width}x{height}, {spp} spp, {variant}: {pt_ms:.0f} ms", file=sys.stderr)
    if a.cloud_only:
        # The reference's detail is its texture and its noise; FLIP over
        # cloud pixels alone counts every pixel of it.
        for r in (1, 2, 3):
            blurred = np.where(sky[..., None], box_blur(pt, r), pt)
            floor = flip(pt, blurred)[1] * sky.size / max(int(sky.sum()), 1)
            print(f"floor: the reference blurred over {2 * r + 1}x{2 * r + 1} pixels: mean FLIP {floor:.4f}", file=sys.stderr)

    rows = [("pathtraced", pt_ms, 0.0, 0.0)]
    settings = sweep_settings(a.scene)
    settings = settings if a.settings == "all" else settings[:1]
    methods = render_methods(cumulus)
    if a.methods:
        wanted = [m.strip() for m in a.methods.split(",") if m.strip()]
        unknown = [m for m in wanted if m not in methods]
        if unknown:
            fail(f"--methods: {', '.join(unknown)} not among {', '.join(str(m) for m in methods)}")
        methods = wanted
    for method in methods:
        for name, overrides in settings:
            label = name if method is None else f"{name} method={method}"
            path = os.path.join(a.out, "scene_" + re.sub(r"[^a-z0-9_.=-]", "_", label) + ".toml")
            with open(path, "w", encoding="utf-8") as f:
                f.write(scene_text(a.scene, overrides, terrain=terrain))
            png = path[:-5] + ".png"
            cmd = [cumulus, "render", path, "--width", str(width), "--height", str(height), "--out", png]
            cmd += common + ([] if method is None else ["--method", method])
            ms = frame_ms(run(cmd))
            ours = load_png(png)
            # Outside the measured pixels ours takes the path tracer's values
            # (no error there); the mean is over the measured pixels.
            ours = np.where(sky[..., None], ours, pt)
            err_map, mean = flip(pt, ours)
            mean *= sky.size / max(int(sky.sum()), 1)
            rmse = float(np.sqrt(np.mean(((ours - pt) ** 2)[sky])))
            rows.append((label, ms, mean, rmse))
            print(f"{label}: {ms:.1f} ms, mean FLIP {mean:.4f}, RMSE {rmse:.4f}", file=sys.stderr)
            if name == "default" and (method is None or len(rows) == 2):
                save_png(os.path.join(a.out, "ours.png"), ours)
                save_png(os.path.join(a.out, "flip.png"), np.asarray(err_map)[..., :3])
                side_by_side = np.concatenate([pt, ours, np.asarray(err_map)[..., :3]], axis=1)
                save_png(os.path.join(a.out, "side_by_side.png"), side_by_side)

    tmp = os.path.join(a.out, ".error_vs_pathtraced.csv.tmp")
    with open(tmp, "w", encoding="utf-8") as f:
        f.write("setting,time_ms,mean_flip,rmse\n")
        for label, ms, mean, rmse in rows:
            f.write(f"{label},{ms:.3f},{mean:.6f},{rmse:.6f}\n")
    os.replace(tmp, os.path.join(a.out, "error_vs_pathtraced.csv"))
    print(f"wrote {os.path.join(a.out, 'error_vs_pathtraced.csv')}", file=sys.stderr)


if __name__ == "__main__":
    main()
