"""Independent checks of what Chromium computed with the exported web hand-off
(tests/node/render_web.mjs), written from the formulas in docs/design.md, not from the code
under test. Run with Debian's /usr/bin/python3 (numpy).

  image   The sphere image against a CPU reference computed here from the analytic GGX
          material the capture was simulated from (docs/design.md §9): numpy builds its own LUT
          by evaluating the material at every texel centre (§5: specular frame S(θin),
          θd = j°, φd = i°; θout beyond the measured 75° clamped to 75°, which is the §6
          extrapolation with p = 1), then samples it per pixel exactly as §5 prescribes
          (tangent frame from the light, centre-exact coordinates, trilinear, clamp-to-edge)
          on the exact ray-traced sphere. What remains is RGB9E5 rounding, the GPU's filtering
          precision and the capture-to-LUT resampling of a 1° capture.
  probes  Every manifest probe equals the RGB9E5 word of the KTX2 file at that index, decoded
          here from EXT_texture_shared_exponent, and what the GPU's texelFetch returned.
  pairs   Every shipped shader the browser ran (--langs: the GLSL of the three.js module as
          MeasuredBrdfCell and as MeasuredBrdfTangent, the sidecar's texel_convention.glsl,
          the GLSL 4.50 file, the Unity and Unreal HLSL and the Godot shader, the last four
          cross-compiled or translated to GLSL ES) against `brdf eval` of the same LUT for the
          same direction pairs: random ones (gen-pairs) and exact ones (gen-exact: views
          exactly along the normal, at the horizon and in the mirror direction, lights exactly
          along the normal), where a shader's angle math meets a pole.

Usage: web_render_check.py gen-pairs COUNT SEED ANGLES_OUT NLV_OUT
       web_render_check.py gen-exact ANGLES_OUT NLV_OUT
       web_render_check.py check [--material M.json] --result DIR --ktx2 F.ktx2
                                  --manifest F.manifest.json [--langs L1,L2,...]
                                  [--eval EVAL_OUT --angles ANGLES]
                                  [--exact-eval EVAL_OUT --exact-angles ANGLES]
Prints one line per check with the figures; exits 1 when a check fails.
"""
import json
import math
import os
import struct
import sys

import numpy as np

DEG = math.pi / 180.0


def spherical(theta, phi):
    s = np.sin(theta)
    return np.stack([s * np.cos(phi), s * np.sin(phi), np.cos(theta)], axis=-1)


def ggx(mat, wi, wo):
    """docs/design.md §9 ggx: kd/pi + F G D / (4 (n.l)(n.v)); wi, wo (..., 3) unit, z = n."""
    kd = np.asarray(mat["kd"], float)
    f0 = np.asarray(mat["f0"], float)
    a2 = float(mat["alpha"]) ** 2
    ci = np.clip(wi[..., 2], 1e-9, 1.0)
    co = np.clip(wo[..., 2], 1e-9, 1.0)
    h = wi + wo
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    ch = np.clip(h[..., 2], 1e-9, 1.0)
    tan2h = (1.0 - ch * ch) / (ch * ch)
    d = a2 / (math.pi * ch ** 4 * (a2 + tan2h) ** 2)

    def g1(c):
        tan2 = (1.0 - c * c) / (c * c)
        return 2.0 / (1.0 + np.sqrt(1.0 + a2 * tan2))

    g = g1(ci) * g1(co)
    vh = np.clip(np.sum(wo * h, axis=-1), 0.0, 1.0)
    f = f0 + (1.0 - f0) * ((1.0 - vh) ** 5)[..., None]
    spec = f * (g * d / (4.0 * ci * co))[..., None]
    return kd / math.pi + spec


def material_f(mat, wi, wo):
    """f_r of the docs/design.md §9 material (the models these tests render)."""
    if mat["model"] == "ggx":
        return ggx(mat, wi, wo)
    if mat["model"] == "lambert":
        return np.broadcast_to(np.asarray(mat["rho"], float) / math.pi, wi.shape).copy()
    raise ValueError("web_render_check: no oracle for model " + mat["model"])


