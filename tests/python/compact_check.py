#!/usr/bin/python3
"""The compact form (.brdfc) and --max-error against independent implementations.

--mode compact (default):
1. `brdf convert --compress compact` of library materials (noise-free captures on the reference
   geometry) and a plain float-EXR conversion of the same inputs (the uncompressed LUT).
2. A numpy reader and decoder of .brdfc written from docs/formats/compact.md (header, lists,
   half-float log2 grid, whole-degree maps, bilinear in log2, f = S * max(2^g - eps, 0)) decodes
   every texel centre; the certified error recorded in the embedded sidecar is recomputed from
   that decode and the EXR's float LUT (docs/design.md §7's definition), measured and filled
   range apart, and must agree to 1e-6 + 1e-4 of the value (float32 there, float64 here).
3. The size target: the payload at most 52 KB and at least 20x smaller than RGB9E5 for 4 slices,
   and the measured max at most 2 %.
4. `brdf eval` of the .brdfc at measured texel centres equals the numpy decode (1e-5 relative),
   and at random directions between texels agrees with the numpy decoder's continuous reading.
5. With --gpu: headless Chromium's WebGL 2 runs the engine kit's compact GLSL ES 3.00 decoder
   (tests/node/compact_gpu.mjs) at the same directions (l and v as float32 vectors); it must
   agree with `brdf eval` to 2e-5 of the texel's scale (float32 arithmetic; measured: 2e-6),
   and at the texel centres lie within the certified max of the full float LUT.

--mode max-error: `brdf convert --max-error E` for E = 2 % and 0.4 % of the library materials and a
noisy capture; for every input the file
written (.brdfc, or the KTX2 as RGB9E5 or BC6H per its sidecar) is read back by `brdf eval` at
every measured texel centre, and numpy computes the relative error against the float LUT: the
maximum must be at most E, and the representation reported on stdout must be the one written.

Usage: compact_check.py --brdf BRDF --work DIR [--mode compact|max-error]
       [--gpu NODE_SCRIPT --node NODE [--chromium PATH]]
"""

import argparse
import json
import math
import os
import shutil
import struct
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio

MATERIALS = ["gold", "diamond_on_black", "plastic_glossy_red", "wood_oak", "paper_white"]


def fail(message):
    print("FAILED: " + message)
    sys.exit(1)


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        fail(f"{' '.join(cmd)} exited {r.returncode}: {r.stderr.strip()}")
    return r


def read_lut(exr_path, sidecar_path):
    """The float LUT (K, 181, 361, 3) from the composite EXR (docs/design.md §5)."""
    with open(sidecar_path) as f:
        side = json.load(f)
    theta_in = side["theta_in_deg"]
    k_count = len(theta_in)
    cols = math.ceil(math.sqrt(k_count))
    inp = oiio.ImageInput.open(exr_path)
    px = inp.read_image(format="float")
    inp.close()
    lut = np.zeros((k_count, 181, 361, 3), np.float64)
    for k in range(k_count):
        r, c = divmod(k, cols)
        lut[k] = px[r * 181:(r + 1) * 181, c * 361:(c + 1) * 361, :3]
    theta_b = side["extrapolation"]["theta_b_deg"] if side["extrapolation"] else 90.0
    return np.array(theta_in), lut, theta_b


def read_brdfc(path):
    """The container of docs/formats/compact.md."""
    data = open(path, "rb").read()
    if data[:8] != b"BRDFCLUT":
        fail(f"{path}: magic {data[:8]!r}")
    version, k_count, flags = struct.unpack_from("<III", data, 8)
    scale, eps = struct.unpack_from("<ff", data, 20)
    crc, sidecar_len = struct.unpack_from("<II", data, 28)
    at = 36
    theta_in = list(struct.unpack_from(f"<{k_count}d", data, at))
    at += 8 * k_count
    sizes = [struct.unpack_from("<HH", data, at + 4 * k) for k in range(k_count)]
    at += 4 * k_count
    rows, cols, grids = [], [], []
    for nr, nc in sizes:
        rows.append(np.frombuffer(data, "<u2", nr, at).astype(np.float64))
        at += 2 * nr
        cols.append(np.frombuffer(data, "<u2", nc, at).astype(np.float64))
        at += 2 * nc
    for nr, nc in sizes:
        g = np.frombuffer(data, "<f2", nr * nc * 3, at).astype(np.float64).reshape(nr, nc, 3)
        grids.append(g)
        at += 2 * nr * nc * 3
    import zlib
    if zlib.crc32(data[36:at]) != crc:
        fail(f"{path}: payload CRC-32 does not match the header")
    sidecar = json.loads(data[at:at + sidecar_len].decode())
    if at + sidecar_len != len(data):
        fail(f"{path}: {len(data) - at - sidecar_len} bytes after the sidecar")
    return dict(theta_in=np.array(theta_in), mirrored=flags == 1, scale=np.float32(scale),
                eps=np.float32(eps), rows=rows, cols=cols, grids=grids, sidecar=sidecar,
                payload_bytes=at, version=version)


