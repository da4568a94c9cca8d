#!/usr/bin/python3
"""Where BC6H's p99 misses come from (docs/benchmarks/bc6h.md, "Blocked by the format").

For every file of `brdf convert --compress bc6h --formats ktx2,exr,json --exr-type float`
output folders: the certified error of each texel (the metric of brdf/exporter/metadata.h,
recomputed here from the float EXR and the decoded KTX2), the failing texels (measured range,
error > 3 %), and the span of each 4 x 4 block: the ratio of the largest to the smallest texel
scale S = max(max_c r_c, 1e-4 R, 2^-14) inside the block. One BC6H subset holds the 8 or 16
levels of one line between two endpoints, so a block whose values span a factor F spends its
levels on a range F wide; the table gives the share of failing texels in blocks of span >= 4
and >= 16, and the share of measured texels in such blocks.

  bench/bc6h/format_limit.py DUMP_FIXTURE FOLDER...   (DUMP_FIXTURE: tests/export/bc6h_dump_fixture)
"""
import json
import math
import os
import subprocess
import sys
import tempfile

import numpy as np
import OpenImageIO as oiio

LIMIT = 0.03
SPANS = (4.0, 16.0)


def load(fixture, folder, name):
    side = json.load(open(os.path.join(folder, name + ".json")))
    theta = side["theta_in_deg"]
    depth, height, width = len(theta), 181, 361
    with tempfile.NamedTemporaryFile(suffix=".raw") as raw:
        subprocess.run([fixture, os.path.join(folder, name + ".ktx2"), raw.name], check=True)
        dec = np.fromfile(raw.name, dtype="<f4").reshape(depth, height, width, 3)
    inp = oiio.ImageInput.open(os.path.join(folder, name + ".exr"))
    image = inp.read_image(format="float")
    inp.close()
    cols = math.ceil(math.sqrt(depth))
    ref = np.zeros((depth, height, width, 3), dtype=np.float64)
    for k in range(depth):
        c, r = k % cols, k // cols
        ref[k] = image[r * height:(r + 1) * height, c * width:(c + 1) * width, :3]
    ref = np.clip(ref, 0.0, 65504.0)
    cert = side["compression"]["certified_error"]
    floor = max(2.0 ** -14, float(np.float32(1e-4)) * ref.max())
    scale = np.maximum(ref.max(axis=3), floor)
    err = np.abs(dec.astype(np.float64) - ref).max(axis=3) / scale
    ti = np.radians(np.array(theta, dtype=np.float64))[:, None, None]
    td = np.radians(np.arange(height, dtype=np.float64))[None, :, None]
    pd = np.radians(np.arange(width, dtype=np.float64))[None, None, :]
    cos_out = np.cos(ti) * np.cos(td) - np.sin(ti) * np.sin(td) * np.cos(pd)
    measured = np.degrees(np.arccos(np.clip(cos_out, -1, 1))) <= cert["theta_b_deg"] + 1e-9
    return scale, err, measured, cert


def block_span(scale):
    """Per texel: max/min of the texel scales of its 4 x 4 block (padding excluded)."""
    depth, height, width = scale.shape
    bh, bw = (height + 3) // 4, (width + 3) // 4
    pad = np.full((depth, bh * 4, bw * 4), np.nan)
    pad[:, :height, :width] = scale
    blocks = pad.reshape(depth, bh, 4, bw, 4)
    hi = np.nanmax(blocks, axis=(2, 4))
    lo = np.nanmin(blocks, axis=(2, 4))
    span = hi / lo
    return np.repeat(np.repeat(span, 4, axis=1), 4, axis=2)[:, :height, :width]


def main():
    fixture = sys.argv[1]
    print("| file | measured p99 % | failing texels (> 3 %) | of them in blocks of span >= 4x | "
          "... >= 16x | measured texels in blocks >= 4x | ... >= 16x |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for folder in sys.argv[2:]:
        for name in sorted(n[:-5] for n in os.listdir(folder) if n.endswith(".json")):
            scale, err, measured, cert = load(fixture, folder, name)
            span = block_span(scale)
            fail = measured & (err > LIMIT)
            n_fail = int(fail.sum())
            shares, covers = [], []
            for limit in SPANS:
                wide = span >= limit
                shares.append(100.0 * (fail & wide).sum() / n_fail if n_fail else 0.0)
                covers.append(100.0 * (measured & wide).sum() / measured.sum())
            print(f"| {name} | {100 * cert['measured']['p99']:.2f} | {n_fail} | "
                  + " | ".join(f"{x:.1f} %" for x in shares) + " | "
                  + " | ".join(f"{x:.2f} %" for x in covers) + " |")


if __name__ == "__main__":
    main()
