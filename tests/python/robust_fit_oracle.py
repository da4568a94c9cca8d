#!/usr/bin/python3
"""Independent check of `brdf fit --robust` for tests/processing/fit_robust_test.cpp.

  robust_fit_oracle.py DIR

DIR holds fit_data.csv (the samples the fit used: tests/processing/fit_data_csv.h; the weights
are computed here from the grid, fit_weights.py, not taken from the fit), job.json {"model", "loss", "scale"} and two material files: start.json (where
the fit started) and fitted.json (what it returned). The models and the residuals of the loss
come from bench/fit/scipy_baseline.py (transcribed from the published formulas, not from the
C++). Prints one JSON object:
  auto_scale        1.4826 × the median |r| at the start (the scale the docs promise when
                    none is given: brdf/fit/fit.h)
  cost_at_fitted    ½·Σ b²·ln(1 + r²/b²) at the fitted parameters with b = job "scale"
  cost_at_start, plain_cost_at_start   the same at the start, and ½·Σ r² there
  scipy_cost        SciPy's least_squares(loss="cauchy", f_scale=b) final cost from the start
  scipy_x, fitted_x the two parameter vectors (scipy_baseline.vector_of order)
  weight_difference the largest relative difference of the fit's own √w and fit_weights.py's
The process fails (non-zero exit, message on stderr) when numpy or SciPy is missing.
"""
import json
import os
import sys

try:
    import numpy as np
    from scipy.optimize import least_squares
except ImportError as e:  # the test must fail, not skip, without the oracle
    sys.exit("robust_fit_oracle.py: needs numpy and SciPy (Debian python3-numpy, python3-scipy): %s" % e)

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "bench", "fit"))
import scipy_baseline as sb  # noqa: E402

import fit_weights  # noqa: E402


def cauchy_cost(r, b):
    return 0.5 * b * b * float(np.sum(np.log1p((r / b) ** 2)))


def main():
    out_dir = sys.argv[1]
    job = json.load(open(os.path.join(out_dir, "job.json")))
    model, loss, b = job["model"], job["loss"], float(job["scale"])
    d, weight_difference = fit_weights.load_with_own_weights(sb, out_dir)
    start = json.load(open(os.path.join(out_dir, "start.json")))
    fitted = json.load(open(os.path.join(out_dir, "fitted.json")))
    residuals, x0, lo, hi = sb.problem(d, model, start, loss)
    x0 = np.clip(x0, lo, hi)
    r0 = residuals(x0)
    x_fit = sb.vector_of(model, fitted)
    result = least_squares(residuals, x0, bounds=(lo, hi), method="trf", loss="cauchy",
                           f_scale=b, x_scale="jac", jac="3-point", ftol=1e-12, xtol=1e-12, gtol=1e-12,
                           max_nfev=2000)
    print(json.dumps({"weight_difference": weight_difference, "auto_scale": 1.4826 * float(np.median(np.abs(r0))),
                      "cost_at_fitted": cauchy_cost(residuals(x_fit), b),
                      "cost_at_start": cauchy_cost(r0, b), "plain_cost_at_start": 0.5 * float(np.sum(r0 * r0)),
                      "scipy_cost": float(result.cost), "scipy_status": int(result.status),
                      "scipy_nfev": int(result.nfev),
                      "scipy_x": [float(v) for v in result.x], "fitted_x": [float(v) for v in x_fit]}))


if __name__ == "__main__":
    main()