def grid_coordinate(kept, x):
    """m(x) = p + (x - a_p)/(a_{p+1} - a_p) on the gap [a_p, a_{p+1}] holding x."""
    p = np.clip(np.searchsorted(kept, x, side="right") - 1, 0, len(kept) - 2)
    return p + (x - kept[p]) / (kept[p + 1] - kept[p])


def decode_slice(c, k, theta_d, phi_d):
    """The slice's value at arrays theta_d, phi_d (degrees)."""
    phi = np.clip(phi_d, 0, 360)
    if c["mirrored"]:
        phi = np.where(phi > 180, 360 - phi, phi)
    mr = grid_coordinate(c["rows"][k], np.clip(theta_d, 0, 180))
    mc = grid_coordinate(c["cols"][k], phi)
    g = c["grids"][k]
    r0 = np.minimum(np.floor(mr).astype(int), g.shape[0] - 2)
    c0 = np.minimum(np.floor(mc).astype(int), g.shape[1] - 2)
    tr = (mr - r0)[..., None]
    tc = (mc - c0)[..., None]
    top = g[r0, c0] * (1 - tc) + g[r0, c0 + 1] * tc
    bottom = g[r0 + 1, c0] * (1 - tc) + g[r0 + 1, c0 + 1] * tc
    lg = top * (1 - tr) + bottom * tr
    return float(c["scale"]) * np.maximum(np.exp2(lg) - float(c["eps"]), 0.0)


def texel_theta_out(theta_in, theta_d, phi_d):
    ti, td, pd = np.radians(theta_in), np.radians(theta_d), np.radians(phi_d)
    cz = np.cos(ti) * np.cos(td) - np.sin(ti) * np.sin(td) * np.cos(pd)
    return np.degrees(np.arccos(np.clip(cz, -1, 1)))


def out_direction(theta_in, theta_d, phi_d):
    """ω_out = S(θin)·ω_d (S is its own inverse), as (θout, φout) in degrees."""
    ti, td, pd = np.radians(theta_in), np.radians(theta_d), np.radians(phi_d)
    wd = np.stack([np.sin(td) * np.cos(pd), np.sin(td) * np.sin(pd), np.cos(td)], -1)
    c, s = np.cos(ti), np.sin(ti)
    wo = np.stack([-c * wd[..., 0] - s * wd[..., 2], -wd[..., 1], -s * wd[..., 0] + c * wd[..., 2]],
                  -1)
    return np.degrees(np.arccos(np.clip(wo[..., 2], -1, 1))), np.degrees(
        np.arctan2(wo[..., 1], wo[..., 0])) % 360


def specular_coords(theta_in, theta_out, phi_out):
    """(θd, φd) of a view for a light at (θin, 0): ω_d = S(θin)·ω_out."""
    ti, to, po = np.radians(theta_in), np.radians(theta_out), np.radians(phi_out)
    wo = np.stack([np.sin(to) * np.cos(po), np.sin(to) * np.sin(po), np.cos(to)], -1)
    c, s = np.cos(ti), np.sin(ti)
    wd = np.stack([-c * wo[..., 0] - s * wo[..., 2], -wo[..., 1], -s * wo[..., 0] + c * wo[..., 2]],
                  -1)
    td = np.degrees(np.arctan2(np.hypot(wd[..., 0], wd[..., 1]), wd[..., 2]))
    pd = np.degrees(np.arctan2(wd[..., 1], wd[..., 0])) % 360
    return td, pd


