#!/usr/bin/python3
"""`brdf atlas --max-error E` against errors recomputed independently.

Three library materials make a 2 x 2 atlas with one unused cell. The float LUT of each comes from
a plain `brdf convert` to float EXR. For each bound the atlas's KTX2 is decoded in numpy (BC6H
with tests/python/bc6h_oracle.py, written from the specification; RGB9E5 from its bit layout), each
material's cell is cut out and its relative error against the float LUT (docs/design.md §7) is
computed over the measured range θout <= θb and the filled range, then:

- the choice: BC6H exactly when every material's BC6H error (numpy, on the BC6H atlas of the
  loose bound, same deterministic encoder) is at most E, else RGB9E5;
- the manifest's per-material "compression" figures (max, p99, median, texel counts, format, the
  bound and whether it is met) equal the numpy ones; stdout names the format and each material
  with its max, and warns for the materials above E; `brdf info` names the format per material;
- the unused cell decodes to zero and is not a material of the manifest.

Bounds: a loose one BC6H meets, 0.5 % (BC6H's max on these materials is above it, RGB9E5's below:
RGB9E5 is chosen and meets it), and 1e-6 (nothing meets it: RGB9E5 with a warning per material).

Usage: atlas_max_error_check.py --brdf BRDF --work DIR
"""

import argparse
import json
import math
import os
import shutil
import struct
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bc6h_oracle  # noqa: E402
from compact_check import fail, nearest_rank, read_lut, run  # noqa: E402

MATERIALS = ["gold", "plastic_glossy_red", "paper_white"]
LOOSE, MIDDLE, TIGHT = 0.5, 0.005, 1e-6


