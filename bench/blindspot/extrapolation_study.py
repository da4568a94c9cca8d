#!/usr/bin/python3
"""Compares ways of filling the instrument's blind spots (issue 18), in numpy, by validation.

The instrument measures the light at θin = 0, 20, 40, 60° and the view up to θb = 75°. The LUT
of docs/design.md §5 stores slices at θin = k·Δin in the specular frame S(θin); this study
builds that LUT at texel centres straight from a truth (an analytic material of
data-samples/materials, written from docs/design.md §9, or an RGL .bsdf file through the numpy
RGL oracle of tests/python/rgl_oracle.py), extends it with each method to θin = 80° and a new
θout band, reads it by the rule of Lut::SampleAngles (reciprocity exchange beyond the LUT's
range, linear in θin at equal (θd, φd), clamp-to-edge), and compares with the truth:

  loo60    leave the last slice out: LUT of θin 0, 20, 40 only, extended, read at θin 60°,
           views θout ≤ 75° (what the instrument measured there): median / p90 rel. error
  both     light and view both in [62°, 88°], random azimuth: median rel. error
  view     light in [0°, 60°], view in [76°, 89°]: median rel. error
  inside   light in [0, 60°], view ≤ 75°: must not change (all methods keep measured texels)

Methods (each keeps every measured texel):
  clamp     today's LUT, K = 4 (nearest slice beyond the range, §6 band with p = 1)
  model     GGX with Schlick Fresnel (kd RGB, f0 RGB, α) fitted to the measured texels, used as
            a ratio on the measured value: θout band f(θk, θb, φ)·M(θ)/M(θb) at equal φout;
            slices beyond the last one from reciprocity where the view is inside the measured
            θin range, else f(θL, θd, φd)·M(θt)/M(θL) at equal specular-frame (θd, φd)
  texel     the same reciprocity, and per texel g = f·cosθi·cosθo continued linearly in θin
            from the last two slices (θout band held, p = 1): no model
  loglin    the same, with log f continued linearly (ratio of the last two slices, limited)
  direct    the fitted model itself wherever nothing is measured (not continuous: a reference)

usage: extrapolation_study.py [--data DIR] [--materials a,b] [--rgl a,b|all] [--pairs N]
"""
import argparse
import json
import math
import os
import sys

import numpy as np
from scipy.optimize import least_squares

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tests", "python"))
from rgl_oracle import RglOracle  # noqa: E402

DEG = math.pi / 180.0
W, H = 361, 181
THETA_B = 75.0
DELTA = 20.0
GRAZE = 89.5  # polar angle the models are read at instead of 90° and below the horizon


def sph(theta_deg, phi_deg):
    t, p = np.asarray(theta_deg) * DEG, np.asarray(phi_deg) * DEG
    s = np.sin(t)
    return np.stack([s * np.cos(p), s * np.sin(p), np.cos(t)], axis=-1)


def spec(theta_m_deg, w):
    """S(θm) of docs/design.md §5 (its own inverse), theta_m broadcast against w[..., 3]."""
    c, s = np.cos(np.asarray(theta_m_deg) * DEG), np.sin(np.asarray(theta_m_deg) * DEG)
    return np.stack([-c * w[..., 0] - s * w[..., 2], -w[..., 1], -s * w[..., 0] + c * w[..., 2]],
                    axis=-1)


def angles(w):
    theta = np.degrees(np.arccos(np.clip(w[..., 2], -1, 1)))
    phi = np.degrees(np.arctan2(w[..., 1], w[..., 0])) % 360.0
    return theta, phi


# ---------------------------------------------------------------------------------------------
# Truths: f_r(θi, θo, φo) with the light at φ = 0, arrays of degrees, result (..., 3).

