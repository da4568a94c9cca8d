"""The solid-angle weights of a fit's samples, computed from the grid (brdf/fit/fit.h: each sample
carries the solid angle of its cell on the measurement grid, estimated per slice from its θout
rows and the number of φout samples in each row, normalised to sum 1), for the fit oracles
(robust_fit_oracle.py, engine_fit_oracle.py).

A slice's θout rows θ_0 < … < θ_n (degrees) get cells bounded by the midpoints between rows;
the first row's lower edge is half a step below it (0 at the pole), the last row's upper edge
half a step above it, both within [0°, 90°]. A row's cell is the zone 2π(cos θ_lo − cos θ_hi),
shared equally by the row's samples.
"""
import numpy as np


def cell_sqrt_weights(d):
    """√w of every sample of `d` (scipy_baseline.load's columns plus "slice"); θout = acos(n·v)."""
    theta = np.degrees(np.arccos(np.clip(d["n_dot_v"], -1.0, 1.0)))
    key = np.round(theta * 1000.0).astype(np.int64)
    slices = d["slice"].astype(np.int64)
    area = np.zeros(len(key))
    for s in np.unique(slices):
        in_slice = slices == s
        rows, inverse, counts = np.unique(key[in_slice], return_inverse=True, return_counts=True)
        deg = rows / 1000.0
        step_lo = deg[1] - deg[0] if len(deg) > 1 else 1.0
        step_hi = deg[-1] - deg[-2] if len(deg) > 1 else 1.0
        prev = np.concatenate([[deg[0] - step_lo], deg[:-1]])
        nxt = np.concatenate([deg[1:], [deg[-1] + step_hi]])
        lo = np.radians(np.maximum(0.0, 0.5 * (prev + deg)))
        hi = np.radians(np.minimum(90.0, 0.5 * (deg + nxt)))
        zone = 2 * np.pi * (np.cos(lo) - np.cos(hi))
        area[in_slice] = (zone / counts)[inverse]
    return np.sqrt(area / area.sum())


def load_with_own_weights(sb, out_dir):
    """scipy_baseline.load(out_dir) with "sqrt_w" replaced by cell_sqrt_weights and the fit's own
    column kept as "library_sqrt_w"; also returns the largest relative difference of the two."""
    d = np.loadtxt(out_dir + "/fit_data.csv", delimiter=",", skiprows=1)
    cols = "n_dot_l n_dot_v n_dot_h v_dot_h l_dot_v v_dot_r m_r m_g m_b cos_in sqrt_w slice".split()
    d = {c: d[:, i] for i, c in enumerate(cols)}
    d["library_sqrt_w"] = d["sqrt_w"]
    d["sqrt_w"] = cell_sqrt_weights(d)
    diff = float(np.max(np.abs(d["library_sqrt_w"] - d["sqrt_w"]) / d["sqrt_w"]))
    return d, diff
