#!/usr/bin/python3
"""Independent check of the EXR and PNG files `brdf convert` writes (OpenEXR and libpng inside
the tool), read here with Debian's python3-openimageio and computed with NumPy:

- EXR: 722 × 362 (K = 4), channels R, G, B, the pixel type and compression asked for, and the
  header attributes carrying the sidecar (the same JSON as the .json sidecar file, its θin
  list, its payload CRC-32); the half file's pixels equal numpy.float16 of the float file's
  (IEEE 754 round to nearest even, overflow to inf).
- PNG: 8-bit RGB of the same size with a "Software" text, whose pixels follow the documented
  tone map (export/include/brdf/exporter/exr.h) computed here in double from the float EXR.

usage: exr_png_oracle.py BRDF MATERIAL.json
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np
import OpenImageIO as oiio

FAILURES = []


def check(condition, message):
    if not condition:
        FAILURES.append(message)


def read(path):
    image = oiio.ImageInput.open(path)
    if image is None:
        sys.exit(f"FAIL: OpenImageIO cannot open {path}: {oiio.geterror()}")
    spec = image.spec()
    pixels = image.read_image(oiio.FLOAT)
    image.close()
    return spec, np.asarray(pixels, dtype=np.float32)


def convert(brdf, material, out_dir, *options):
    # --beyond clamp: the measured 4 slices, the 2 × 2 composite checked below (the default
    # blind-spot fill makes 9, a 3 × 3 composite of the same writer).
    run = subprocess.run([brdf, "convert", material, "--out", out_dir, "--formats",
                          "exr,png,json", "--beyond", "clamp", *options], capture_output=True,
                         text=True, timeout=300)
    if run.returncode != 0:
        sys.exit(f"FAIL: brdf convert {' '.join(options)}: {run.stderr.strip()}")


def tone_map(rgb):
    """The PNG tone map of exr.h, in double."""
    flat = rgb.reshape(-1, 3).astype(np.float64)
    lum = 0.2126 * flat[:, 0] + 0.7152 * flat[:, 1] + 0.0722 * flat[:, 2]
    lum = lum[np.isfinite(lum) & (lum > 0)]
    scale = 1.0
    if lum.size:
        q = int(np.floor(0.99 * (lum.size - 1) + 0.5))
        scale = 1.0 / np.partition(lum, q)[q]
    v = np.where(flat > 0, flat, 0.0) * scale  # NaN and negatives → black
    with np.errstate(invalid="ignore", over="ignore"):
        mapped = np.where(np.isinf(v), 1.0, np.minimum(1.0, 2 * v / (1 + v)))
    srgb = np.where(mapped <= 0.0031308, 12.92 * mapped,
                    1.055 * np.power(mapped, 1 / 2.4) - 0.055)
    return np.floor(255 * srgb + 0.5).astype(np.int64).reshape(rgb.shape)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    brdf, material = sys.argv[1:]
    name = os.path.splitext(os.path.basename(material))[0]
    work = tempfile.mkdtemp(prefix="brdf_exr_png_oracle_")
    try:
        convert(brdf, material, os.path.join(work, "float"), "--exr-type", "float",
                "--exr-compression", "zip")
        convert(brdf, material, os.path.join(work, "half"), "--exr-type", "half",
                "--exr-compression", "none")
        images = {}
        for kind, pixel_type, compression in (("float", "float", "zip"),
                                              ("half", "half", "none")):
            path = os.path.join(work, kind, name + ".exr")
            spec, pixels = read(path)
            images[kind] = pixels
            check((spec.width, spec.height, spec.nchannels) == (722, 362, 3),
                  f"{kind}: size {spec.width} x {spec.height} x {spec.nchannels}")
            check(tuple(spec.channelnames) == ("R", "G", "B"),
                  f"{kind}: channels {spec.channelnames}")
            check(str(spec.format) == pixel_type, f"{kind}: pixel type {spec.format}")
            check(spec.get_string_attribute("compression") == compression,
                  f"{kind}: compression {spec.get_string_attribute('compression')}")
            with open(os.path.join(work, kind, name + ".json"), encoding="utf-8") as f:
                sidecar = json.load(f)
            header_sidecar = spec.get_string_attribute("brdf:sidecar")
            check(header_sidecar != "" and json.loads(header_sidecar) == sidecar,
                  f"{kind}: brdf:sidecar differs from the sidecar file")
            check(spec.get_string_attribute("brdf:theta_in_deg") ==
                  ", ".join(f"{t:g}" for t in sidecar["theta_in_deg"]),
                  f"{kind}: brdf:theta_in_deg {spec.get_string_attribute('brdf:theta_in_deg')}")
            check(spec.get_string_attribute("brdf:payload_crc32") ==
                  sidecar["payload"]["checksum"]["value"],
                  f"{kind}: brdf:payload_crc32 {spec.get_string_attribute('brdf:payload_crc32')}")
            check("+ 0.5" in spec.get_string_attribute("brdf:texel_convention"),
                  f"{kind}: brdf:texel_convention")
            check(spec.get_string_attribute("brdf:layout").startswith("2 x 2 slices"),
                  f"{kind}: brdf:layout {spec.get_string_attribute('brdf:layout')}")
            check("brdf-toolchain" in spec.get_string_attribute("Software"),
                  f"{kind}: Software {spec.get_string_attribute('Software')}")
        full = images["float"]
        check(np.count_nonzero(full) > full.size // 4, "float EXR is mostly black")
        want_half = full.astype(np.float16).astype(np.float32)
        same = (images["half"] == want_half) | (np.isnan(images["half"]) & np.isnan(want_half))
        check(bool(same.all()),
              f"half EXR: {np.count_nonzero(~same)} values differ from numpy.float16(float)")

        spec, png = read(os.path.join(work, "float", name + ".png"))
        check((spec.width, spec.height, spec.nchannels) == (722, 362, 3),
              f"png: size {spec.width} x {spec.height} x {spec.nchannels}")
        check(str(spec.format) == "uint8", f"png: format {spec.format}")
        check("brdf-toolchain" in spec.get_string_attribute("Software"), "png: Software text")
        codes = np.floor(png.astype(np.float64) * 255 + 0.5).astype(np.int64)
        want = tone_map(full)
        diff = np.abs(codes - want)
        # The tool maps in float, this oracle in double: at a rounding boundary they may differ
        # by one code.
        check(int(diff.max()) <= 1, f"png: a code differs by {int(diff.max())} from the tone map")
        check(np.count_nonzero(diff) <= diff.size // 1000,
              f"png: {np.count_nonzero(diff)} of {diff.size} codes differ from the tone map")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    if FAILURES:
        for failure in FAILURES:
            print("FAIL:", failure)
        sys.exit(1)
    print("OK: EXR headers, half rounding and PNG tone map match the independent reading")


if __name__ == "__main__":
    main()