def ggx_f(kd, f0, alpha, ti, to, po):
    l = sph(ti, np.zeros_like(np.asarray(ti, float)))
    v = sph(to, po)
    a2 = np.asarray(alpha, float) ** 2
    ci = np.clip(l[..., 2], 1e-9, 1)
    co = np.clip(v[..., 2], 1e-9, 1)
    h = l + v
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    ch = np.clip(h[..., 2], 1e-9, 1)[..., None]
    tan2h = (1 - ch * ch) / (ch * ch)
    d = a2 / (math.pi * ch ** 4 * (a2 + tan2h) ** 2)

    def g1(c):
        tan2 = (1 - c * c) / (c * c)
        return 2 / (1 + np.sqrt(1 + a2 * tan2[..., None]))

    g = g1(ci) * g1(co)
    vh = np.clip(np.sum(v * h, axis=-1), 0, 1)[..., None]
    fr = f0 + (1 - f0) * (1 - vh) ** 5
    return kd / math.pi + fr * g * d / (4 * ci * co)[..., None]


def analytic(mat):
    m = mat["model"]
    rgb = lambda x: np.broadcast_to(np.asarray(x, float), (3,))  # noqa: E731

    def f(ti, to, po):
        l = sph(ti, np.zeros_like(np.asarray(ti, float)))
        v = sph(to, po)
        shape = np.broadcast_shapes(np.shape(ti), np.shape(to), np.shape(po)) + (3,)
        if m == "lambert":
            return np.broadcast_to(rgb(mat["rho"]) / math.pi, shape).copy()
        if m == "ggx":
            return ggx_f(rgb(mat["kd"]), rgb(mat["f0"]), float(mat["alpha"]), ti, to, po)
        h = l + v
        h = h / np.linalg.norm(h, axis=-1, keepdims=True)
        ch = np.clip(h[..., 2], 1e-9, 1)[..., None]
        if m == "lafortune":
            r = l * np.array([-1, -1, 1])
            vr = np.clip(np.sum(v * r, -1), 0, 1)[..., None]
            n = float(mat["n"])
            return rgb(mat["kd"]) / math.pi + rgb(mat["ks"]) * (n + 2) / (2 * math.pi) * vr ** n
        if m == "blinn-phong":
            n = float(mat["n"])
            return rgb(mat["kd"]) / math.pi + rgb(mat["ks"]) * (n + 8) / (8 * math.pi) * ch ** n
        if m == "ward":
            a2 = float(mat["alpha"]) ** 2
            tan2h = (1 - ch * ch) / (ch * ch)
            cc = np.sqrt(np.clip(l[..., 2], 1e-9, 1) * np.clip(v[..., 2], 1e-9, 1))[..., None]
            return (rgb(mat["rho_d"]) / math.pi +
                    rgb(mat["rho_s"]) * np.exp(-tan2h / a2) / (4 * math.pi * a2 * cc))
        raise SystemExit("no formula for model " + m)
    return f


def rgl(path):
    o = RglOracle(path)

    def f(ti, to, po):
        shape = np.broadcast_shapes(np.shape(ti), np.shape(to), np.shape(po))
        ti, to, po = (np.broadcast_to(x, shape).ravel() for x in (ti, to, po))
        out = np.zeros((ti.size, 3))
        for s in range(0, ti.size, 200000):
            e = slice(s, s + 200000)
            out[e] = o.eval(sph(ti[e], np.zeros(ti[e].size)), sph(to[e], po[e]))
        return out.reshape(shape + (3,))
    return f


# ---------------------------------------------------------------------------------------------
# The LUT of §5 and its evaluation rule.

def texel_dirs():
    j, i = np.meshgrid(np.arange(H, dtype=float), np.arange(W, dtype=float), indexing="ij")
    return sph(j, i)  # ω_d at texel centres (θd = j°, φd = i°)


WD = texel_dirs()


def slice_view_angles(theta_in):
    """(θout, φout) of every texel of the slice at θin (θout up to 180°)."""
    return angles(spec(theta_in, WD))


