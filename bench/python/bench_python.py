#!/usr/bin/python3
"""Timings of the Python module brdf: `import brdf` and eval_deg throughput, against
`brdf eval --pairs` on the same source and pairs and, for the exported LUT, against a pure-numpy
trilinear lookup of the same texture (numpy_trilinear.py) (docs/benchmarks/python.md).

Usage: PYTHONPATH=build/dev/python /usr/bin/python3 bench/python/bench_python.py build/dev/tools/brdf
Medians of several runs, baselines measured in the same run (the machine is shared and noisy).
"""
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import brdf

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from numpy_trilinear import NumpyLut  # noqa: E402


def median_seconds(f, runs):
    times = []
    for _ in range(runs):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def python_start(code, runs=15):
    return median_seconds(
        lambda: subprocess.run([sys.executable, "-c", code], check=True, env=os.environ), runs)


def main():
    tool = sys.argv[1]
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([tool, "convert", "copper", "--out", tmp], check=True,
                       capture_output=True)
        sources = {"gold (analytic)": "gold", "copper.ktx2 (exported LUT)": f"{tmp}/copper.ktx2"}
        rgl = os.path.join(os.environ.get("BRDF_DATA_DIR", "../shared/brdf-data"), "rgl",
                           "aurora_white_rgb.bsdf")
        if os.path.isfile(rgl):
            sources["aurora_white_rgb.bsdf (RGL)"] = rgl

        bare = python_start("pass")
        numpy_only = python_start("import numpy")
        with_brdf = python_start("import brdf")
        print(f"start-up, median of 15: python3 -c pass {bare * 1e3:.1f} ms, "
              f"import numpy {numpy_only * 1e3:.1f} ms, import brdf {with_brdf * 1e3:.1f} ms "
              f"(brdf over numpy: {(with_brdf - numpy_only) * 1e3:.1f} ms)")

        rng = np.random.default_rng(1)
        n = 2_000_000
        args = (rng.uniform(0, 90, n), rng.uniform(0, 360, n), rng.uniform(0, 90, n),
                rng.uniform(0, 360, n))
        n_cli = 200_000
        pairs = os.path.join(tmp, "pairs.txt")
        with open(pairs, "w") as f:
            for row in zip(*(a[:n_cli].tolist() for a in args)):
                f.write("%r %r %r %r\n" % row)
        for label, path in sources.items():
            s = brdf.open(path)
            s.eval_deg(*(a[:1000] for a in args))  # warm-up
            t_py = median_seconds(lambda: s.eval_deg(*args), 5)
            t_one = median_seconds(lambda: s.eval_deg(*args, jobs=1), 5)
            t_cli = median_seconds(
                lambda: subprocess.run([tool, "eval", path, "--pairs", pairs], check=True,
                                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL), 3)
            print(f"{label}: eval_deg {n / t_py / 1e6:.2f} M/s ({n} pairs, median of 5; "
                  f"jobs=1: {n / t_one / 1e6:.2f} M/s); "
                  f"brdf eval --pairs {n_cli / t_cli / 1e6:.3f} M/s ({n_cli} pairs incl. "
                  f"start-up and text, median of 3); ratio {(n / t_py) / (n_cli / t_cli):.0f}x")
            if path.endswith(".ktx2"):
                # The direction-vector path (LutBrdf::Eval per pair, what eval_deg called before
                # brdf/core/eval_pairs.h), directions precomputed by numpy.
                t, p = np.radians(args[0]), np.radians(args[1])
                wi = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)
                t, p = np.radians(args[2]), np.radians(args[3])
                wo = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)
                t_vec = median_seconds(lambda: s.eval(wi, wo), 5)
                print(f"  eval(wi, wo), LutBrdf::Eval per pair: {n / t_vec / 1e6:.2f} M/s "
                      f"(median of 5; eval_deg {t_vec / t_py:.2f}x faster)")
                # The same texture looked up by numpy (bench/python/numpy_trilinear.py).
                lut = NumpyLut.from_ktx2(path)
                t_np = median_seconds(lambda: lut.eval_deg(*args), 3)
                diff = np.max(np.abs(lut.eval_deg(*(a[:100000] for a in args)) -
                                     s.eval_deg(*(a[:100000] for a in args))))
                print(f"  numpy trilinear lookup of the same texture: {n / t_np / 1e6:.2f} M/s "
                      f"(median of 3; eval_deg {t_np / t_py:.1f}x faster; largest difference "
                      f"{diff:.2g} 1/sr on 100,000 pairs)")


if __name__ == "__main__":
    main()
