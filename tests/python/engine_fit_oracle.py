#!/usr/bin/python3
"""Independent optimum of the engine-model fits for tests/processing/fit_engine_scipy_test.cpp.

  engine_fit_oracle.py DIR

DIR holds fit_data.csv (the samples the fits used: tests/processing/fit_data_csv.h; the
solid-angle weights are computed here from the grid, fit_weights.py) and job.json
{"fits": [{"model", "fitted": material file}]}. The engine models and the ngan residuals
√w·cosθin·(f − m) come from bench/fit/scipy_baseline.py (transcribed from the engines' shader
sources, not from the C++). For every fit, scipy.optimize.least_squares (trf, bounds [0, 1])
runs from the fitted parameters, from the middle of the range and from a seeded random
point; the lowest final cost is SciPy's optimum. Prints one JSON object:
  weight_difference   the largest relative difference of the fit's own √w and fit_weights.py's
  fits: [{"model", "cost_at_fitted" (½·Σ r² at the fitted parameters), "scipy_cost",
          "scipy_x", "fitted_x", "scipy_start" (which start reached it)}]
The process fails (non-zero exit, message on stderr) when numpy or SciPy is missing.
"""
import json
import os
import sys

try:
    import numpy as np
    from scipy.optimize import least_squares
except ImportError as e:  # the test must fail, not skip, without the oracle
    sys.exit("engine_fit_oracle.py: needs numpy and SciPy (Debian python3-numpy, python3-scipy): %s" % e)

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "bench", "fit"))
import scipy_baseline as sb  # noqa: E402

import fit_weights  # noqa: E402


def main():
    out_dir = sys.argv[1]
    job = json.load(open(os.path.join(out_dir, "job.json")))
    d, weight_difference = fit_weights.load_with_own_weights(sb, out_dir)
    rng = np.random.default_rng(7)
    results = []
    for fit in job["fits"]:
        model, fitted = fit["model"], fit["fitted"]
        residuals, x_fit, lo, hi = sb.problem(d, model, fitted, "ngan")
        r_fit = residuals(x_fit)
        starts = {"fitted": x_fit, "middle": 0.5 * (lo + hi)}
        for k in range(1):
            starts["random%d" % k] = rng.uniform(lo, hi)
        best = None
        for name, x0 in starts.items():
            res = least_squares(residuals, np.clip(x0, lo, hi), bounds=(lo, hi), method="trf",
                                x_scale="jac", ftol=1e-12, xtol=1e-12, gtol=1e-12, max_nfev=400)
            if best is None or res.cost < best[1].cost:
                best = (name, res)
        results.append({"model": model, "cost_at_fitted": 0.5 * float(np.sum(r_fit * r_fit)),
                        "scipy_cost": float(best[1].cost), "scipy_start": best[0],
                        "scipy_x": [float(v) for v in best[1].x], "fitted_x": [float(v) for v in x_fit]})
    print(json.dumps({"weight_difference": weight_difference, "fits": results}))


if __name__ == "__main__":
    main()