def capture_lut(truth, theta_ins):
    """Measured LUT: the truth at texel centres, θout held at θb beyond it (§6 with p = 1, and
    the edge extension below the horizon)."""
    out = []
    for t in theta_ins:
        to, po = slice_view_angles(t)
        out.append(truth(np.full(to.shape, t), np.minimum(to, THETA_B), po))
    return np.stack(out).astype(np.float32)


def sample_texture(lut, thetas, ti, to, po):
    ti, to, po = np.broadcast_arrays(np.asarray(ti, float), np.asarray(to, float),
                                     np.asarray(po, float))
    wd = spec(ti, sph(to, po))
    td, pd = angles(wd)
    k = (ti - thetas[0]) / (thetas[1] - thetas[0])
    K = lut.shape[0]

    def taps(x, n):
        x = np.clip(x, 0, n - 1)
        i0 = np.floor(x).astype(int)
        i1 = np.minimum(i0 + 1, n - 1)
        return i0, i1, (x - i0)[..., None]
    x0, x1, tx = taps(pd, W)
    y0, y1, ty = taps(td, H)
    z0, z1, tz = taps(k, K)

    def bil(z):
        a = lut[z, y0, x0] * (1 - tx) + lut[z, y0, x1] * tx
        b = lut[z, y1, x0] * (1 - tx) + lut[z, y1, x1] * tx
        return a * (1 - ty) + b * ty
    return bil(z0) * (1 - tz) + bil(z1) * tz


def sample_angles(lut, thetas, ti, to, po):
    """Lut::SampleAngles: exchange light and view when the light lies outside the LUT's θin
    range and the view nearer to it."""
    lo, hi = thetas[0], thetas[-1]
    dist = lambda t: np.maximum(np.maximum(lo - t, t - hi), 0)  # noqa: E731
    ti, to, po = np.broadcast_arrays(np.asarray(ti, float), np.asarray(to, float),
                                     np.asarray(po, float))
    ex = (dist(ti) > 1e-3) & (dist(to) < dist(ti))
    a = np.where(ex, to, ti)
    b = np.where(ex, ti, to)
    p = np.where(ex, -po, po)
    return sample_texture(lut, thetas, a, b, p)


# ---------------------------------------------------------------------------------------------
# The model fitted to the measured texels.

def fit_ggx(lut, thetas):
    rng = np.random.default_rng(1)
    ti, to, po, fv = [], [], [], []
    for k, t in enumerate(thetas):
        a, p = slice_view_angles(t)
        ok = a <= THETA_B
        idx = np.flatnonzero(ok.ravel())
        # Every texel near the peak, a random tenth of the rest.
        near = idx[WD[..., 2].ravel()[idx] > math.cos(30 * DEG)]
        far = rng.choice(idx, size=len(idx) // 10, replace=False)
        pick = np.unique(np.concatenate([near, far]))
        ti.append(np.full(pick.size, t))
        to.append(a.ravel()[pick])
        po.append(p.ravel()[pick])
        fv.append(lut[k].reshape(-1, 3)[pick])
    ti, to, po, fv = (np.concatenate(x) for x in (ti, to, po, fv))
    eps = 0.02 * float(np.mean(fv)) + 1e-6

    def unpack(x):
        return x[0:3], x[3:6], x[6]

    def res(x):
        kd, f0, al = unpack(x)
        m = ggx_f(kd, f0, al, ti, to, po)
        return (np.log(m + eps) - np.log(fv + eps)).ravel()
    best = None
    for a0 in (0.05, 0.15, 0.4):
        x0 = np.concatenate([np.full(3, 0.1), np.full(3, 0.5), [a0]])
        r = least_squares(res, x0, bounds=([0] * 6 + [0.005], [1] * 6 + [1.5]), max_nfev=200)
        if best is None or r.cost < best.cost:
            best = r
    kd, f0, al = unpack(best.x)
    return (lambda a, b, c: ggx_f(kd, f0, al, a, b, c)), dict(kd=kd.round(4).tolist(),
                                                              f0=f0.round(4).tolist(),
                                                              alpha=round(float(al), 4))


# ---------------------------------------------------------------------------------------------
# Extensions. Each returns (lut, thetas) with thetas = 0, Δ, …, 80°.

def safe_ratio(a, b):
    return a / np.maximum(b, 1e-12)


def band_by_model(lut, thetas, model):
    out = lut.copy()
    for k, t in enumerate(thetas):
        to, po = slice_view_angles(t)
        band = to > THETA_B
        tt = np.full(to.shape, t)
        r = safe_ratio(model(tt, np.minimum(to, GRAZE), po), model(tt, np.full(to.shape, THETA_B),
                                                                    po))
        out[k][band] = (lut[k] * r)[band]
    return out


def densify(lut, thetas, step):
    """Slices every `step` degrees between the measured ones, linear at equal (θd, φd): read
    by the rule they give the same values as the measured slices alone."""
    n = int(round((thetas[-1] - thetas[0]) / step))
    out = []
    for k in range(n + 1):
        x = k * step / (thetas[1] - thetas[0])
        a = min(int(math.floor(x)), len(thetas) - 1)
        b = min(a + 1, len(thetas) - 1)
        f = x - a
        out.append(lut[a] * (1 - f) + lut[b] * f)
    return np.stack(out).astype(np.float32), [thetas[0] + k * step for k in range(n + 1)]


def rusinkiewicz(ti, to, po):
    """(θh, θd) in degrees of the light at (θi, 0) and the view at (θo, φo)."""
    l = sph(ti, np.zeros_like(np.asarray(ti, float)))
    v = sph(to, po)
    h = l + v
    h = h / np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), 1e-12)
    th = np.degrees(np.arccos(np.clip(h[..., 2], -1, 1)))
    td = np.degrees(np.arccos(np.clip(np.sum(l * h, -1), -1, 1)))
    return th, td