def errors(decoded, reference, brightest):
    """docs/design.md §7: max_c |d − r| / max(max_c r, 1e-4·R, 2^-14), r clamped to [0, 65504]."""
    r = np.clip(reference, 0, 65504)
    scale = np.maximum(r.max(-1), max(1e-4 * brightest, 2.0 ** -14))
    return np.abs(decoded - r).max(-1) / scale


def nearest_rank(values, p):
    v = np.sort(values)
    return v[max(min(int(math.ceil(p * len(v))), len(v)), 1) - 1]


def measured_texels(theta_in, theta_b):
    """(k, j, i) of every texel with θout ≤ θb, as arrays."""
    jj, ii = np.meshgrid(np.arange(181), np.arange(361), indexing="ij")
    out = []
    for k, t in enumerate(theta_in):
        m = texel_theta_out(t, jj, ii) <= theta_b + 1e-9
        out.append((np.full(m.sum(), k), jj[m], ii[m]))
    return [np.concatenate(a) for a in zip(*out)]


def brdf_eval(brdf, path, theta_in, theta_out, phi_out, work):
    pairs = os.path.join(work, "pairs.txt")
    with open(pairs, "w") as f:
        for a, b, c in zip(theta_in, theta_out, phi_out):
            f.write(f"{a:.12f} 0 {b:.12f} {c:.12f}\n")
    r = run([brdf, "eval", path, "--pairs", pairs])
    return np.array([[float(x) for x in line.split()] for line in r.stdout.splitlines()])


