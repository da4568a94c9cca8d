#!/usr/bin/python3
"""Accuracy of the tabulated RGL form (brdf::RglTabulatedBrdf, what `brdf preview` integrates
for isotropic .bsdf files) against the float64 NumPy oracle of the exact evaluator
(rgl_oracle.py, written from the published algorithm; the C++ exact evaluator agrees with it to
~1e-11).

Run as a test:  rgl_tabulated_check.py --driver PATH/rgl_eval_points --data-dir BRDF_DATA_DIR

For each file, three measures, each with a bound that fails the test when exceeded:
  * pointwise: at the oracle's direction pairs (a third uniform, a third near the mirror
    direction, a third at the file's incidence nodes) where f_r·cosθo is at least 1 % of the
    sample's largest value, the 99th and 99.9th percentiles of the relative difference of f_r
    (all channels; the maximum is printed: it lies on the creases where the RGB table changes
    within one of its cells, e.g. at the edge of the measured region);
  * directional albedo, both ways: ρ(ωi) = ∫ f_r cosθo dωo at several ωi, and the integral over
    ωi at fixed ωo (what the preview computes per pixel, under a white furnace), both by the same
    midpoint rule in (cosθ, φ) refined around the mirror direction, relative difference;
  * the cosine-weighted RMS difference of f_r·cosθo over uniform pairs relative to its mean
    (printed; dominated by the peak of sharp lobes, so it is bounded loosely).
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from rgl_oracle import RglOracle, direction_pairs, sph  # noqa: E402


def tabulated(driver, path, wi, wo, tmp):
    pairs = os.path.join(tmp, 'pairs.f64')
    result = os.path.join(tmp, 'result.f64')
    np.concatenate([wi, wo], 1).astype('<f8').tofile(pairs)
    subprocess.run([driver, path, pairs, result, '--tabulated'], check=True)
    return np.fromfile(result, '<f8').reshape(-1, 3)


def hemisphere_grid(n_theta, n_phi, axis=None, cap_deg=0.0, cap_n=0):
    """Midpoint rule over the upper hemisphere in (cosθ, φ): directions and solid angles. With
    `axis`, a cap of half-angle cap_deg around it is removed from the coarse grid and covered by
    a fine polar grid of its own (cap_n × 4 cap_n cells), so that a lobe of a fraction of a
    degree around the mirror direction is resolved. Directions below the horizon get weight 0."""
    z = (np.arange(n_theta) + 0.5) / n_theta
    phi = (np.arange(n_phi) + 0.5) / n_phi * 2 * np.pi
    zz, pp = np.meshgrid(z, phi, indexing='ij')
    dirs = sph(np.arccos(zz.ravel()), pp.ravel())
    weight = np.full(len(dirs), 2 * np.pi / (n_theta * n_phi))
    if axis is None:
        return dirs, weight
    cos_cap = np.cos(np.radians(cap_deg))
    weight[dirs @ axis > cos_cap] = 0.0
    # Fine cap: local (cosα, β) grid around `axis`.
    ca = 1 - (1 - cos_cap) * (np.arange(cap_n) + 0.5) / cap_n
    be = (np.arange(4 * cap_n) + 0.5) / (4 * cap_n) * 2 * np.pi
    aa, bb = np.meshgrid(np.arccos(ca), be, indexing='ij')
    local = sph(aa.ravel(), bb.ravel())
    t = np.cross(axis, [0.0, 0.0, 1.0] if abs(axis[2]) < 0.9 else [1.0, 0.0, 0.0])
    t /= np.linalg.norm(t)
    b = np.cross(axis, t)
    cap = local[:, :1] * t + local[:, 1:2] * b + local[:, 2:] * axis
    cap_w = np.full(len(cap), 2 * np.pi * (1 - cos_cap) / (cap_n * 4 * cap_n))
    cap_w[cap[:, 2] <= 0] = 0.0
    return np.concatenate([dirs, cap]), np.concatenate([weight, cap_w])


def albedos(driver, path, oracle, tmp, angles_deg):
    """Relative albedo differences: [(label, exact, tabulated)] for fixed ωi (integral over ωo)
    and fixed ωo (integral over ωi), at θ = angles_deg, φ = 30°."""
    rows, wis, wos, spans = [], [], [], []
    for fixed_is_wi in (True, False):
        for theta in angles_deg:
            w = sph(np.radians(theta), np.radians(30.0))
            mirror = np.array([-w[0], -w[1], w[2]])
            dirs, weight = hemisphere_grid(128, 512, mirror, 3.0, 96)
            fixed = np.repeat(w[None, :], len(dirs), 0)
            wis.append(fixed if fixed_is_wi else dirs)
            wos.append(dirs if fixed_is_wi else fixed)
            spans.append((('ωi' if fixed_is_wi else 'ωo') + ' θ=%g°' % theta, weight,
                          dirs[:, 2]))
    wi, wo = np.concatenate(wis), np.concatenate(wos)
    exact = oracle.eval(wi, wo)
    tab = tabulated(driver, path, wi, wo, tmp)
    start = 0
    for label, weight, cos_var in spans:
        end = start + len(weight)
        wgt = (weight * cos_var)[:, None]
        rows.append((label, np.sum(exact[start:end] * wgt, 0), np.sum(tab[start:end] * wgt, 0)))
        start = end
    return rows


def check(driver, path, n, seed, bounds, tmp):
    name = os.path.basename(path)
    oracle = RglOracle(path)
    ok = True
    # Pointwise.
    wi, wo = direction_pairs(n, seed)
    exact = oracle.eval(wi, wo)
    tab = tabulated(driver, path, wi, wo, tmp)
    cos_o = wo[:, 2:3]
    fc = exact * np.where(cos_o > 0, cos_o, 0)
    big = fc >= 0.01 * fc.max(axis=0)
    rel = np.abs(tab - exact)[big] / np.abs(exact)[big]
    p99, p999, worst = (float(np.percentile(rel, 99)), float(np.percentile(rel, 99.9)),
                        float(rel.max()))
    # Cosine-weighted RMS over the uniform third (cosθi · cosθo weights).
    k = n // 3
    w = (wi[:k, 2] * wo[:k, 2])[:, None]
    d = (tab[:k] - exact[:k]) * wo[:k, 2:3]
    rms = float(np.sqrt(np.sum(w * d * d) / np.sum(w)) /
                (np.sum(w * exact[:k] * wo[:k, 2:3]) / np.sum(w)))
    print('%-28s pointwise (f·cos >= 1%% of max, %d values): p99 %.2f %%  p99.9 %.2f %%  '
          'max %.2f %%;  cos-weighted RMS / mean %.2f %%'
          % (name, rel.size, 100 * p99, 100 * p999, 100 * worst, 100 * rms))
    if p99 > bounds['p99'] or p999 > bounds['p999'] or rms > bounds['rms']:
        print('  FAILED: bounds p99 %.1f %%, p99.9 %.1f %%, RMS %.1f %%'
              % (100 * bounds['p99'], 100 * bounds['p999'], 100 * bounds['rms']))
        ok = False
    # Albedo.
    worst_albedo = 0.0
    for label, a_exact, a_tab in albedos(driver, path, oracle, tmp, [0.0, 30.0, 60.0, 75.0]):
        r = np.abs(a_tab - a_exact) / np.maximum(a_exact, 1e-12)
        worst_albedo = max(worst_albedo, float(r.max()))
        print('    albedo, fixed %-10s exact %s  tabulated %s  rel diff %.3f %%'
              % (label, np.array2string(a_exact, precision=4),
                 np.array2string(a_tab, precision=4), 100 * r.max()))
    if worst_albedo > bounds['albedo']:
        print('  FAILED: albedo differs by %.3f %% > %.2f %%' % (100 * worst_albedo,
                                                               100 * bounds['albedo']))
        ok = False
    return ok


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--driver', required=True)
    ap.add_argument('--data-dir', required=True,
                    help='the brdf-data folder (its rgl/ is read); $BRDF_DATA_DIR overrides it')
    ap.add_argument('--files', nargs='*', default=[
        'cc_ibiza_sunset_rgb.bsdf', 'chm_light_blue_rgb.bsdf', 'paper_white_rgb.bsdf',
        'cg_sunflower_rgb.bsdf'])
    ap.add_argument('--pairs', type=int, default=30000)
    # The bounds (docs/preview.md, "RGL files"): the 99th and 99.9th percentiles of the
    # pointwise relative difference where f·cos is not tiny, the cosine-weighted RMS relative to
    # the mean over uniform pairs, the largest relative albedo difference.
    ap.add_argument('--p99', type=float, default=0.04)
    ap.add_argument('--p999', type=float, default=0.15)
    ap.add_argument('--rms', type=float, default=0.10)
    ap.add_argument('--albedo', type=float, default=0.005)
    args = ap.parse_args()
    data_dir = os.environ.get('BRDF_DATA_DIR') or args.data_dir
    rgl_dir = os.path.join(data_dir, 'rgl')
    if not os.path.isdir(rgl_dir):
        sys.exit(f"third-party data folder '{rgl_dir}' not found: set BRDF_DATA_DIR to the "
                 "brdf-data folder (see README.md, 'Test data')")
    bounds = {'p99': args.p99, 'p999': args.p999, 'rms': args.rms, 'albedo': args.albedo}
    ok = True
    with tempfile.TemporaryDirectory() as tmp:
        for i, f in enumerate(args.files):
            ok &= check(args.driver, os.path.join(rgl_dir, f), args.pairs, 4321 + i, bounds, tmp)
    if not ok:
        print('FAILED: the tabulated form and the NumPy oracle differ by more than the bounds')
        return 1
    print('OK')
    return 0


if __name__ == '__main__':
    sys.exit(main())
