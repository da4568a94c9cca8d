#!/usr/bin/python3
"""SciPy baseline of bench_fit: scipy.optimize.least_squares (trf, bounds, 2-point Jacobian)
fitting the same model (docs/design.md §9 ggx or lafortune, one value per channel), the same
loss (ngan: sqrt(w)·cosθin·(f − m)) and the same samples and weights (fit_data.csv written by
bench_fit) from the same start (start_MODEL.json). Cost convention as Ceres: ½·Σ r².

  scipy_baseline.py OUT_DIR MODEL [REPEATS]
prints {"model", "mode": "scipy", "seconds" (median), "cost", "nfev"} as JSON.
"""
import json
import sys
import time

import numpy as np
from scipy.optimize import least_squares


def load(out_dir):
    d = np.loadtxt(out_dir + "/fit_data.csv", delimiter=",", skiprows=1)
    cols = "n_dot_l n_dot_v n_dot_h v_dot_h l_dot_v v_dot_r m_r m_g m_b cos_in sqrt_w".split()
    return {c: d[:, i] for i, c in enumerate(cols)}


def ggx(d, kd, f0, alpha):
    a2 = alpha * alpha
    fres = f0 + (1 - f0) * (1 - d["v_dot_h"]) ** 5

    def g1(c):
        tan2 = (1 - c * c) / (c * c)
        return 2 / (1 + np.sqrt(1 + a2 * tan2))

    denom = d["n_dot_h"] ** 2 * (a2 - 1) + 1
    dist = a2 / (np.pi * denom * denom)
    return kd / np.pi + fres * g1(d["n_dot_l"]) * g1(d["n_dot_v"]) * dist / (4 * d["n_dot_l"] * d["n_dot_v"])


def lafortune(d, kd, ks, n):
    c = d["v_dot_r"]
    lobe = np.where(c > 0, np.abs(c) ** n, 0.0)
    return kd / np.pi + ks * (n + 2) / (2 * np.pi) * lobe


MODELS = {"ggx": (ggx, ["kd", "f0", "alpha"], [(0, 1), (0, 1), (1e-3, 1)]),
          "lafortune": (lafortune, ["kd", "ks", "n"], [(0, 1), (0, 1), (1e-3, 1e6)])}


def main():
    out_dir, model = sys.argv[1], sys.argv[2]
    repeats = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    d = load(out_dir)
    f, names, bounds = MODELS[model]
    start = json.load(open(out_dir + "/start_" + model + ".json"))

    def as_rgb(v):
        return np.array(v if isinstance(v, list) else [v, v, v], dtype=float)

    x0 = np.concatenate([as_rgb(start[n]) for n in names])  # kd rgb, ks rgb, shape rgb
    lo = np.concatenate([[b[0]] * 3 for b in bounds])
    hi = np.concatenate([[b[1]] * 3 for b in bounds])
    w = d["sqrt_w"] * d["cos_in"]
    meas = [d["m_r"], d["m_g"], d["m_b"]]

    def residuals(x):
        return np.concatenate([w * (f(d, x[c], x[3 + c], x[6 + c]) - meas[c]) for c in range(3)])

    times, cpu, result = [], [], None
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        result = least_squares(residuals, x0, bounds=(lo, hi), method="trf", ftol=1e-10, xtol=1e-10, gtol=1e-12)
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    times.sort()
    cpu.sort()
    print(json.dumps({"model": model, "mode": "scipy", "threads": 1, "seconds": times[len(times) // 2], "cpu_seconds": cpu[len(cpu) // 2],
                      "cost": float(result.cost), "nfev": int(result.nfev),
                      "x": [float(v) for v in result.x]}))


if __name__ == "__main__":
    main()
