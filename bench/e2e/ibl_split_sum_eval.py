#!/usr/bin/python3
"""How far `brdf preview --ibl engine` (the engines' split sum of the IBL pack) lies from the
true environment-lit preview (the rendering integral), per material and pooled, on the CPU.

The materials, environment, image size and error measures are those of the ibl_browser test
(tests/engines/ibl_browser_test.py: its environment EXR, its sphere mask, relative RMSE and
per-pixel error): every library material (`brdf materials`), every RGL file of DATA_DIR/rgl
through `brdf import`, and data-samples/captures/gold.bpc with `--beyond auto` (37 today), or
the names given with --only. Prints one line per material (relative RMSE, p95 pixel error),
the medians and the pooled 95th percentile over every
material's pixels.

Usage: bench/e2e/ibl_split_sum_eval.py BRDF_TOOL [DATA_DIR] [--work DIR] [--env MAP]
       [--only NAME,NAME...]
(Debian python3 with numpy and OpenImageIO; DATA_DIR default ../shared/brdf-data.)
Environment variables are passed on to `brdf`, so one script run can compare builds or forms.
"""
import argparse
import glob
import json
import os
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tests", "engines"))
import ibl_browser_test as ibt  # noqa: E402  (its environment, mask and metrics)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("tool")
    ap.add_argument("data_dir", nargs="?", default=os.path.join(HERE, "..", "..", "..", "shared",
                                                                "brdf-data"))
    ap.add_argument("--work", default="")
    ap.add_argument("--env", default="", help="a map for brdf preview --env instead of the test's")
    ap.add_argument("--only", default="", help="comma-separated material names")
    args = ap.parse_args()
    work = args.work or tempfile.mkdtemp(prefix="brdf_ibl_eval_")
    os.makedirs(work, exist_ok=True)
    env = args.env or os.path.join(work, "env.exr")
    out = os.path.join(work, "luts")
    library = [m["name"] for m in json.loads(subprocess.run(
        [args.tool, "materials", "--json"], check=True, capture_output=True, text=True).stdout)]
    rgl = sorted(glob.glob(os.path.join(args.data_dir, "rgl", "*.bsdf")))
    rgl_names = [os.path.basename(p)[:-len(".bsdf")] for p in rgl]
    names = library + rgl_names + [ibt.CAPTURE]
    if args.only:
        names = [n for n in names if n in args.only.split(",")]
    if not os.path.isfile(os.path.join(out, ibt.CAPTURE + ".ktx2")):
        if not args.env:
            ibt.write_environment(env)
        captures = []
        for n, p in zip(rgl_names, rgl):
            captures.append(os.path.join(work, n + ".bpc"))
            subprocess.run([args.tool, "import", p, "--out", captures[-1]], check=True,
                           stdout=subprocess.DEVNULL)
        subprocess.run([args.tool, "convert", *library, *captures, "--out", out, "--quiet",
                        "--jobs", "2", "--formats", "ktx2"], check=True)
        capture = os.path.join(work, ibt.CAPTURE + ".bpc")
        src = os.path.join(HERE, "..", "..", "data-samples", "captures", "gold.bpc")
        with open(src, "rb") as f, open(capture, "wb") as g:
            g.write(f.read())
        subprocess.run([args.tool, "convert", capture, "--beyond", "auto", "--out", out,
                        "--quiet", "--formats", "ktx2"], check=True)
    preview = [args.tool, "preview", "--env", env, "--size", str(ibt.SIZE), "--no-background",
               "--quiet", "--jobs", "1"]

    def render(n):
        ktx2 = os.path.join(out, n + ".ktx2")
        truth = os.path.join(work, n + ".truth.exr")
        if not os.path.isfile(truth):  # the truth does not depend on the split sum
            subprocess.run(preview + [ktx2, "--out", truth], check=True)
        engine = os.path.join(work, n + ".engine.exr")
        subprocess.run(preview + [ktx2, "--ibl", "engine", "--force", "--out", engine], check=True)
        return truth, engine

    with ThreadPoolExecutor(2) as pool:
        files = list(pool.map(render, names))
    rmse, p95, pooled = [], [], []
    for n, (truth, engine) in zip(names, files):
        t, e = ibt.read_exr(truth), ibt.read_exr(engine)
        r, p = ibt.metrics(e, t)
        rmse.append(r)
        p95.append(p)
        pooled.append(ibt.pixel_errors(e, t))
        print(f"{n:28s} rmse {100 * r:6.2f} %  p95 {100 * p:6.1f} %")
    print(f"median rmse {100 * np.median(rmse):.2f} %  median p95 {100 * np.median(p95):.1f} %  "
          f"pooled p95 {100 * np.percentile(np.concatenate(pooled), 95):.1f} %  (work {work})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