def specular_matrix(theta_in):
    c, s = math.cos(theta_in), math.sin(theta_in)
    return np.array([[-c, 0.0, -s], [0.0, -1.0, 0.0], [-s, 0.0, c]])


def numpy_lut(mat, theta_in_deg, theta_b_deg=75.0):
    """(K, 181, 361, 3) texel-centre values of the analytic material (design §5, §6 with p=1)."""
    j, i = np.meshgrid(np.arange(181), np.arange(361), indexing="ij")
    wd = spherical(j * DEG, i * DEG)
    out = []
    for t in theta_in_deg:
        wo = wd @ specular_matrix(t * DEG).T  # S is symmetric and its own inverse
        theta_o = np.arccos(np.clip(wo[..., 2], -1, 1))
        phi_o = np.arctan2(wo[..., 1], wo[..., 0])
        wo_c = spherical(np.minimum(theta_o, theta_b_deg * DEG), phi_o)
        wi = np.broadcast_to(np.array([math.sin(t * DEG), 0.0, math.cos(t * DEG)]), wo_c.shape)
        out.append(material_f(mat, wi, wo_c))
    return np.stack(out)


def lut_coords(n, l, v, theta0, delta, k):
    """Centre-exact (u, v, w) of design §5 from world-space n, l, v (..., 3), in double."""
    cos_in = np.sum(n * l, axis=-1)
    lt = l - n * cos_in[..., None]
    sin_in = np.linalg.norm(lt, axis=-1)
    x = lt / np.maximum(sin_in, 1e-12)[..., None]
    y = np.cross(n, x)
    vl = np.stack([np.sum(v * x, -1), np.sum(v * y, -1), np.sum(v * n, -1)], axis=-1)
    wd = np.stack([-cos_in * vl[..., 0] - sin_in * vl[..., 2], -vl[..., 1],
                   -sin_in * vl[..., 0] + cos_in * vl[..., 2]], axis=-1)
    theta_d = np.degrees(np.arctan2(np.hypot(wd[..., 0], wd[..., 1]), wd[..., 2]))
    phi_d = np.degrees(np.arctan2(wd[..., 1], wd[..., 0])) % 360.0
    theta_in = np.degrees(np.arctan2(sin_in, cos_in))
    return ((phi_d + 0.5) / 361.0, (theta_d + 0.5) / 181.0,
            ((theta_in - theta0) / delta + 0.5) / k)


def trilinear(lut, u, v, w):
    """GL sampling of a (K, H, W, 3) texture at normalised coords, linear, clamp-to-edge."""
    def taps(c, n):
        x = np.clip(c * n - 0.5, 0.0, n - 1.0)
        i0 = np.floor(x).astype(int)
        i1 = np.minimum(i0 + 1, n - 1)
        return i0, i1, (x - i0)[..., None]
    k_, h_, w_ = lut.shape[:3]
    x0, x1, tx = taps(u, w_)
    y0, y1, ty = taps(v, h_)
    z0, z1, tz = taps(w, k_)

    def bil(z):
        a = lut[z, y0, x0] * (1 - tx) + lut[z, y0, x1] * tx
        b = lut[z, y1, x0] * (1 - tx) + lut[z, y1, x1] * tx
        return a * (1 - ty) + b * ty
    return bil(z0) * (1 - tz) + bil(z1) * tz


def decode_rgb9e5(words):
    words = np.asarray(words, dtype=np.int64)
    scale = np.exp2(((words >> 27) & 31).astype(float) - 24.0)
    return np.stack([(words & 511) * scale, ((words >> 9) & 511) * scale,
                     ((words >> 18) & 511) * scale], axis=-1)