def read_atlas_texture(path):
    """(depth, height, width, 3) float64 texels of the KTX2's level 0 and its format name."""
    data = open(path, "rb").read()
    assert data[:12] == b"\xabKTX 20\xbb\r\n\x1a\n", path + ": not KTX 2.0"
    vk_format, _, width, height, depth = struct.unpack_from("<5I", data, 12)
    if vk_format == 131:
        _, _, _, level, _ = bc6h_oracle.read_ktx2_bc6h(path)
        return bc6h_oracle.decode_volume(level, width, height, depth).astype(np.float64), "bc6h"
    if vk_format != 123:
        fail(f"{path}: vkFormat {vk_format}, expected 123 (RGB9E5) or 131 (BC6H)")
    offset, length = struct.unpack_from("<QQ", data, 80)
    w = np.frombuffer(data, dtype="<u4", count=length // 4, offset=offset).astype(np.int64)
    # E5B9G9R9: R bits 0-8, G 9-17, B 18-26, shared exponent 27-31; value = m * 2^(e - 15 - 9).
    scale = np.exp2(((w >> 27) & 31).astype(np.float64) - 24.0)
    rgb = np.stack([(w & 511) * scale, ((w >> 9) & 511) * scale, ((w >> 18) & 511) * scale], -1)
    return rgb.reshape(depth, height, width, 3), "rgb9e5"


def cell_errors(decoded, lut, theta_in, theta_b):
    """docs/design.md §7's relative error of every texel, and the measured-range mask."""
    ref = np.clip(lut, 0.0, 65504.0)
    floor = max(2.0 ** -14, float(np.float32(1e-4)) * ref.max())
    err = np.abs(decoded - ref).max(-1) / np.maximum(ref.max(-1), floor)
    ti = np.radians(np.asarray(theta_in, dtype=np.float64))[:, None, None]
    td = np.radians(np.arange(181, dtype=np.float64))[None, :, None]
    pd = np.radians(np.arange(361, dtype=np.float64))[None, None, :]
    cos_out = np.cos(ti) * np.cos(td) - np.sin(ti) * np.sin(td) * np.cos(pd)
    measured = np.degrees(np.arccos(np.clip(cos_out, -1, 1))) <= theta_b + 1e-9
    return err, measured


def statistics(values):
    v = np.sort(values)
    return {"max": float(v[-1]), "p99": float(nearest_rank(v, 0.99)),
            "median": float(nearest_rank(v, 0.5)), "texels": int(v.size)}


def check_bound(args, refs, bound, bc6h_max):
    out = os.path.join(args.work, f"atlas_{bound:g}")
    prefix = os.path.join(out, "lib")
    r = run([args.brdf, "atlas", *MATERIALS, "--out", prefix, "--max-error", f"{bound:g}",
             "--quiet", "--force"])
    text = r.stdout + r.stderr
    manifest = json.load(open(prefix + ".json"))
    texture, fmt = read_atlas_texture(prefix + ".ktx2")
    payload_fmt = manifest["payload"].get("format", "rgb9e5")
    if {"bc6h": "bc6h_ufloat", "rgb9e5": "rgb9e5"}[fmt] != payload_fmt:
        fail(f"--max-error {bound:g}: the KTX2 holds {fmt}, the manifest says {payload_fmt}")
    if [m["name"] for m in manifest["materials"]] != MATERIALS:
        fail(f"manifest materials {[m['name'] for m in manifest['materials']]}, expected "
             f"{MATERIALS} (the unused cell is no material)")
    if texture.shape[1:3] != (362, 722):
        fail(f"atlas texture {texture.shape}, expected 2 x 2 cells of 361 x 181")
    # The unused cell (column 1, row 1) holds no data. RGB9E5 stores it exactly; BC6H blocks
    # straddle the cell borders (361 and 181 are not multiples of 4), so only its inside is
    # compared there.
    empty = texture[:, 181 + 4:, 361 + 4:] if fmt == "bc6h" else texture[:, 181:, 361:]
    if np.abs(empty).max() != 0.0:
        fail(f"--max-error {bound:g}: the unused cell decodes to {np.abs(empty).max()}, not 0")
    errors = {}
    for m in manifest["materials"]:
        name = m["name"]
        theta_in, lut, theta_b = refs[name]
        x0, y0 = m["cell"]["x0"], m["cell"]["y0"]
        cell = texture[:, y0:y0 + 181, x0:x0 + 361]
        err, measured = cell_errors(cell, lut, theta_in, theta_b)
        comp = m.get("compression")
        if comp is None:
            fail(f"{name}: no 'compression' member in the manifest for --max-error {bound:g}")
        if comp["format"] != payload_fmt:
            fail(f"{name}: compression.format {comp['format']}, payload {payload_fmt}")
        cert = comp["certified_error"]
        if not math.isclose(cert["theta_b_deg"], theta_b):
            fail(f"{name}: theta_b {cert['theta_b_deg']} recorded, {theta_b} in the sidecar")
        for rng, mask in (("measured", measured), ("filled", ~measured)):
            mine, rec = statistics(err[mask]), cert[rng]
            if rec["texels"] != mine["texels"]:
                fail(f"{name} {rng}: manifest counts {rec['texels']} texels, numpy "
                     f"{mine['texels']}")
            for key in ("max", "p99", "median"):
                if not math.isclose(rec[key], mine[key], rel_tol=1e-4, abs_tol=1e-6):
                    fail(f"{name} {rng} {key}: manifest {rec[key]}, numpy {mine[key]}")
        e = statistics(err[measured])["max"]
        errors[name] = e
        if comp.get("max_error_bound") != float(f"{bound:g}"):
            fail(f"{name}: manifest bound {comp.get('max_error_bound')}, --max-error {bound:g}")
        if comp.get("max_error_met") is not (e <= bound):
            fail(f"{name}: manifest max_error_met {comp.get('max_error_met')}, numpy max {e}")
        line = [ln for ln in text.splitlines() if ln.strip().startswith(name + ": measured max")]
        if not line or f"measured max {100 * e:.2f} %" not in line[0]:
            fail(f"{name}: stdout line {line!r} does not give the max {100 * e:.2f} %")
        if ("WARNING" in line[0]) == (e <= bound):
            fail(f"{name}: stdout line {line[0]!r} and max {e} vs bound {bound:g} disagree")
    if bc6h_max is not None:
        want = "bc6h" if all(v <= bound for v in bc6h_max.values()) else "rgb9e5"
        if fmt != want:
            fail(f"--max-error {bound:g}: chose {fmt}, BC6H maxima {bc6h_max} call for {want}")
    word = "BC6H" if fmt == "bc6h" else "RGB9E5"
    if f"{word} for the atlas" not in text:
        fail(f"--max-error {bound:g}: stdout does not say '{word} for the atlas': {text!r}")
    info = run([args.brdf, "info", prefix + ".json"]).stdout
    if info.count(f"certified {word} error") != len(MATERIALS):
        fail(f"--max-error {bound:g}: `brdf info` does not name {word} for every material: "
             f"{info!r}")
    print(f"--max-error {100 * bound:g} %: {word}; measured max per material "
          + ", ".join(f"{n} {100 * v:.3f} %" for n, v in errors.items())
          + " (numpy, as the manifest records)")
    return fmt, errors


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--brdf", required=True)
    ap.add_argument("--work", required=True)
    args = ap.parse_args()
    shutil.rmtree(args.work, ignore_errors=True)
    os.makedirs(args.work)
    ref = os.path.join(args.work, "reference")
    run([args.brdf, "convert", *MATERIALS, "--out", ref, "--formats", "exr,json", "--exr-type",
         "float", "--force", "--quiet"])
    refs = {n: read_lut(os.path.join(ref, n + ".exr"), os.path.join(ref, n + ".json"))
            for n in MATERIALS}
    fmt, bc6h_max = check_bound(args, refs, LOOSE, None)
    if fmt != "bc6h":
        fail(f"--max-error {LOOSE}: BC6H maxima {bc6h_max} all within it, yet {fmt} was chosen")
    if all(v <= MIDDLE for v in bc6h_max.values()):
        fail(f"BC6H meets {MIDDLE} on every material ({bc6h_max}): the test needs a bound it "
             "fails")
    fmt, rgb_max = check_bound(args, refs, MIDDLE, bc6h_max)
    if fmt != "rgb9e5" or any(v > MIDDLE for v in rgb_max.values()):
        fail(f"--max-error {MIDDLE}: expected RGB9E5 within the bound, got {fmt} {rgb_max}")
    fmt, _ = check_bound(args, refs, TIGHT, bc6h_max)
    print("PASSED")


if __name__ == "__main__":
    main()
