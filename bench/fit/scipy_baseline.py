#!/usr/bin/python3
"""SciPy baseline of bench_fit: scipy.optimize.least_squares (trf, bounds, 2-point Jacobian)
fitting the same model, the same loss (ngan: sqrt(w)·cosθin·(f − m)) and the same samples and
weights (fit_data.csv written by bench_fit) from the same start (start_MODEL.json). Cost
convention as Ceres: ½·Σ r².

The models are transcribed here from their published formulas, not from brdf-toolchain's C++:
  lafortune, blinn-phong, ggx, ward   docs/design.md §9 (one value per channel, the channels
                                      fitted together as one 9-parameter problem)
  unreal-defaultlit                   Unreal Engine BRDF.ush (D_GGX, Vis_SmithJointApprox,
                                      F_Schlick with F90 = saturate(50·F0.g), Diffuse_Lambert)
                                      and ShadingModels.ush (DefaultLitBxDF)
  unity-hdrp-lit                      Unity SRP core BSDF.hlsl (F_Schlick, D_GGX,
                                      V_SmithJointGGX, DisneyDiffuse), HDRP Lit.hlsl
                                      (ComputeDiffuseColor, ComputeFresnel0 with 0.04)
  unity-urp-lit                       Unity URP BRDF.hlsl (InitializeBRDFData,
                                      DirectBRDFSpecular), divided by π (URP's lights carry it)

  scipy_baseline.py OUT_DIR MODEL [REPEATS]
prints {"model", "mode": "scipy", "seconds", "cpu_seconds" (medians), "cost", "nfev", "x"}.
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


def blinn_phong(d, kd, ks, n):
    c = d["n_dot_h"]
    lobe = np.where(c > 0, np.abs(c) ** n, 0.0)
    return kd / np.pi + ks * (n + 8) / (8 * np.pi) * lobe


def ward(d, rho_d, rho_s, alpha):
    cos2 = d["n_dot_h"] ** 2
    tan2 = (1 - cos2) / cos2
    a2 = alpha * alpha
    return rho_d / np.pi + rho_s * np.exp(-tan2 / a2) / (4 * np.pi * a2 * np.sqrt(d["n_dot_l"] * d["n_dot_v"]))


def pow5(x):
    return x * x * x * x * x


def unreal(d, x):
    base, metallic, specular, roughness = x[0:3], x[3], x[4], x[5]
    nol, noh, voh = d["n_dot_l"], d["n_dot_h"], d["v_dot_h"]
    nov = np.minimum(1.0, np.abs(d["n_dot_v"]) + 1e-5)
    a2 = max(roughness ** 4, 1e-12)
    a = np.sqrt(a2)
    dd = (noh * a2 - noh) * noh + 1
    dist = a2 / (np.pi * dd * dd)
    vis = 0.5 / (nol * (nov * (1 - a) + a) + nov * (nol * (1 - a) + a))
    fc = pow5(1 - voh)
    f0 = 0.08 * specular * (1 - metallic) + base * metallic
    f90 = min(max(50 * f0[1], 0.0), 1.0)
    return [base[c] * (1 - metallic) / np.pi + dist * vis * (f90 * fc + (1 - fc) * f0[c]) for c in range(3)]


def hdrp_terms(d, smoothness):
    """The terms HDRP Lit's two parameterisations share: GGX D, the height-correlated visibility,
    the Disney diffuse (renormalised) and the Schlick weight (1 - l·h)^5."""
    perceptual = 1 - smoothness
    alpha = max(perceptual * perceptual, 1e-4)
    a2 = alpha * alpha
    nol, noh, lov, loh = d["n_dot_l"], d["n_dot_h"], d["l_dot_v"], d["v_dot_h"]
    nov = np.maximum(d["n_dot_v"], 1e-4)
    s = (noh * a2 - noh) * noh + 1
    dist = a2 / (np.pi * s * s)
    vis = 0.5 / (nol * np.sqrt((-nov * a2 + nov) * nov + a2) + nov * np.sqrt((-nol * a2 + nol) * nol + a2))
    fd90 = 0.5 + perceptual * (1 + lov)
    disney = (1 + (fd90 - 1) * pow5(1 - nol)) * (1 + (fd90 - 1) * pow5(1 - nov)) / (1.03571 * np.pi)
    fc = pow5(1 - loh)
    return dist * vis, disney, fc


def hdrp(d, x):
    base, metallic, smoothness = x[0:3], x[3], x[4]
    spec_dv, disney, fc = hdrp_terms(d, smoothness)
    out = []
    for c in range(3):
        f0 = 0.04 + (base[c] - 0.04) * metallic
        out.append(base[c] * (1 - metallic) * disney + (f0 + (1 - f0) * fc) * spec_dv)
    return out


def urp_specular_term(d, smoothness):
    """URP Lit's specular lobe (its minimalist GGX, DirectBRDFSpecular) for a smoothness."""
    perceptual = 1 - smoothness
    roughness = max(perceptual * perceptual, 2.0 ** -7)
    r2 = max(roughness * roughness, 2.0 ** -14)
    noh, loh = d["n_dot_h"], d["v_dot_h"]
    dd = noh * noh * (r2 - 1) + 1.00001
    term = r2 / (dd * dd * np.maximum(0.1, loh * loh) * (4 * roughness + 2))
    return term


