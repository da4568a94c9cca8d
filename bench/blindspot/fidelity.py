#!/usr/bin/python3
"""How well the toolchain renders what the instrument cannot measure (issue 18), measured with
the shipped commands only, so the same command gives the before and after figures.

  1. gold (data-samples/materials/gold.json) and a GGX α 0.2 metal, captured noise-free at the
     reference geometry (`brdf capture --device sim --noise 0`), converted (`brdf convert`, KTX2)
     and previewed against their material (`brdf preview LUT --compare MATERIAL`, sphere,
     studio and sky); `brdf eval` of the capture against the material over random pairs with
     light and view both in [62°, 88°] (median relative error).
  2. RGL files brought in at the instrument geometry (`brdf import FILE.bsdf`) and previewed
     against the file itself (`--compare FILE.bsdf`, studio).
  3. Leave the last slice out on the RGL files: the 4-slice import exported to CSV without its
     θin = 60° rows and imported again (a 3-slice capture); `brdf eval` of it at θin = 60°
     over random views θout ≤ 75° against `brdf eval` of the 4-slice capture (its measured
     60° slice): median and p90 relative error per file.
  4. Time: `brdf convert` of one capture and `brdf preview` of one LUT (median of --repeat).

Relative error of a pair: |Σrgb(a) − Σrgb(b)| / max(Σrgb(b), 1e-3·max over the set).

usage: fidelity.py [--brdf PATH] [--size 96] [--rgl all|a,b] [--convert-args "..."]
                   [--pairs 2000] [--repeat 3] [--out DIR]
"""
import argparse
import json
import os
import re
import shlex
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
METAL = {"name": "metal_a02", "description": "GGX alpha 0.2 metal (issue 18 benchmark)",
         "model": "ggx", "kd": 0.0, "f0": [0.9, 0.6, 0.3], "alpha": 0.2}


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        sys.exit("failed: %s\n%s%s" % (" ".join(cmd), r.stdout, r.stderr))
    return r.stdout


def timed(cmd):
    t = time.perf_counter()
    out = run(cmd)
    return out, time.perf_counter() - t


def rms_of(output):
    m = re.search(r"\(([0-9.]+) % of the mean", output)
    if not m:
        sys.exit("no RMS figure in: " + output)
    return float(m.group(1))


def eval_pairs(brdf, source, pairs, tmp, extra=()):
    path = os.path.join(tmp, "pairs.txt")
    np.savetxt(path, pairs, fmt="%.6f")
    out = run([brdf, "eval", source, "--pairs", path] + list(extra))
    return np.loadtxt(out.splitlines()).reshape(-1, 3)