class HalfDiffTable:
    """Σ f / Σ M of the measured texels per 1° × 1° (θh, θd) cell: the data's departure from
    the model as a function of the half and difference angles."""

    def __init__(self, lut, thetas, model):
        num = np.zeros((91, 91, 3))
        den = np.zeros((91, 91, 3))
        for k, t in enumerate(thetas):
            to, po = slice_view_angles(t)
            ok = to <= THETA_B
            tt = np.full(to.shape, t)
            th, td = rusinkiewicz(tt[ok], to[ok], po[ok])
            m = model(tt[ok], to[ok], po[ok])
            i, j = np.rint(th).astype(int), np.rint(td).astype(int)
            np.add.at(num, (i, j), lut[k][ok])
            np.add.at(den, (i, j), m)
        self.cov = den.sum(-1) > 0
        self.c = np.where(den > 0, num / np.maximum(den, 1e-30), 1.0)

    def correction(self, ti, to, po):
        th, td = rusinkiewicz(ti, to, po)
        i, j = np.rint(th).astype(int), np.rint(np.minimum(td, 90)).astype(int)
        return self.c[i, j], self.cov[i, j]


def band_by_table(lut, thetas, model, table):
    out = lut.copy()
    for k, t in enumerate(thetas):
        to, po = slice_view_angles(t)
        band = to > THETA_B
        tt = np.full(to.shape, t)
        toc = np.minimum(to, GRAZE)
        r = safe_ratio(model(tt, toc, po), model(tt, np.full(to.shape, THETA_B), po))
        c, cov = table.correction(tt, toc, po)
        v = np.where(cov[..., None], model(tt, toc, po) * c, lut[k] * r)
        out[k][band] = v[band]
    return out