def urp(d, x):
    albedo, metallic, smoothness = x[0:3], x[3], x[4]
    term = urp_specular_term(d, smoothness)
    return [(albedo[c] * (0.96 - 0.96 * metallic) + term * (0.04 + (albedo[c] - 0.04) * metallic)) / np.pi
            for c in range(3)]


def hdrp_specular(d, x):
    """HDRP Lit, specular colour: fresnel0 = specularColor, diffuseColor = baseColor·(1 − max(specularColor))."""
    base, spec, smoothness = x[0:3], x[3:6], x[6]
    spec_dv, disney, fc = hdrp_terms(d, smoothness)
    keep = 1 - max(spec)
    return [base[c] * keep * disney + (spec[c] + (1 - spec[c]) * fc) * spec_dv for c in range(3)]


def urp_specular(d, x):
    """URP Lit, specular setup: diffuse = albedo·(1 − specular) per channel, specular = specular colour."""
    albedo, spec, smoothness = x[0:3], x[3:6], x[6]
    term = urp_specular_term(d, smoothness)
    return [(albedo[c] * (1 - spec[c]) + term * spec[c]) / np.pi for c in range(3)]


# Per-channel models: function, parameter names, bounds (the material file's ranges).
LEGACY = {"ggx": (ggx, ["kd", "f0", "alpha"], [(0, 1), (0, 1), (1e-3, 1)]),
          "lafortune": (lafortune, ["kd", "ks", "n"], [(0, 1), (0, 1), (1e-3, 1e6)]),
          "blinn-phong": (blinn_phong, ["kd", "ks", "n"], [(0, 1), (0, 1), (1e-3, 1e6)]),
          "ward": (ward, ["rho_d", "rho_s", "alpha"], [(0, 1), (0, 1), (1e-3, 1)])}
# Engine models: function of the whole value vector, parameter names (all in [0, 1]).
ENGINE = {"unreal-defaultlit": (unreal, ["base_color", "metallic", "specular", "roughness"]),
          "unity-hdrp-lit": (hdrp, ["base_color", "metallic", "smoothness"]),
          "unity-hdrp-lit-specular": (hdrp_specular, ["base_color", "specular_color", "smoothness"]),
          "unity-urp-lit": (urp, ["base_color", "metallic", "smoothness"]),
          "unity-urp-lit-specular": (urp_specular, ["base_color", "specular_color", "smoothness"])}


def as_rgb(v):
    return np.array(v if isinstance(v, list) else [v, v, v], dtype=float)


def vector_of(model, material):
    """The parameter vector of a material file's values in this script's order (legacy models:
    the first parameter's r, g, b, then the second's, then the shape's; engine models: base colour
    r, g, b (and the specular colour's), then the scalars)."""
    if model in LEGACY:
        return np.concatenate([as_rgb(material[n]) for n in LEGACY[model][1]])
    names = ENGINE[model][1]
    rgb = ("base_color", "specular_color")
    return np.concatenate([as_rgb(material[n]) if n in rgb else [float(material[n])] for n in names])


def problem(d, model, start, loss="ngan"):
    """(residuals(x), x0, lo, hi) of fitting `model` to the samples `d` from the material `start`
    under `loss`: ngan sqrt(w)·cosθin·(f − m), log sqrt(w)·(ln(1 + cosθin·f) − ln(1 + cosθin·m))."""
    c_in, sqrt_w = d["cos_in"], d["sqrt_w"]
    meas = [d["m_r"], d["m_g"], d["m_b"]]
    if loss == "ngan":
        def r(f, m):
            return sqrt_w * c_in * (f - m)
    elif loss == "log":
        def r(f, m):
            return sqrt_w * (np.log1p(c_in * f) - np.log1p(c_in * m))
    else:
        raise ValueError("loss " + loss)
    x0 = vector_of(model, start)
    if model in LEGACY:
        f, _, bounds = LEGACY[model]
        lo = np.concatenate([[b[0]] * 3 for b in bounds])
        hi = np.concatenate([[b[1]] * 3 for b in bounds])

        def residuals(x):
            return np.concatenate([r(f(d, x[c], x[3 + c], x[6 + c]), meas[c]) for c in range(3)])
    else:
        f = ENGINE[model][0]
        lo, hi = np.zeros(len(x0)), np.ones(len(x0))

        def residuals(x):
            fx = f(d, x)
            return np.concatenate([r(fx[c], meas[c]) for c in range(3)])
    return residuals, x0, lo, hi


def main():
    out_dir, model = sys.argv[1], sys.argv[2]
    repeats = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    d = load(out_dir)
    start = json.load(open(out_dir + "/start_" + model + ".json"))
    residuals, x0, lo, hi = problem(d, model, start)

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