def ktx2_words(path):
    """The level 0 RGB9E5 words of a KTX2 file, from the KTX 2.0 header and level index."""
    data = open(path, "rb").read()
    assert data[:12] == b"\xabKTX 20\xbb\r\n\x1a\n", path + ": not KTX 2.0"
    vk_format, _, width, height, depth = struct.unpack_from("<5I", data, 12)
    assert vk_format == 123, f"{path}: vkFormat {vk_format}"
    offset, length = struct.unpack_from("<QQ", data, 80)
    words = np.frombuffer(data, dtype="<u4", count=length // 4, offset=offset)
    return words.reshape(depth, height, width)


def ktx2_texel_reader(path):
    """texel(x, y, z) → RGB of the KTX2's level 0: RGB9E5 words (vkFormat 123) or BC6H blocks
    (131, 4 × 4 texels per 16 bytes, slices padded to whole blocks), decoded independently."""
    data = open(path, "rb").read()
    (vk_format,) = struct.unpack_from("<I", data, 12)
    if vk_format == 123:
        words = ktx2_words(path)
        return lambda x, y, z: decode_rgb9e5(words[z, y, x])
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import bc6h_oracle
    width, height, depth, payload, _ = bc6h_oracle.read_ktx2_bc6h(path)
    bw, bh = (width + 3) // 4, (height + 3) // 4

    def texel(x, y, z):
        at = ((z * bh + y // 4) * bw + x // 4) * 16
        halves = bc6h_oracle.decode_block(payload[at:at + 16])[(y % 4) * 4 + x % 4]
        return np.array(halves, dtype=np.uint16).view(np.float16).astype(np.float64)
    return texel


FILLED_PAIRS = 100


def in_filled_region(theta_in, theta_out):
    return theta_in >= 65.0 and theta_out >= 76.0


def gen_pairs(count, seed, angles_out, nlv_out):
    rng = np.random.default_rng(seed)
    # θin over the measured slices and beyond the last (exchanged with the view by reciprocity
    # when the view is nearer the measured range, else clamped to the last slice), θout into
    # the extrapolated band; random azimuths and a random rotation of the whole frame.
    # Then FILLED_PAIRS more in the region the blind-spot fill builds (docs/design.md §5, "Beyond
    # the measured slices"): light at θin 65–85° and view at θout 76–88°, both past what the
    # instrument measures (θin ≤ 60°, θout ≤ 75°).
    theta_in = np.concatenate([rng.uniform(0.0, 85.0, count),
                               rng.uniform(65.0, 85.0, FILLED_PAIRS)])
    theta_out = np.concatenate([rng.uniform(0.0, 85.0, count),
                                rng.uniform(76.0, 88.0, FILLED_PAIRS)])
    phi_in = rng.uniform(0.0, 360.0, count + FILLED_PAIRS)
    phi_out = rng.uniform(0.0, 360.0, count + FILLED_PAIRS)
    write_pairs(zip(theta_in, phi_in, theta_out, phi_out), rng, angles_out, nlv_out)


def write_pairs(rows, rng, angles_out, nlv_out):
    """Each (θin, φin, θout, φout) as an angles line and as n, l, v in a random frame."""
    with open(angles_out, "w") as a, open(nlv_out, "w") as b:
        for t_i, p_i, t_o, p_o in rows:
            q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
            n = q @ np.array([0.0, 0.0, 1.0])
            l = q @ spherical(t_i * DEG, p_i * DEG)
            v = q @ spherical(t_o * DEG, p_o * DEG)
            a.write(f"{t_i:.9f} {p_i:.9f} {t_o:.9f} {p_o:.9f}\n")
            b.write(" ".join(f"{x:.9f}" for x in (*n, *l, *v)) + "\n")


# Exact frames for gen-exact: signed permutations (entries 0 and ±1), so the zero components of
# n, l and v stay exactly zero in the file and on the GPU. Each is (x, y, z) of the surface frame
# in world space, right-handed (y = z × x), with x the axis `brdf eval` measures azimuths from.
# x is also the tangent the shaders fall back to for a light on the normal (the world x axis
# projected, or the world y axis when |n.x| > 0.7), so for such a light eval and the GPU read
# the θin = 0 slice at the same azimuth even where RGB9E5 rounding breaks its symmetry.
EXACT_FRAMES = [
    ((1, 0, 0), (0, 1, 0), (0, 0, 1)),
    ((1, 0, 0), (0, 0, 1), (0, -1, 0)),
    ((0, 1, 0), (0, 0, 1), (1, 0, 0)),
]


def exact_angles():
    """(θin, φin, θout, φout) in degrees: the directions where a shader's angle math meets a pole
    or the horizon: the view exactly along the normal, exactly at the horizon (four relative
    azimuths), exactly in the mirror direction, for lights inside, on the edge of and beyond the
    measured θin range, and the light exactly along the normal."""
    out = []
    for phi_in in (0.0, 90.0):
        for t_in in (10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 90.0):
            out.append((t_in, phi_in, 0.0, 0.0))  # view along the normal
            for rel in (0.0, 90.0, 180.0, 270.0):  # view at the horizon
                out.append((t_in, phi_in, 90.0, phi_in + rel))
            if t_in < 90.0:
                out.append((t_in, phi_in, t_in, phi_in + 180.0))  # mirror direction
        # Light along the normal (its azimuth is meaningless; eval and the shaders measure the
        # view's azimuth from the frame's x axis).
        for t_out, p_out in ((0.0, 0.0), (30.0, 0.0), (30.0, 90.0), (45.0, 45.0), (75.0, 200.0),
                             (90.0, 0.0), (90.0, 90.0), (90.0, 180.0), (90.0, 270.0)):
            out.append((0.0, phi_in, t_out, p_out))
    return out


def exact_category(t_in, p_in, t_out, p_out):
    if t_in == 0.0:
        return "light on the normal"
    if t_out == 0.0:
        return "view on the normal"
    if t_out == 90.0:
        return "view at the horizon"
    return "mirror view"


def gen_exact(angles_out, nlv_out):
    with open(angles_out, "w") as a, open(nlv_out, "w") as b:
        for frame in EXACT_FRAMES:
            q = np.array(frame, dtype=float).T  # columns: the frame's x, y, z in world space
            for t_i, p_i, t_o, p_o in exact_angles():
                n = q @ np.array([0.0, 0.0, 1.0])
                l = q @ spherical(t_i * DEG, p_i * DEG)
                v = q @ spherical(t_o * DEG, p_o * DEG)
                a.write(f"{t_i:.9f} {p_i:.9f} {t_o:.9f} {p_o:.9f}\n")
                # %.9f writes cos 90° (6e-17) as 0: the components on a pole or the horizon are
                # exactly 0 on the GPU.
                b.write(" ".join(f"{x:.9f}" for x in (*n, *l, *v)) + "\n")


def seam_angles():
    """(θin, φin, θout, φout) in degrees where a lookup addressed with the wrong texture width
    or height reads other texels most plainly: φd within 1° of the 0°/360° seam (the last
    columns, next to the BC6H padding) at several θd and θin, and θd 170–179.6° (the last rows),
    which only a grazing light with a grazing view near backscatter reaches. Built in the
    specular frame: v_local = S(θin)·ω_d (S is its own inverse), kept when above the horizon."""
    out = []
    for t_in in (20.0, 45.0, 70.0):
        for t_d in (5.0, 30.0, 60.0):
            for p_d in (0.2, 0.7, 359.3, 359.8):
                out.append((t_in, t_d, p_d))
    for t_in in (86.0, 88.0, 89.0, 89.5):
        for t_d in (170.0, 174.0, 177.0, 179.0, 179.6):
            for p_d in (170.0, 180.0, 190.0):
                out.append((t_in, t_d, p_d))
    result = []
    for t_in, t_d, p_d in out:
        c, s_ = math.cos(t_in * DEG), math.sin(t_in * DEG)
        w = spherical(t_d * DEG, p_d * DEG)
        v = np.array([-c * w[0] - s_ * w[2], -w[1], -s_ * w[0] + c * w[2]])
        if v[2] <= 1e-3:
            continue
        t_out = math.degrees(math.atan2(math.hypot(v[0], v[1]), v[2]))
        p_out = math.degrees(math.atan2(v[1], v[0])) % 360.0
        result.append((t_in, 0.0, t_out, p_out))
    return result


def gen_seam(angles_out, nlv_out, seed=5):
    rows = seam_angles()
    write_pairs(rows, np.random.default_rng(seed), angles_out, nlv_out)
    print(f"{len(rows)} seam and last-row pairs")


# Exact directions where one direction has several texels: the pole (mirror view, θd = 0: every
# column of row 0) and the seam and plane of incidence (view at the horizon in it: φd 0 or 360°,
# columns 0 and 360). RGB9E5 keeps those texels equal; BC6H encodes them in different blocks,
# so two readings of one direction may differ by up to twice the certified max error.
AMBIGUOUS = ("mirror view", "view at the horizon")


def compare_pairs(name, cpu, gpu, angles, by_category, ambiguous_tolerance=None):
    """Prints the max and median relative difference of gpu against cpu; False when above 1e-4
    (with ambiguous_tolerance: that bound for the exact categories in AMBIGUOUS)."""
    if gpu.shape != cpu.shape:
        print(f"FAIL {name}: {gpu.shape} values, brdf eval gave {cpu.shape}")
        return False
    rel = np.abs(gpu - cpu) / np.maximum(np.abs(cpu), 1e-6)
    worst_per_pair = np.max(rel, axis=1)
    line = (f"{name}: {len(cpu)} direction pairs vs brdf eval of the LUT: max rel diff "
            f"{rel.max():.3g}, median {np.median(rel):.3g}")
    if by_category:
        cats = [exact_category(*a) for a in angles]
        parts = []
        for c in dict.fromkeys(cats):
            sel = np.array([x == c for x in cats])
            parts.append(f"{c} {worst_per_pair[sel].max():.3g}")
        line += " (max by case: " + ", ".join(parts) + ")"
    else:
        filled = np.array([in_filled_region(a[0], a[2]) for a in angles])
        if filled.sum() < FILLED_PAIRS // 2:
            print(f"FAIL {name}: only {filled.sum()} pairs in the filled region (θin ≥ 65°, "
                  f"θout ≥ 76°)")
            return False
        line += (f"; filled region (θin 65–85°, θout 76–88°): {filled.sum()} pairs, max rel "
                 f"diff {worst_per_pair[filled].max():.3g}")
    print(line)
    # Same texels, same coordinates: only float32 angle math and the GPU's filter weights differ
    # from the double-precision CPU lookup (measured: up to 4.6e-6, the HLSL paths).
    limit = np.full(len(cpu), 1e-4)
    if by_category and ambiguous_tolerance is not None:
        cats = [exact_category(*a) for a in angles]
        amb = np.array([c in AMBIGUOUS for c in cats])
        limit[amb] = ambiguous_tolerance
        print(f"{name}: pole and seam directions ({int(amb.sum())} pairs, BC6H) within "
              f"{ambiguous_tolerance:.3g}: max {worst_per_pair[amb].max():.3g}; the other "
              f"{int((~amb).sum())} within 1e-4: max {worst_per_pair[~amb].max():.3g}")
    if np.all(worst_per_pair <= limit):
        return True
    bad = np.nonzero(worst_per_pair > limit)[0]
    for i in bad[:6]:
        print(f"FAIL {name}: pair {i + 1} (θin {angles[i][0]:g}, φin {angles[i][1]:g}, θout "
              f"{angles[i][2]:g}, φout {angles[i][3]:g}): GPU {gpu[i]} vs eval {cpu[i]}")
    if len(bad) > 6:
        print(f"FAIL {name}: {len(bad) - 6} more pairs differ by more than their bound")
    return False


def check(argv):
    opts = {}
    it = iter(argv)
    for a in it:
        opts[a.lstrip("-")] = next(it)
    mat = json.load(open(opts["material"])) if "material" in opts else None
    manifest = json.load(open(opts["manifest"]))
    res = opts["result"]
    meta = json.load(open(f"{res}/image.json"))
    theta = manifest["theta_in_deg"]
    theta0, delta, k = theta[0], theta[1] - theta[0], len(theta)
    ok = True

    # Probes: the texel the KTX2 holds, RGB9E5 decoded here or BC6H by the numpy decoder of
    # tests/python/bc6h_oracle.py (written from the specification).
    texel = ktx2_texel_reader(opts["ktx2"])
    probes = json.load(open(f"{res}/probes.json"))
    worst_fetch = worst_filtered = 0.0
    for p in probes:
        x, y, z = p["index"]
        expect = texel(x, y, z)
        if not np.array_equal(np.asarray(p["manifest"]), expect):
            print(f"FAIL probe {p['index']}: manifest {p['manifest']} != KTX2 texel {expect.tolist()}")
            ok = False
        worst_fetch = max(worst_fetch, float(np.max(np.abs(np.asarray(p["texel_fetch"]) - expect))))
        worst_filtered = max(worst_filtered,
                             float(np.max(np.abs(np.asarray(p["filtered_at_centre"]) - expect) /
                                          np.maximum(expect, 1e-6))))
    print(f"probes: {len(probes)} texels; manifest = KTX2 decode exactly; GPU texelFetch max abs "
          f"diff {worst_fetch:.3g}; filtered fetch at texel centre max rel diff {worst_filtered:.3g}")
    if worst_fetch != 0.0 or worst_filtered > 1e-6:
        print("FAIL probes: GPU values differ from the manifest")
        ok = False

    # Image (with --material: the analytic material the LUT was made from).
    if mat is not None:
        size = meta["width"]
        img = np.fromfile(f"{res}/image.f32", dtype="<f4").reshape(size, size, 4)[..., :3]
        img = img.astype(float)
        cam = np.asarray(meta["camera"]["position"], float)
        tan_half = math.tan(meta["camera"]["fov_y_deg"] * DEG / 2)
        py, px = np.meshgrid(np.arange(size), np.arange(size), indexing="ij")
        ndc_x = (px + 0.5) / size * 2 - 1
        ndc_y = 1 - (py + 0.5) / size * 2
        d = np.stack([ndc_x * tan_half, ndc_y * tan_half, -np.ones_like(ndc_x)], axis=-1)
        d /= np.linalg.norm(d, axis=-1, keepdims=True)
        b = np.sum(d * cam, -1)
        disc = b * b - (np.dot(cam, cam) - 1.0)
        hit = disc > 0
        t = -b - np.sqrt(np.maximum(disc, 0))
        p = cam + d * t[..., None]
        n = p / np.linalg.norm(p, axis=-1, keepdims=True)
        v = cam - p
        v /= np.linalg.norm(v, axis=-1, keepdims=True)
        light = np.asarray(meta["light_direction"], float)
        light /= np.linalg.norm(light)
        l = np.broadcast_to(light, n.shape)
        cos_l = np.sum(n * l, -1)
        # Away from the silhouette (the GPU sphere is a 128 × 64 mesh, the reference exact).
        mask = hit & (np.sum(n * v, -1) > 0.2) & (cos_l > 0.0)
        lut = numpy_lut(mat, theta)
        u, vv, w = lut_coords(n[mask], l[mask], v[mask], theta0, delta, k)
        # An atlas cell samples the same texels as the material's own LUT (the cell is clamped to
        # its outer texel centres), so the single-LUT reference applies; the cell offset is what
        # the GPU must get right.
        ref = np.zeros_like(img)
        ref[mask] = trilinear(lut, u, vv, w) * cos_l[mask][:, None]
        peak = float(np.max(ref[mask]))
        diff = img[mask] - ref[mask]
        rms = float(np.sqrt(np.mean(diff ** 2)))
        mx = float(np.max(np.abs(diff)))
        rel = np.abs(diff) / np.maximum(np.abs(ref[mask]), 1e-3 * peak)
        # Direct analytic shading (no LUT) for scale: includes the θin interpolation between
        # slices.
        analytic = np.zeros_like(img)
        nm, lm, vm = n[mask], l[mask], v[mask]
        lt = lm - nm * cos_l[mask][:, None]
        x = lt / np.linalg.norm(lt, axis=-1, keepdims=True)
        y = np.cross(nm, x)
        frame = lambda a: np.stack([np.sum(a * x, -1), np.sum(a * y, -1), np.sum(a * nm, -1)], -1)
        analytic[mask] = material_f(mat, frame(lm), frame(vm)) * cos_l[mask][:, None]
        a_rms = float(np.sqrt(np.mean((img[mask] - analytic[mask]) ** 2)))
        print(f"image: {int(mask.sum())} sphere pixels of {size}x{size}; peak radiance {peak:.4g}; "
              f"vs LUT-scheme reference: RMS {rms:.3g} ({rms / peak:.3%} of peak), max {mx:.3g} "
              f"({mx / peak:.3%} of peak), 99th percentile relative {np.percentile(rel, 99):.3%}; "
              f"vs direct analytic shading: RMS {a_rms / peak:.3%} of peak")
        # RGB9E5 rounds each texel by at most 2^-9 of its largest channel (0.2 %, RMS about a
        # third of that); the 1° capture's resampling and the GPU's filter weights add less
        # (measured with SwiftShader: RMS 0.034 % / 0.049 %, max 0.19 % / 0.22 % of peak for the
        # GGX LUT and a Lambertian atlas cell). Allow 0.07 % RMS and 0.35 % max: a lookup half a
        # texel off in θd alone gives 0.09 % and 0.45 %.
        if not (rms <= 0.0007 * peak and mx <= 0.0035 * peak):
            print("FAIL image: the rendered sphere differs from the reference")
            ok = False
        np.save(f"{res}/reference.npy", ref)

    # Direction pairs: random ones (pairs_<lang>.txt) and exact ones (exact_<lang>.txt), every
    # shader path the browser ran (--langs), against `brdf eval` of the same LUT. Godot's light()
    # returns radiance, f_r · max(n·l, 0) with a white light, so eval is multiplied by cos θin.
    langs = opts["langs"].split(",") if "langs" in opts else []
    # BC6H (--sidecar of the BC6H file): twice the certified max error over both ranges.
    ambiguous = None
    if "sidecar" in opts:
        cert = json.load(open(opts["sidecar"]))["compression"]["certified_error"]
        ambiguous = 2 * max(cert["measured"]["max"], cert["filled"]["max"])
    for prefix, eval_key, angles_key in (("pairs", "eval", "angles"),
                                         ("exact", "exact-eval", "exact-angles")):
        if eval_key not in opts:
            continue
        cpu = np.loadtxt(opts[eval_key], ndmin=2)
        angles = np.loadtxt(opts[angles_key], ndmin=2)
        cos_in = np.maximum(np.cos(angles[:, 0] * DEG), 0.0)[:, None]
        for lang in langs:
            gpu = np.loadtxt(f"{res}/{prefix}_{lang}.txt", ndmin=2)
            expect = cpu * cos_in if lang == "godot" else cpu
            ok = compare_pairs(f"{prefix} ({lang})", expect, gpu, angles.tolist(),
                               prefix == "exact", ambiguous) and ok
    return 0 if ok else 1


def main():
    if len(sys.argv) >= 2 and sys.argv[1] == "gen-pairs":
        gen_pairs(int(sys.argv[2]), int(sys.argv[3]), sys.argv[4], sys.argv[5])
        return 0
    if len(sys.argv) >= 2 and sys.argv[1] == "gen-seam":
        gen_seam(sys.argv[2], sys.argv[3])
        return 0
    if len(sys.argv) >= 2 and sys.argv[1] == "gen-exact":
        gen_exact(sys.argv[2], sys.argv[3])
        return 0
    if len(sys.argv) >= 2 and sys.argv[1] == "check":
        return check(sys.argv[2:])
    print(__doc__)
    return 2


if __name__ == "__main__":
    sys.exit(main())