def extend(lut, thetas, method, model=None, top=80.0, blend_deg=5.0, step=DELTA):
    thetas = list(thetas)
    last = thetas[-1]
    table = HalfDiffTable(lut, thetas, model) if method == "rus" else None
    if method in ("model", "direct"):
        base = band_by_model(lut, thetas, model)
    elif method == "rus":
        base = band_by_table(lut, thetas, model, table)
    else:
        base = lut.copy()
    if step != thetas[1] - thetas[0]:
        base, thetas = densify(base, thetas, step)
    new = []
    targets = np.arange(last + step, top + 1e-9, step)
    for t in targets:
        to, po = slice_view_angles(t)
        toc = np.minimum(to, 90.0)
        tt = np.full(to.shape, t)
        # Reciprocity: the light at the view's angle, the view at t (the band there).
        recip = sample_texture(base, thetas, np.minimum(toc, last), np.full(to.shape, t), -po)
        # Continuation at the same specular-frame texel of the slice below.
        prev = thetas[-1]
        tl, pl = slice_view_angles(prev)
        fl = base[-1]
        if method == "rus":
            ratio = safe_ratio(model(tt, np.minimum(to, GRAZE), po),
                               model(np.full(to.shape, prev), np.minimum(tl, GRAZE), pl))
            c, cov = table.correction(tt, np.minimum(to, GRAZE), po)
            cont = np.where(cov[..., None], model(tt, np.minimum(to, GRAZE), po) * c,
                            fl * ratio)
        elif method in ("model", "direct"):
            ratio = safe_ratio(model(tt, np.minimum(to, GRAZE), po),
                               model(np.full(to.shape, prev), np.minimum(tl, GRAZE), pl))
            cont = fl * ratio
            if method == "direct":
                cont = model(tt, np.minimum(to, GRAZE), po)
        elif method == "texel":
            fp = base[-2]
            tp, _ = slice_view_angles(thetas[-2])
            cosv = lambda a: np.maximum(np.cos(np.minimum(a, GRAZE) * DEG), 0.02)  # noqa: E731
            gl = fl * (math.cos(prev * DEG) * cosv(tl))[..., None]
            gp = fp * (math.cos(thetas[-2] * DEG) * cosv(tp))[..., None]
            s = (t - prev) / (prev - thetas[-2])
            g = np.clip(gl + (gl - gp) * s, 0.25 * gl, 4 * gl)
            cont = g / (math.cos(t * DEG) * cosv(to))[..., None]
        elif method == "loglin":
            fp = base[-2]
            q = np.clip(safe_ratio(fl, fp), 0.25, 4.0)
            q = np.where(fp > 1e-9, q, 1.0)
            cont = fl * q ** ((t - prev) / (prev - thetas[-2]))
        else:
            raise ValueError(method)
        w = np.clip((toc - (last - blend_deg)) / (2 * blend_deg), 0, 1)[..., None]
        new.append(recip * (1 - w) + cont * w)
        base = np.concatenate([base, new[-1][None].astype(np.float32)])
        thetas.append(float(t))
    return base.astype(np.float32), thetas


# ---------------------------------------------------------------------------------------------

def rel_err(got, want):
    g, w = got.sum(-1), want.sum(-1)
    floor = 1e-3 * np.max(w)
    return np.abs(g - w) / np.maximum(w, floor)


def pairs(rng, n, lo_i, hi_i, lo_o, hi_o):
    return (rng.uniform(lo_i, hi_i, n), rng.uniform(lo_o, hi_o, n), rng.uniform(0, 360, n))


