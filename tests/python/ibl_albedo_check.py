#!/usr/bin/python3
"""Directional albedo of the IBL pack (brdf/core/ibl_pack.h) against NumPy's own quadrature.

For each file and a selection of the pack's view rows μ = cosθv, NumPy integrates
E(μ) = ∫ f_r cosθl dω over the light hemisphere by the midpoint rule on a grid of the NORMAL
frame (θl in 0.5° steps, φl in 1° steps: sinθl·Δθ·Δφ weights), not the pack's grid around the
mirror direction, with f_r from `brdf eval FILE --pairs` (the one evaluation rule of the file,
docs/design.md §5), and compares it with what the pack reports for the same file
(ibl_pack_print FILE, the same OpenBrdf path). Nothing here calls the pack's quadrature.

  ibl_albedo_check.py --tool BRDF --driver IBL_PACK_PRINT --work DIR FILE...
  ibl_albedo_check.py --tool BRDF --manifest NAME.manifest.json --work DIR FILE
      the pack as `brdf convert --engine` wrote it (the manifest's "ibl"), against `brdf eval`
      of FILE (the exported texture).
Fails (exit 1) when a channel differs by more than TOLERANCE of the NumPy value.
"""
import argparse
import json
import os
import subprocess
import sys

import numpy as np

TOLERANCE = 0.005
ROWS = [0, 6, 20, 32, 44, 56, 63]


def numpy_albedo(tool, path, mu, work):
    theta_v = np.degrees(np.arccos(mu))
    d_theta, d_phi = 0.5, 1.0
    theta = (np.arange(int(90 / d_theta)) + 0.5) * d_theta
    phi = (np.arange(int(360 / d_phi)) + 0.5) * d_phi
    t, p = np.meshgrid(theta, phi, indexing="ij")
    pairs = os.path.join(work, "pairs.txt")
    with open(pairs, "w") as f:
        for ti, pi in zip(t.ravel(), p.ravel()):
            f.write(f"{ti:.9g} {pi:.9g} {theta_v:.12g} 0\n")
    out = subprocess.run([tool, "eval", path, "--pairs", pairs], check=True,
                         capture_output=True, text=True).stdout
    values = np.array([[float(x) for x in line.split()] for line in out.splitlines()])
    assert values.shape == (t.size, 3), values.shape
    rad = np.pi / 180.0
    weight = (np.cos(t * rad) * np.sin(t * rad)).ravel() * (d_theta * rad) * (d_phi * rad)
    return (values * weight[:, None]).sum(axis=0)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--tool", required=True)
    parser.add_argument("--driver")
    parser.add_argument("--manifest")
    parser.add_argument("--work", required=True)
    parser.add_argument("files", nargs="+")
    args = parser.parse_args()
    os.makedirs(args.work, exist_ok=True)
    failures = 0
    for path in args.files:
        if args.manifest:
            with open(args.manifest) as f:
                pack = json.load(f)["ibl"]
        else:
            pack = json.loads(subprocess.run([args.driver, path], check=True,
                                             capture_output=True, text=True).stdout)
        if len(pack["mu"]) != 64 or len(pack["albedo_rgb"]) != 64:
            print(f"{path}: expected 64 rows, got {len(pack['mu'])}")
            return 1
        for row in ROWS:
            mu = pack["mu"][row]
            if abs(mu - (row + 0.5) / 64) > 1e-6:
                print(f"{path}: row {row}: expected mu {(row + 0.5) / 64}, got {mu}")
                failures += 1
            truth = numpy_albedo(args.tool, path, mu, args.work)
            got = np.array(pack["albedo_rgb"][row])
            rel = np.abs(got - truth) / np.maximum(truth, 1e-12)
            status = "ok" if rel.max() <= TOLERANCE else "FAIL"
            print(f"{os.path.basename(path)} mu {mu:.4f}: pack {got.round(5)} numpy "
                  f"{truth.round(5)} max rel {rel.max():.2e} {status}")
            if status != "ok":
                failures += 1
    print("ok" if failures == 0 else f"{failures} rows outside {TOLERANCE:.1%}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