def check_compact(args):
    work = args.work
    src, ref = os.path.join(work, "compact"), os.path.join(work, "reference")
    run([args.brdf, "convert", *MATERIALS, "--out", src, "--compress", "compact", "--formats",
         "ktx2,json", "--force", "--quiet"])
    run([args.brdf, "convert", *MATERIALS, "--out", ref, "--formats", "ktx2,exr,json",
         "--exr-type", "float", "--engine", "web", "--force", "--quiet"])
    rng = np.random.default_rng(21)
    for name in MATERIALS:
        theta_in, lut, theta_b = read_lut(os.path.join(ref, name + ".exr"),
                                          os.path.join(ref, name + ".json"))
        c = read_brdfc(os.path.join(src, name + ".brdfc"))
        if not np.array_equal(c["theta_in"], theta_in):
            fail(f"{name}: θin list {c['theta_in']} differs from the LUT's {theta_in}")
        brightest = np.clip(lut, 0, 65504).max()
        jj, ii = np.meshgrid(np.arange(181.0), np.arange(361.0), indexing="ij")
        decoded = np.stack([decode_slice(c, k, jj, ii) for k in range(len(theta_in))])
        e = errors(decoded, lut, brightest)
        tout = np.stack([texel_theta_out(t, jj, ii) for t in theta_in])
        measured = tout <= theta_b + 1e-9
        cert = c["sidecar"]["compression"]
        for rng_name, mask in (("measured", measured), ("filled", ~measured)):
            got = cert["certified_error"][rng_name]
            mine = {"max": e[mask].max(), "p99": nearest_rank(e[mask], 0.99),
                    "median": nearest_rank(e[mask], 0.5), "texels": int(mask.sum())}
            for key, value in mine.items():
                # The library decodes in float32, numpy in float64.
                if abs(got[key] - value) > 1e-6 + 1e-4 * abs(value):
                    fail(f"{name}: certified {rng_name} {key} {got[key]} but numpy finds {value}")
        rgb9e5 = len(theta_in) * 181 * 361 * 4
        payload = c["sidecar"]["payload"]["bytes"]
        if payload != c["payload_bytes"] or cert["bytes"] != payload:
            fail(f"{name}: payload bytes {payload} / {cert['bytes']}, container {c['payload_bytes']}")
        if e[measured].max() > 0.02:
            fail(f"{name}: measured max error {e[measured].max():.4f} above 2 %")
        if len(theta_in) == 4 and not (payload <= 52000 and rgb9e5 / payload >= 20):
            fail(f"{name}: {payload} bytes, {rgb9e5 / payload:.1f}x smaller than RGB9E5")
        print(f"{name}: {len(theta_in)} slices, {payload} bytes ({rgb9e5 / payload:.1f}x), "
              f"measured max {100 * e[measured].max():.2f} %, p99 "
              f"{100 * nearest_rank(e[measured], 0.99):.2f} %, certified figures recomputed")

        # brdf eval at measured texel centres and at random directions between texels.
        ks, js, is_ = measured_texels(theta_in, theta_b)
        pick = rng.choice(len(ks), 1500, replace=False)
        ks, js, is_ = ks[pick], js[pick], is_[pick]
        t_in = theta_in[ks]
        t_out, p_out = out_direction(t_in, js.astype(float), is_.astype(float))
        n_rand = 700
        r_in = rng.uniform(0, theta_in[-1], n_rand)
        r_out = rng.uniform(0, 89, n_rand)
        r_phi = rng.uniform(0, 360, n_rand)
        all_in = np.concatenate([t_in, r_in])
        all_out = np.concatenate([t_out, r_out])
        all_phi = np.concatenate([p_out, r_phi])
        ev = brdf_eval(args.brdf, os.path.join(src, name + ".brdfc"), all_in, all_out, all_phi,
                       work)
        # The sidecar stands for its .brdfc: the same values.
        via_sidecar = brdf_eval(args.brdf, os.path.join(src, name + ".json"), all_in[:50],
                                all_out[:50], all_phi[:50], work)
        if not np.array_equal(via_sidecar, ev[:50]):
            fail(f"{name}: brdf eval of the sidecar differs from eval of the .brdfc")
        centre = decoded[ks, js, is_]
        scale_c = np.maximum(np.clip(lut[ks, js, is_], 0, 65504).max(-1), 1e-4 * brightest)
        d = np.abs(ev[:1500] - centre).max(-1) / scale_c
        if d.max() > 1e-5:
            fail(f"{name}: brdf eval differs from the numpy decode at texel centres by {d.max():.2e}")
        # Between texels: slice interpolation of the continuous reading (no exchange: θin
        # inside the slices' range).
        delta = theta_in[1] - theta_in[0]
        x = r_in / delta
        k0 = np.clip(np.floor(x).astype(int), 0, len(theta_in) - 1)
        k1 = np.clip(k0 + 1, 0, len(theta_in) - 1)
        t = (x - np.floor(x))[:, None]
        td, pd = specular_coords(r_in, r_out, r_phi)
        a = np.stack([decode_slice(c, k, td[i], pd[i]) for i, k in enumerate(k0)])
        b = np.stack([decode_slice(c, k, td[i], pd[i]) for i, k in enumerate(k1)])
        cont = a * (1 - t) + b * t
        scale_r = np.maximum(cont.max(-1), 1e-4 * brightest)
        d = np.abs(ev[1500:] - cont).max(-1) / scale_r
        if d.max() > 1e-4:
            fail(f"{name}: brdf eval between texels differs from numpy by {d.max():.2e}")

        if args.gpu:
            pairs = os.path.join(work, name + ".pairs.f32")
            ti, to, po = np.radians(all_in), np.radians(all_out), np.radians(all_phi)
            lv = np.stack([np.sin(ti), 0 * ti, np.cos(ti), np.sin(to) * np.cos(po),
                           np.sin(to) * np.sin(po), np.cos(to)], -1)
            lv.astype("<f4").tofile(pairs)
            glsl = [f for f in os.listdir(os.path.join(ref, "web"))
                    if f.endswith(".compact.es300.glsl")]
            if len(glsl) != 1:
                fail(f"expected one *.compact.es300.glsl in the web kit, found {glsl}")
            out = os.path.join(work, name + ".gpu.f32")
            cmd = [args.node, args.gpu, "--brdfc", os.path.join(src, name + ".brdfc"), "--glsl",
                   os.path.join(ref, "web", glsl[0]), "--pairs", pairs, "--out", out]
            if args.chromium:
                cmd += ["--chromium", args.chromium]
            print(run(cmd).stdout.strip())
            gpu = np.fromfile(out, "<f4").reshape(-1, 3).astype(np.float64)
            ev32 = ev  # the same directions, in double precision
            scale_g = np.maximum(ev32.max(-1), 1e-4 * brightest)
            d = np.abs(gpu - ev32).max(-1) / scale_g
            worst = int(np.argmax(d))
            if d.max() > 2e-5:
                fail(f"{name}: GPU differs from brdf eval by {d.max():.2e} at pair {worst} "
                     f"{all_in[worst], all_out[worst], all_phi[worst]}: GPU {gpu[worst]}, eval "
                     f"{ev32[worst]}")
            # Against the full float LUT at the measured texel centres: within the certified bound.
            eg = errors(gpu[:1500], lut[ks, js, is_], brightest)
            if eg.max() > cert["certified_error"]["measured"]["max"] + 2e-5:
                fail(f"{name}: GPU reads {eg.max():.4f} off the full LUT at a measured texel, above "
                     f"the certified {cert['certified_error']['measured']['max']:.4f}")
            print(f"{name}: GPU decoder agrees with brdf eval at {len(gpu)} directions "
                  f"(largest difference {d.max():.1e} of the texel's scale); against the full LUT "
                  f"at 1500 measured texel centres max {100 * eg.max():.2f} %")