def rel_err(got, want):
    g, w = got.sum(1), want.sum(1)
    return np.abs(g - w) / np.maximum(w, 1e-3 * w.max())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--brdf", default=os.path.join(ROOT, "build", "dev", "tools", "brdf"))
    ap.add_argument("--data", default=os.environ.get("BRDF_DATA_DIR", "/work/shared/brdf-data"))
    ap.add_argument("--size", type=int, default=96)
    ap.add_argument("--rgl", default="all")
    ap.add_argument("--convert-args", default="", help="extra `brdf convert` options")
    ap.add_argument("--beyond", default=None,
                    help="--beyond of convert and eval (default: the commands' own default)")
    ap.add_argument("--pairs", type=int, default=2000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--out", default=None, help="keep the files here (default: a temp folder)")
    a = ap.parse_args()
    brdf = a.brdf
    extra = shlex.split(a.convert_args)
    beyond = ["--beyond", a.beyond] if a.beyond else []
    extra += beyond
    tmp_obj = None
    if a.out:
        os.makedirs(a.out, exist_ok=True)
        tmp = a.out
    else:
        tmp_obj = tempfile.TemporaryDirectory()
        tmp = tmp_obj.name
    rng = np.random.default_rng(18)
    results = {"size": a.size, "convert_args": " ".join(extra), "analytic": {}, "rgl": {}}

    # 1. Analytic materials.
    metal = os.path.join(tmp, "metal_a02.json")
    with open(metal, "w") as f:
        json.dump(METAL, f)
    n = a.pairs
    both = np.stack([rng.uniform(62, 88, n), np.zeros(n), rng.uniform(62, 88, n),
                     rng.uniform(0, 360, n)], 1)
    print("%-10s %9s %9s %12s %10s %10s" % ("material", "studio", "sky", "eval 62-88",
                                             "convert s", "preview s"))
    for name, mat in (("gold", os.path.join(ROOT, "data-samples", "materials", "gold.json")),
                      ("metal_a02", metal)):
        bpc = os.path.join(tmp, name + ".bpc")
        run([brdf, "capture", "--device", "sim", "--material", mat, "--noise", "0",
             "--sample", name, "--out", bpc, "--quiet", "--force"])
        lut_dir = os.path.join(tmp, "luts_" + name)
        conv = []
        for _ in range(a.repeat):
            _, dt = timed([brdf, "convert", bpc, "--out", lut_dir, "--formats", "ktx2,json",
                           "--quiet", "--force"] + extra)
            conv.append(dt)
        ktx = os.path.join(lut_dir, name + ".ktx2")
        row = {"convert_s": float(np.median(conv))}
        for env in ("studio", "sky"):
            times = []
            for _ in range(a.repeat if env == "studio" else 1):
                out, dt = timed([brdf, "preview", ktx, "--compare", mat, "--env", env,
                                 "--size", str(a.size), "--quiet", "--force", "--out",
                                 os.path.join(tmp, "%s_%s.exr" % (name, env))])
                times.append(dt)
            row[env] = rms_of(out)
            if env == "studio":
                row["preview_s"] = float(np.median(times))
        e = rel_err(eval_pairs(brdf, ktx, both, tmp), eval_pairs(brdf, mat, both, tmp))
        row["eval_both_grazing_median"] = float(np.median(e)) * 100
        results["analytic"][name] = row
        print("%-10s %8.2f%% %8.2f%% %11.1f%% %10.3f %10.3f" % (
            name, row["studio"], row["sky"], row["eval_both_grazing_median"], row["convert_s"],
            row["preview_s"]))
        sys.stdout.flush()

    # 2 and 3. RGL files.
    rgl_dir = os.path.join(a.data, "rgl")
    files = sorted(f for f in os.listdir(rgl_dir) if f.endswith(".bsdf"))
    if a.rgl != "all":
        files = [f for f in files if any(f.startswith(w) for w in a.rgl.split(","))]
    views = np.stack([np.full(n, 60.0), np.zeros(n), rng.uniform(0, 75, n),
                      rng.uniform(0, 360, n)], 1)
    if files:
        print("\n%-34s %9s %11s %9s" % ("RGL file", "studio", "LOO60 med", "LOO60 p90"))
    for f in files:
        src = os.path.join(rgl_dir, f)
        stem = f[:-5]
        bpc4 = os.path.join(tmp, stem + ".bpc")
        run([brdf, "import", src, "--out", bpc4, "--force"])
        csv = os.path.join(tmp, stem + ".csv")
        run([brdf, "export-csv", bpc4, "--out", csv, "--force"])
        csv3 = os.path.join(tmp, stem + "_3.csv")
        with open(csv) as fin, open(csv3, "w") as fout:
            for line in fin:
                if line.startswith("# extra.theta_in_deg="):
                    continue
                if line[:1].isdigit() and abs(float(line.split(",", 1)[0]) - 60.0) < 1e-6:
                    continue
                fout.write(line)
        bpc3 = os.path.join(tmp, stem + "_3.bpc")
        run([brdf, "import", csv3, "--out", bpc3, "--force"])
        lut_dir = os.path.join(tmp, "luts_rgl")
        run([brdf, "convert", bpc4, "--out", lut_dir, "--formats", "ktx2,json", "--quiet",
             "--force"] + extra)
        out = run([brdf, "preview", os.path.join(lut_dir, stem + ".ktx2"), "--compare", src,
                   "--size", str(a.size), "--quiet", "--force", "--out",
                   os.path.join(tmp, stem + ".exr")])
        e = rel_err(eval_pairs(brdf, bpc3, views, tmp, beyond),
                    eval_pairs(brdf, bpc4, views, tmp, beyond))
        row = {"studio": rms_of(out), "loo60_median": float(np.median(e)) * 100,
               "loo60_p90": float(np.percentile(e, 90)) * 100}
        results["rgl"][f] = row
        print("%-34s %8.1f%% %10.1f%% %8.1f%%" % (f, row["studio"], row["loo60_median"],
                                                  row["loo60_p90"]))
        sys.stdout.flush()
    if results["rgl"]:
        s = [r["studio"] for r in results["rgl"].values()]
        l = [r["loo60_median"] for r in results["rgl"].values()]
        print("RGL studio RMS: median %.1f %%, worst %.1f %%; LOO60 median of medians %.1f %%, "
              "worst %.1f %%" % (np.median(s), np.max(s), np.median(l), np.max(l)))
    with open(os.path.join(tmp, "fidelity.json"), "w") as fj:
        json.dump(results, fj, indent=1)
    if a.out:
        print("results in " + os.path.join(tmp, "fidelity.json"))


if __name__ == "__main__":
    main()
