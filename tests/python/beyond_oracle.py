#!/usr/bin/python3
"""The blind-spot fill (brdf/processing/beyond.h) against NumPy, through the built tool only.

usage: beyond_oracle.py BRDF_TOOL MATERIALS_DIR

Noise-free 4-slice captures (`brdf capture --device sim --noise 0`, θin 0/20/40/60, θout ≤ 75°)
of analytic materials, evaluated with `brdf eval CAPTURE --pairs --beyond auto`, checked
against values written here from the formulas of docs/design.md §9:
  1. filled values at θin 70/80°, θout 80/85° within 2 % of the formula (gold, a GGX α 0.2
     metal, Lafortune wood_oak, Ward wood_walnut);
  2. continuity where the light crosses the last measured slice (60°) and where the view
     crosses θb (75°); the step where the light crosses the LUT's last slice (80°, where the
     reciprocity exchange starts) is printed, not checked: it is the LUT's θin interpolation
     error (docs/design.md §5), not a seam of the fill;
  3. reciprocity of the filled region (light and view both in [62°, 88°]);
  4. directional albedo ≤ 1 (NumPy quadrature of `brdf eval`) at θin 70, 80, 85° for silver
     (f0 0.99) and the white reference;
  5. measured texels unchanged bit for bit: the KTX2 of `convert --beyond clamp` and of the
     default, RGB9E5 words of every texel with θout ≤ θb of every measured slice;
  6. the leave-last-slice-out figure the sidecar records, recomputed from `brdf eval` of a
     3-slice capture (θin 0/20/40) and of the 4-slice one at the 60° slice's texel directions,
     and the same figure in `brdf info --json` of the capture and in `brdf convert`'s line;
  7. `brdf info --json`'s physical sanity report of a noisy capture (the simulator's default
     detector noise) against NumPy: per LUT slice the directional albedo, measured part
     (θout ≤ θb) and filled part, by a 0.75° × 1.5° midpoint quadrature of `brdf eval`; the
     reciprocity residual over the pairs measured both ways, f(a → b, Δφ) against
     f(b → a, Δφ); the saturated and below-noise counts from the file itself
     (tests/python/bpc_reader.py, written from docs/formats/bpc.md).
Exit status 1 with the failing checks listed.
"""
import json
import math
import os
import re
import struct
import subprocess
import sys
import tempfile

import numpy as np

DEG = math.pi / 180.0
FAILURES = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        FAILURES.append(what)


def sph(theta_deg, phi_deg):
    t, p = np.asarray(theta_deg) * DEG, np.asarray(phi_deg) * DEG
    return np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)


def formula(mat, ti, pi_, to, po):
    """docs/design.md §9 f_r, light (ti, pi_), view (to, po), degrees, arrays -> (n, 3)."""
    rgb = lambda x: np.broadcast_to(np.asarray(x, float), (3,))  # noqa: E731
    l, v = sph(ti, pi_), sph(to, po)
    h = l + v
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    cl, cv, ch = l[:, 2:3], v[:, 2:3], h[:, 2:3]
    m = mat["model"]
    if m == "lambert":
        return np.broadcast_to(rgb(mat["rho"]) / math.pi, (len(l), 3))
    if m == "ggx":
        a2 = float(mat["alpha"]) ** 2
        tan2h = (1 - ch ** 2) / ch ** 2
        d = a2 / (math.pi * ch ** 4 * (a2 + tan2h) ** 2)
        g1 = lambda c: 2 / (1 + np.sqrt(1 + a2 * (1 - c ** 2) / c ** 2))  # noqa: E731
        vh = np.sum(v * h, -1, keepdims=True)
        f = rgb(mat["f0"]) + (1 - rgb(mat["f0"])) * (1 - vh) ** 5
        return rgb(mat["kd"]) / math.pi + f * g1(cl) * g1(cv) * d / (4 * cl * cv)
    if m == "lafortune":
        r = l * np.array([-1.0, -1.0, 1.0])
        vr = np.clip(np.sum(v * r, -1, keepdims=True), 0, None)
        n = float(mat["n"])
        return rgb(mat["kd"]) / math.pi + rgb(mat["ks"]) * (n + 2) / (2 * math.pi) * vr ** n
    if m == "ward":
        a2 = float(mat["alpha"]) ** 2
        tan2h = (1 - ch ** 2) / ch ** 2
        return (rgb(mat["rho_d"]) / math.pi +
                rgb(mat["rho_s"]) * np.exp(-tan2h / a2) / (4 * math.pi * a2 * np.sqrt(cl * cv)))
    raise SystemExit("no formula for " + m)