def study(name, truth, n, methods):
    rng = np.random.default_rng(7)
    full = [0.0, 20.0, 40.0, 60.0]
    lut4 = capture_lut(truth, full)
    lut3 = lut4[:3]
    model4, p4 = fit_ggx(lut4, full)
    model3, _ = fit_ggx(lut3, full[:3])
    sets = {
        "loo60": (np.full(n, 60.0),) + pairs(rng, n, 0, 0, 0, THETA_B)[1:],
        "both": pairs(rng, n, 62, 88, 62, 88),
        "view": pairs(rng, n, 0, 60, 76, 89),
        "inside": pairs(rng, n, 0, 60, 0, THETA_B),
    }
    truths = {k: truth(*v) for k, v in sets.items()}
    rows = {}
    loo_of = {}
    for m in methods:
        if m == "auto":
            # Per material: the method whose leave-last-slice-out error (median, then p90) is
            # lower, chosen from the capture alone.
            pick = min(("clamp", "model"), key=lambda x: loo_of[x])
            r = dict(rows[pick])
            r["pick"] = pick
            rows[m] = r
            continue
        base_m, _, fine = m.partition("@")
        step = float(fine) if fine else DELTA
        top = 90.0 if step < DELTA else 80.0
        if m == "clamp":
            e4, t4, e3, t3 = lut4, full, lut3, full[:3]
        else:
            e4, t4 = extend(lut4, full, base_m, model4, top=top, step=step)
            e3, t3 = extend(lut3, full[:3], base_m, model3, top=top, step=step)
        r = {}
        g = sample_angles(e3, t3, *sets["loo60"])
        e = rel_err(g, truths["loo60"])
        r["loo60"] = (np.median(e), np.percentile(e, 90))
        loo_of[m] = (round(float(np.median(e)), 3), float(np.percentile(e, 90)))
        for k in ("both", "view", "inside"):
            e = rel_err(sample_angles(e4, t4, *sets[k]), truths[k])
            r[k] = np.median(e)
        k40 = t4.index(40.0)
        measured_kept = bool(np.array_equal(
            np.where((slice_view_angles(40.0)[0] <= THETA_B)[..., None], e4[k40], 0),
            np.where((slice_view_angles(40.0)[0] <= THETA_B)[..., None], lut4[2], 0)))
        r["kept"] = measured_kept
        rows[m] = r
    print("%s  (GGX fit of 4 slices: %s)" % (name, json.dumps(p4)))
    for m, r in rows.items():
        print("  %-7s loo60 median %6.1f %%  p90 %6.1f %%  both %6.1f %%  view %6.1f %%  "
              "inside %5.2f %%  measured kept %s %s" % (
                  m, 100 * r["loo60"][0], 100 * r["loo60"][1], 100 * r["both"],
                  100 * r["view"], 100 * r["inside"], r["kept"], r.get("pick", "")))
    sys.stdout.flush()
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", default=os.environ.get("BRDF_DATA_DIR", "/work/shared/brdf-data"))
    ap.add_argument("--materials", default="gold,metal_a02,wood_oak,wood_walnut,"
                                           "plastic_glossy_red,plastic_matte_white")
    ap.add_argument("--rgl", default="all")
    ap.add_argument("--pairs", type=int, default=4000)
    ap.add_argument("--methods", default="clamp,model,texel,loglin,direct,model@10")
    a = ap.parse_args()
    methods = a.methods.split(",")
    summary = {}
    for m in filter(None, a.materials.split(",")):
        if m == "metal_a02":
            mat = {"model": "ggx", "kd": 0.0, "f0": [0.9, 0.6, 0.3], "alpha": 0.2}
        else:
            mat = json.load(open(os.path.join(ROOT, "data-samples", "materials", m + ".json")))
        summary[m] = study(m, analytic(mat), a.pairs, methods)
    rgl_dir = os.path.join(a.data, "rgl")
    files = sorted(f for f in os.listdir(rgl_dir) if f.endswith(".bsdf"))
    if a.rgl != "all":
        want = a.rgl.split(",")
        files = [f for f in files if any(f.startswith(w) for w in want)]
    rgl_rows = {}
    for f in files:
        rgl_rows[f] = study(f, rgl(os.path.join(rgl_dir, f)), a.pairs, methods)
    if rgl_rows:
        print("RGL summary over %d files (median of per-file medians / worst file):" %
              len(rgl_rows))
        for m in methods:
            for k in ("loo60", "both", "view"):
                v = [r[m][k][0] if k == "loo60" else r[m][k] for r in rgl_rows.values()]
                print("  %-7s %-6s median %6.1f %%  worst %6.1f %%" % (
                    m, k, 100 * np.median(v), 100 * np.max(v)))


if __name__ == "__main__":
    main()