def check_max_error(args):
    work = args.work
    ref = os.path.join(work, "reference")
    # The library materials noise-free, and one capture with the reference instrument's noise
    # (which no smooth form carries texel by texel).
    noisy = os.path.join(work, "noisy_paper.bpc")
    run([args.brdf, "capture", "--device", "sim", "--material", "paper_white", "--sample",
         "noisy_paper", "--out", noisy, "--quiet", "--force"])
    inputs, names = MATERIALS + [noisy], MATERIALS + ["noisy_paper"]
    run([args.brdf, "convert", *inputs, "--out", ref, "--formats", "exr,json", "--exr-type",
         "float", "--force", "--quiet"])
    seen = set()
    for bound in (0.02, 0.004):
        out = os.path.join(work, f"max{bound}")
        r = run([args.brdf, "convert", *inputs, "--out", out, "--max-error", str(bound),
                 "--formats", "ktx2,json", "--force", "--quiet"])
        lines = {ln.split(":")[0]: ln for ln in (r.stdout + r.stderr).splitlines() if ": " in ln}
        for name in names:
            theta_in, lut, theta_b = read_lut(os.path.join(ref, name + ".exr"),
                                              os.path.join(ref, name + ".json"))
            compact = os.path.join(out, name + ".brdfc")
            ktx2 = os.path.join(out, name + ".ktx2")
            if os.path.exists(compact) == os.path.exists(ktx2):
                fail(f"{name}: expected exactly one of {compact}, {ktx2}")
            chosen = compact if os.path.exists(compact) else ktx2
            with open(os.path.join(out, name + ".json")) as f:
                side = json.load(f)
            fmt = side["payload"].get("format", "rgb9e5")
            comp = side["compression"]
            if comp.get("max_error_bound") != bound or comp.get("max_error_met") is not True:
                fail(f"{name}: sidecar records bound {comp.get('max_error_bound')}, met "
                     f"{comp.get('max_error_met')}, for --max-error {bound}")
            word = {"compact_log_grid": "compact", "bc6h_ufloat": "BC6H", "rgb9e5": "RGB9E5"}[fmt]
            if name not in lines or f"{name}: {word} " not in lines[name]:
                fail(f"{name}: stdout line {lines.get(name)!r} does not name {word}")
            ks, js, is_ = measured_texels(theta_in, theta_b)
            t_out, p_out = out_direction(theta_in[ks], js.astype(float), is_.astype(float))
            ev = brdf_eval(args.brdf, chosen, theta_in[ks], t_out, p_out, work)
            brightest = np.clip(lut, 0, 65504).max()
            e = errors(ev, lut[ks, js, is_], brightest)
            if e.max() > bound:
                fail(f"{name}: --max-error {bound}: {word} file reads back {e.max():.4f} at "
                     f"texel {ks[np.argmax(e)], js[np.argmax(e)], is_[np.argmax(e)]}")
            seen.add(word)
            print(f"{name}: --max-error {100 * bound:g} %: {word}, max {100 * e.max():.3f} % over "
                  f"{len(e)} measured texels (brdf eval of {os.path.basename(chosen)})")
    if len(seen) < 2:
        fail(f"the bounds chose only {seen}: the test does not exercise the choice")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--brdf", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--mode", default="compact", choices=["compact", "max-error"])
    ap.add_argument("--gpu")
    ap.add_argument("--node")
    ap.add_argument("--chromium")
    args = ap.parse_args()
    shutil.rmtree(args.work, ignore_errors=True)
    os.makedirs(args.work)
    if args.mode == "compact":
        check_compact(args)
    else:
        check_max_error(args)
    print("PASSED")


if __name__ == "__main__":
    main()