class Tool:
    def __init__(self, exe, tmp):
        self.exe, self.tmp = exe, tmp

    def run(self, *args):
        r = subprocess.run([self.exe] + list(args), capture_output=True, text=True)
        if r.returncode != 0:
            raise SystemExit("brdf %s failed:\n%s%s" % (" ".join(args), r.stdout, r.stderr))
        return r.stdout

    def capture(self, material, name, theta_in="0,20,40,60"):
        out = os.path.join(self.tmp, name + ".bpc")
        self.run("capture", "--device", "sim", "--material", material, "--noise", "0",
                 "--sample", name, "--theta-in", theta_in, "--out", out, "--quiet", "--force")
        return out

    def eval(self, source, pairs, *extra):
        path = os.path.join(self.tmp, "pairs.txt")
        np.savetxt(path, pairs, fmt="%.9f")
        out = self.run("eval", source, "--pairs", path, *(extra or ("--beyond", "auto")))
        return np.loadtxt(out.splitlines()).reshape(-1, 3)


def ktx2_words(path):
    """RGB9E5 words of a KTX2 file's single level (header fields of the KTX2 specification)."""
    data = open(path, "rb").read()
    if data[:12] != b"\xabKTX 20\xbb\r\n\x1a\n":
        raise SystemExit(path + ": not a KTX2 file")
    w, h, d = struct.unpack_from("<3I", data, 20)
    offset, length = struct.unpack_from("<QQ", data, 80)
    return np.frombuffer(data, "<u4", length // 4, offset).reshape(d, h, w)


def slice_views(theta_in):
    """θout of every texel of the slice at θin (docs/design.md §5: ω_out = S(θin)·ω_d)."""
    j, i = np.meshgrid(np.arange(181.0), np.arange(361.0), indexing="ij")
    wd = sph(j, i)
    c, s = math.cos(theta_in * DEG), math.sin(theta_in * DEG)
    wo = np.stack([-c * wd[..., 0] - s * wd[..., 2], -wd[..., 1], -s * wd[..., 0] + c * wd[..., 2]],
                  -1)
    return np.degrees(np.arccos(np.clip(wo[..., 2], -1, 1))), \
        np.degrees(np.arctan2(wo[..., 1], wo[..., 0])) % 360.0


def main(argv):
    exe, materials = argv[1], argv[2]
    with tempfile.TemporaryDirectory(prefix="beyond_oracle_") as tmp:
        tool = Tool(exe, tmp)
        mats = {n: json.load(open(os.path.join(materials, n + ".json")))
                for n in ("gold", "wood_oak", "wood_walnut", "silver", "white_reference")}
        mats["metal_a02"] = {"model": "ggx", "kd": 0.0, "f0": [0.9, 0.6, 0.3], "alpha": 0.2}
        paths = {}
        for n, m in mats.items():
            p = os.path.join(tmp, n + ".json")
            json.dump(m, open(p, "w"))
            paths[n] = tool.capture(p, n)

        # 1. Filled values against the formulas.
        pts = np.array([[ti, 0, to, po] for ti in (70, 80) for to in (80, 85)
                        for po in (180, 150, 90, 0)], float)
        for n in ("gold", "metal_a02", "wood_oak", "wood_walnut"):
            got = tool.eval(paths[n], pts)
            want = formula(mats[n], pts[:, 0], pts[:, 1], pts[:, 2], pts[:, 3])
            rel = np.abs(got - want) / np.maximum(want, 1e-3 * want.max())
            worst = int(np.argmax(rel.max(1)))
            check(rel.max() <= 0.02, "%s: filled values at θin 70/80°, θout 80/85° within 2 %% of "
                  "the formula (worst %.2f %% at %s)" % (n, 100 * rel.max(), pts[worst]))

        # 2. Continuity across the boundaries.
        rng = np.random.default_rng(3)
        for n in ("gold", "wood_walnut"):
            for label, a, b in (
                    ("light crossing the last measured slice (60°)", [59.999, 0, None, None],
                     [60.001, 0, None, None]),
                    ("view crossing θb (75°)", [None, 0, 74.999, None], [None, 0, 75.001, None]),
                    ("light crossing the LUT's last slice (80°)", [79.999, 0, None, None],
                     [80.001, 0, None, None])):
                informative = "80°" in label
                k = 200
                base = np.stack([rng.uniform(0, 60, k), np.zeros(k), rng.uniform(62, 88, k),
                                 rng.uniform(0, 360, k)], 1)
                if a[0] is not None:
                    base[:, 2] = rng.uniform(20, 88, k)
                pa, pb = base.copy(), base.copy()
                for col in (0, 2):
                    if a[col] is not None:
                        pa[:, col], pb[:, col] = a[col], b[col]
                fa, fb = tool.eval(paths[n], pa), tool.eval(paths[n], pb)
                step = np.abs(fa - fb).max(1) / np.maximum(np.abs(fa).max(1), 1e-6)
                what = "%s: no step where the %s (largest %.3f %%)" % (n, label, 100 * step.max())
                if informative:
                    print("info  " + what.replace("no step", "step"))
                else:
                    check(step.max() <= 0.002, what)

        # 3. Reciprocity of the filled region.
        for n in ("gold", "metal_a02", "wood_walnut"):
            k = 400
            a, b = rng.uniform(62, 88, k), rng.uniform(62, 88, k)
            phi = rng.uniform(0, 360, k)
            f1 = tool.eval(paths[n], np.stack([a, np.zeros(k), b, phi], 1))
            f2 = tool.eval(paths[n], np.stack([b, np.zeros(k), a, -phi % 360], 1))
            rel = np.abs(f1 - f2).sum(1) / np.maximum(f2.sum(1), 1e-3 * f2.sum(1).max())
            check(np.median(rel) <= 0.01 and np.percentile(rel, 95) <= 0.05,
                  "%s: f(a→b) = f(b→a) in the filled region (median %.2f %%, p95 %.2f %%)" % (
                      n, 100 * np.median(rel), 100 * np.percentile(rel, 95)))

        # 4. Directional albedo.
        nt, nphi = 90, 180
        tt = (np.arange(nt) + 0.5) * 90.0 / nt
        pp = (np.arange(nphi) + 0.5) * 360.0 / nphi
        T, P = np.meshgrid(tt, pp, indexing="ij")
        dw = np.sin(T * DEG) * (90.0 / nt * DEG) * (360.0 / nphi * DEG)
        for n in ("silver", "white_reference", "gold"):
            for ti in (70.0, 80.0, 85.0):
                pairs = np.stack([np.full(T.size, ti), np.zeros(T.size), T.ravel(), P.ravel()], 1)
                f = tool.eval(paths[n], pairs).reshape(nt, nphi, 3)
                albedo = (f * (np.cos(T * DEG) * dw)[..., None]).sum((0, 1))
                check(albedo.max() <= 1.01, "%s: albedo at θin %g° ≤ 1 (%s)" % (
                    n, ti, np.round(albedo, 4).tolist()))

        # 5. Measured texels unchanged.
        for n in ("gold", "wood_oak"):
            d_clamp, d_fill = os.path.join(tmp, "clamp"), os.path.join(tmp, "fill")
            tool.run("convert", paths[n], "--out", d_clamp, "--formats", "ktx2,json", "--quiet",
                     "--force", "--beyond", "clamp")
            tool.run("convert", paths[n], "--out", d_fill, "--formats", "ktx2,json", "--quiet",
                     "--force", "--beyond", "auto")
            wc = ktx2_words(os.path.join(d_clamp, n + ".ktx2"))
            wf = ktx2_words(os.path.join(d_fill, n + ".ktx2"))
            side = json.load(open(os.path.join(d_fill, n + ".json")))
            thetas = side["theta_in_deg"]
            same = True
            for k, t in enumerate((0.0, 20.0, 40.0, 60.0)):
                to, _ = slice_views(t)
                m = to <= 75.0
                same &= bool(np.array_equal(wc[k][m], wf[thetas.index(t)][m]))
            check(same and len(thetas) > 4,
                  "%s: every measured texel (θout ≤ 75° of the 4 measured slices) has the same "
                  "RGB9E5 word with the fill as without (θin %s)" % (n, thetas))

        # 6. Leave-last-slice-out, recomputed.
        for n in ("gold", "metal_a02", "wood_walnut"):
            three = tool.capture(os.path.join(tmp, n + ".json"), n + "_3", "0,20,40")
            out = os.path.join(tmp, "loo")
            tool.run("convert", paths[n], "--out", out, "--formats", "json", "--quiet", "--force",
                     "--beyond", "auto")
            rec = json.load(open(os.path.join(out, n + ".json")))["beyond"]
            method = rec["method"]
            to, po = slice_views(60.0)
            m = (to <= 75.0)
            m[:, 360] = False
            pairs = np.stack([np.full(m.sum(), 60.0), np.zeros(m.sum()), to[m], po[m]], 1)
            got = tool.eval(three, pairs, "--beyond", method).sum(1)
            want = tool.eval(paths[n], pairs, "--beyond", "clamp").sum(1)
            e = np.abs(got - want) / np.maximum(want, 1e-3 * want.max())
            med, p90 = float(np.median(e)), float(np.percentile(e, 90))
            r = rec["leave_last_slice_out"]
            close = lambda x, y: abs(x - y) <= 0.02 * y + 2e-4  # noqa: E731
            check(close(med, r["median_relative_error"]) and close(p90, r["p90_relative_error"]),
                  "%s: leave-last-slice-out (%s) from brdf eval: median %.4f p90 %.4f; sidecar "
                  "%.4f %.4f" % (n, method, med, p90, r["median_relative_error"],
                                 r["p90_relative_error"]))
            info = json.loads(tool.run("info", "--json", paths[n]))["blind_spot_fill"]
            i = info["leave_last_slice_out"]
            check(info["method"] == method and close(med, i["median_relative_error"])
                  and close(p90, i["p90_relative_error"]),
                  "%s: brdf info --json reports the same leave-last-slice-out figure (%s %.4f "
                  "%.4f)" % (n, info["method"], i["median_relative_error"],
                             i["p90_relative_error"]))
            conv = subprocess.run([exe, "convert", paths[n], "--out", out, "--formats", "json",
                                   "--force"], capture_output=True, text=True)
            line = [x for x in conv.stderr.splitlines() if "predicted from the others" in x]
            nums = re.findall(r"within ([0-9.e+-]+) % \(median\), ([0-9.e+-]+) % \(p90\)",
                              line[0] if line else "")
            check(len(line) == 1 and "θin 60°" in line[0] and len(nums) == 1 and
                  close(med, float(nums[0][0]) / 100) and close(p90, float(nums[0][1]) / 100),
                  "%s: brdf convert prints one leave-last-slice-out line (%s; NumPy: median "
                  "%.4f %%, p90 %.4f %%)" % (n, line, 100 * med, 100 * p90))

        # 7. The physical sanity report of a noisy capture.
        sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
        import bpc_reader  # noqa: E402
        noisy = os.path.join(tmp, "gold_noisy.bpc")
        tool.run("capture", "--device", "sim", "--material", os.path.join(tmp, "gold.json"),
                 "--sample", "gold noisy", "--seed", "5", "--out", noisy, "--quiet", "--force")
        rep = json.loads(tool.run("info", "--json", noisy))["physical_sanity"]
        theta_b = rep["theta_b_deg"]
        measured = [0.0, 20.0, 40.0, 60.0]
        nt, nphi = 120, 240
        tt = (np.arange(nt) + 0.5) * 90.0 / nt
        pp = (np.arange(nphi) + 0.5) * 360.0 / nphi
        T, P = np.meshgrid(tt, pp, indexing="ij")
        w = np.cos(T * DEG) * np.sin(T * DEG) * (90.0 / nt * DEG) * (360.0 / nphi * DEG)
        cap = bpc_reader.read_bpc(noisy)
        flags = {round(s["theta_in_deg"], 6): s["records"]["flags"] for s in cap["slices"]}
        check([s["theta_in"] for s in rep["slices"]] == [10.0 * k for k in range(9)],
              "gold (noisy): the report covers the LUT's slices θin 0, 10, …, 80°")
        for s in rep["slices"]:
            ti = s["theta_in"]
            pairs = np.stack([np.full(T.size, ti), np.zeros(T.size), T.ravel(), P.ravel()], 1)
            f = tool.eval(noisy, pairs).reshape(nt, nphi, 3)
            is_measured = ti in measured
            inside = (T <= theta_b) if is_measured else np.zeros_like(T, bool)
            a_meas = (f * (w * inside)[..., None]).sum((0, 1))
            a_fill = (f * (w * ~inside)[..., None]).sum((0, 1))
            got_m, got_f = np.array(s["albedo_measured"]), np.array(s["albedo_filled"])
            ok = (np.abs(got_m - a_meas) <= 0.01 * a_meas + 1e-4).all() and \
                (np.abs(got_f - a_fill) <= 0.01 * a_fill + 1e-4).all()
            check(ok and s["measured"] == is_measured,
                  "gold (noisy) θin %g°: albedo measured part %s + filled part %s; NumPy %s + %s"
                  % (ti, np.round(got_m, 4).tolist(), np.round(got_f, 4).tolist(),
                     np.round(a_meas, 4).tolist(), np.round(a_fill, 4).tolist()))
            if not is_measured:
                check(s["reciprocity"] is None, "gold (noisy) θin %g°: no reciprocity pairs in a "
                      "filled slice" % ti)
                continue
            phi = np.arange(0.0, 360.0, 5.0)
            res = []
            for b in measured:
                if b == ti or b > theta_b:
                    continue
                k = phi.size
                f1 = tool.eval(noisy, np.stack([np.full(k, ti), np.zeros(k), np.full(k, b), phi],
                                               1)).sum(1)
                f2 = tool.eval(noisy, np.stack([np.full(k, b), np.zeros(k), np.full(k, ti), phi],
                                               1)).sum(1)
                res.extend((np.abs(f1 - f2) / (0.5 * (f1 + f2))).tolist())
            res = np.sort(np.array(res))
            r = s["reciprocity"]
            check(r["pairs"] == res.size and abs(r["median_relative"] - res[res.size // 2]) <=
                  1e-4 + 1e-3 * res[res.size // 2] and abs(r["max_relative"] - res[-1]) <=
                  1e-4 + 1e-3 * res[-1] and res[-1] > 0,
                  "gold (noisy) θin %g°: reciprocity residual median %.4f max %.4f over %d pairs;"
                  " NumPy %.4f %.4f over %d" % (ti, r["median_relative"], r["max_relative"],
                                                r["pairs"], res[res.size // 2], res[-1], res.size))
            fl = flags[round(ti, 6)]
            sat, low = int(((fl & 1) != 0).sum()), int(((fl & 2) != 0).sum())
            check(s["saturated"] == sat and s["below_noise_floor"] == low,
                  "gold (noisy) θin %g°: saturated %d, below noise %d; the file: %d, %d" % (
                      ti, s["saturated"], s["below_noise_floor"], sat, low))
            total = a_meas + a_fill  # NumPy's
            check(s["energy_flag"] == bool((total > 1 + s["energy_margin"]).any()),
                  "gold (noisy) θin %g°: energy flag %s for albedo %s" % (
                      ti, s["energy_flag"], np.round(total, 4).tolist()))
    if FAILURES:
        print("%d check(s) failed" % len(FAILURES))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
