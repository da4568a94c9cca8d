#!/usr/bin/python3
"""BC6H: the library's decoder and sidecar figures against an independent numpy implementation.

1. Hand-made blocks, one per mode (all 14): each block is assembled from chosen field values
   (endpoints or deltas, partition, indices) through the specification's Table.F; the expected
   half-float texels are computed from those field values with the specification's arithmetic
   (transform, unquantize, interpolate, × 31/64), without reading any bits back. The numpy
   decoder (bc6h_oracle.py) and the library (bc6h_dump_fixture on a KTX2 holding the blocks)
   must both give exactly those values. The same file is what the browser test uploads to a
   real GPU (tests/engines/web_bc6h_test.mjs).
2. Blocks from our encoder: `brdf convert --compress bc6h` of a simulated capture; every texel
   decoded by numpy equals, bit for bit, what the library decodes (and so `brdf eval` reads).
3. The certified error in the sidecar recomputed from the EXR's float LUT and the numpy decode:
   the definition in docs/design.md §7 (reference clamped to [0, 65504], max over channels of
   |d − r| / max(max r, 1e-4 · the LUT's largest value, 2^−14)), θout ≤ θb versus beyond,
   nearest-rank p99 and median.

4. With --gpu (ctest label browser): headless Chromium's WebGL 2 (SwiftShader) uploads both
   KTX2 files as compressed 3D textures and texelFetches every texel (tests/node/bc6h_gpu.mjs);
   the GPU's values must equal the hand-derived ones and the numpy decode bit for bit, and
   `brdf eval` of the BC6H file at the directions of every texel of the 20° slice (θout ≤ 89°,
   off the poles and the seam)
   must read the same values (to 1e-5: its trilinear weights at texel centres are exact only up
   to float rounding).

Usage: bc6h_check.py --brdf BRDF --dump BC6H_DUMP_FIXTURE --work DIR [--gpu NODE_SCRIPT
       [--chromium PATH]]
"""

import argparse
import json
import math
import os
import struct
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bc6h_oracle as bc  # noqa: E402


def pack_block(mode, fields, partition, indices):
    """fields: {'r0': int, ...} raw field values (deltas already masked); indices per texel."""
    bits = []
    for name, hi, lo in bc.RUNS[mode]:
        value = mode if name == "m" else fields.get(name, 0)
        step = 1 if hi >= lo else -1
        for n in range(abs(hi - lo) + 1):
            bits.append((value >> (lo + n * step)) & 1)
    _, pbits, _, _ = bc.MODES[mode]
    two = pbits > 0
    if two:
        bits += [(partition >> n) & 1 for n in range(5)]
    ib = 3 if two else 4
    for t in range(16):
        anchor = t == 0 or (two and t == bc.A2[partition])
        n = ib - 1 if anchor else ib
        assert indices[t] < (1 << n)
        bits += [(indices[t] >> i) & 1 for i in range(n)]
    assert len(bits) == 128, (mode, len(bits))
    return bytes(np.packbits(np.array(bits, dtype=np.uint8), bitorder="little"))


# Chosen per mode: endpoint 0 (R, G, B raw values), then for transformed modes the signed deltas
# of endpoints 1..3 (two subsets) or 1, for raw modes their absolute values; the partition.
HAND = {
    0: ((725, 419, 796), [(7, -5, 15), (-16, 3, -1), (10, -9, 4)], 18),
    1: ((101, 77, 30), [(31, -32, 5), (-20, 11, 17), (2, 29, -7)], 3),
    2: ((1500, 700, 1999), [(-16, 7, -8), (9, -3, 2), (15, 6, -5)], 26),
    6: ((40, 2047, 1024), [(7, -16, 3), (-8, 15, -2), (1, 9, 6)], 17),
    10: ((333, 1234, 2000), [(5, -1, -16), (-3, 4, 15), (6, -7, 11)], 31),
    14: ((300, 111, 500), [(-9, 12, 1), (15, -16, 8), (-2, 3, -4)], 8),
    18: ((200, 13, 255), [(31, 2, -3), (-32, 14, -16), (7, -11, 9)], 22),
    22: ((17, 180, 99), [(-6, 31, 4), (13, -32, -9), (-1, 19, 15)], 29),
    26: ((240, 64, 3), [(11, -4, 31), (-10, 6, -32), (2, -15, 25)], 12),
    30: ((63, 0, 17), [(10, 44, 33), (5, 63, 1), (62, 30, 50)], 24),
    3: ((1000, 3, 517), [(12, 1023, 700)], None),
    7: ((2047, 1, 1111), [(-256, 255, -1)], None),
    11: ((4000, 2222, 17), [(127, -128, 60)], None),
    15: ((65535, 12345, 40000), [(-8, 7, 1)], None),
}


def hand_case(mode):
    transformed, pbits, epb, delta = bc.MODES[mode]
    e0, rest, partition = HAND[mode]
    partition = partition or 0
    two = pbits > 0
    fields = {}
    ends = [list(e0)]
    for c, ch in enumerate("rgb"):
        fields[ch + "0"] = e0[c]
    for e, vals in enumerate(rest, start=1):
        end = []
        for c, ch in enumerate("rgb"):
            if transformed:
                d = vals[c]
                assert -(1 << (delta[c] - 1)) <= d < (1 << (delta[c] - 1)), (mode, e, c, d)
                fields[ch + str(e)] = d & ((1 << delta[c]) - 1)
                end.append((e0[c] + d) & ((1 << epb) - 1))
            else:
                fields[ch + str(e)] = vals[c]
                end.append(vals[c])
        ends.append(end)
    levels = 8 if two else 16
    indices = []
    for t in range(16):
        anchor = t == 0 or (two and t == bc.A2[partition])
        indices.append((5 * t + 3) % (levels // 2 if anchor else levels))
    block = pack_block(mode, fields, partition, indices)

    # Expected values from the fields, by the specification's arithmetic.
    def unq(x):
        if epb >= 15:
            return x
        if x == 0:
            return 0
        if x == (1 << epb) - 1:
            return 0xFFFF
        return ((x << 16) + 0x8000) >> epb

    weights = bc.W3 if two else bc.W4
    expected = []
    for t in range(16):
        s = int(bc.P2[partition][t]) if two else 0
        w = weights[indices[t]]
        a, b = ends[2 * s], ends[2 * s + 1]
        expected.append([(((64 - w) * unq(a[c]) + w * unq(b[c]) + 32) // 64) * 31 // 64
                         for c in range(3)])
    return block, expected


def write_ktx2_bc6h(path, width, height, depth, payload):
    """A minimal conforming KTX2 with the BC6H_UFLOAT DFD (KTX 2.0 and Data Format 1.3)."""
    dfd = struct.pack("<11I", 44, 0, 2 | (40 << 16), 131 | (1 << 8) | (1 << 16), 3 | (3 << 8),
                      16, 0, 127 << 16 | 0x80 << 24, 0, 0, 0x3F800000)
    dfd_offset = 80 + 24
    level_offset = (dfd_offset + len(dfd) + 15) // 16 * 16
    header = b"\xabKTX 20\xbb\r\n\x1a\n" + struct.pack(
        "<9I", 131, 1, width, height, depth, 0, 1, 1, 0)
    index = struct.pack("<4I2Q", dfd_offset, len(dfd), 0, 0, 0, 0)
    level = struct.pack("<3Q", level_offset, len(payload), len(payload))
    body = header + index + level + dfd
    body += b"\0" * (level_offset - len(body))
    with open(path, "wb") as f:
        f.write(body + payload)


def dump(fixture, texture, out):
    subprocess.run([fixture, texture, out], check=True)
    return np.fromfile(out, dtype="<f4")


def check_modes(args):
    blocks, expected = [], []
    for mode in bc.MODES:
        block, exp = hand_case(mode)
        assert bc.mode_of(block) == mode
        got = bc.decode_block(block)
        if got != exp:
            raise AssertionError(f"numpy decoder, mode {mode}: {got} != hand-derived {exp}")
        blocks.append(block)
        expected.append(exp)
    path = os.path.join(args.work, "bc6h_modes.ktx2")
    write_ktx2_bc6h(path, 4, 4, len(blocks), b"".join(blocks))
    lib = dump(args.dump, path, os.path.join(args.work, "bc6h_modes.raw")).reshape(-1, 16, 3)
    want = np.array(expected, dtype=np.uint16).view(np.float16).astype(np.float32)
    for i, mode in enumerate(bc.MODES):
        if not np.array_equal(lib[i], want[i]):
            raise AssertionError(f"library decoder, mode {mode}: {lib[i].tolist()} != "
                                 f"{want[i].tolist()}")
    print(f"hand-made blocks: all {len(blocks)} modes decode to the hand-derived values "
          f"(numpy and library); {path}")
    if args.gpu:
        gpu = gpu_fetch(args, path, "bc6h_modes_gpu.raw").reshape(-1, 16, 3)
        for i, mode in enumerate(bc.MODES):
            if not np.array_equal(gpu[i], want[i]):
                raise AssertionError(f"GPU, mode {mode}: {gpu[i].tolist()} != {want[i].tolist()}")
        print("GPU: the hand-made blocks of all 14 modes fetch as the hand-derived values")


def gpu_fetch(args, ktx2, name):
    out = os.path.join(args.work, name)
    subprocess.run([args.node, args.gpu, "--ktx2", ktx2, "--out", out, "--chromium", args.chromium],
                   check=True, stderr=subprocess.DEVNULL if not args.verbose else None)
    return np.fromfile(out, dtype="<f4")


def nearest_rank(sorted_values, p):
    n = len(sorted_values)
    return float(sorted_values[min(max(math.ceil(p * n), 1), n) - 1])


def check_encoder(args):
    brdf = args.brdf
    cap = os.path.join(args.work, "gold.bpc")
    out = os.path.join(args.work, "out")
    subprocess.run([brdf, "capture", "--device", "sim", "--material", "gold", "--sample", "gold",
                    "--out", cap, "--quiet", "--force"], check=True)
    subprocess.run([brdf, "convert", cap, "--out", out, "--compress", "bc6h", "--exr-type",
                    "float", "--quiet", "--force"], check=True)
    width, height, depth, level, kv = bc.read_ktx2_bc6h(os.path.join(out, "gold.ktx2"))
    # Whatever slices the LUT has (4 measured, or 9 with the blind-spot fill's --beyond auto).
    theta_in_list = json.load(open(os.path.join(out, "gold.json")))["theta_in_deg"]
    assert (width, height, depth) == (361, 181, len(theta_in_list))
    assert len(level) == 91 * 46 * depth * 16
    ours = bc.decode_volume(level, width, height, depth)
    lib = dump(args.dump, os.path.join(out, "gold.ktx2"), os.path.join(args.work, "gold.raw"))
    lib = lib.reshape(depth, height, width, 3)
    if not np.array_equal(ours.view(np.uint32), lib.view(np.uint32)):
        bad = np.argwhere(ours != lib)
        raise AssertionError(f"{len(bad)} texels differ between numpy and the library, first "
                             f"{bad[0].tolist()}")
    modes = {}
    for i in range(0, len(level), 16):
        m = bc.mode_of(level[i:i + 16])
        modes[m] = modes.get(m, 0) + 1
    print(f"encoder blocks: {len(level) // 16} blocks (modes {sorted(modes.items())}) decode "
          "identically in numpy and the library")
    if args.gpu:
        ktx2 = os.path.join(out, "gold.ktx2")
        gpu = gpu_fetch(args, ktx2, "gold_gpu.raw").reshape(depth, height, width, 3)
        if not np.array_equal(gpu.view(np.uint32), ours.view(np.uint32)):
            bad = np.argwhere(gpu != ours)
            raise AssertionError(f"{len(bad)} texels differ between the GPU and numpy, first "
                                 f"{bad[0].tolist()}: {gpu[tuple(bad[0][:3])]} vs "
                                 f"{ours[tuple(bad[0][:3])]}")
        print(f"GPU: all {width * height * depth} texels fetch bit for bit as numpy decodes them")
        # brdf eval at the direction of every texel of the slice at θin = 20°.
        k = theta_in_list.index(20.0)
        theta_m = math.radians(20.0)
        lines, where = [], []
        # Directions name texels uniquely except at the poles (row 0 and 180: every φd is the
        # same direction) and on the seam (columns 0 and 360 are both φd = 0, which eval may read
        # from either; after compression the two columns need not be equal).
        for j in range(1, height - 1):
            for i in range(1, width - 1):
                td, pd = math.radians(j), math.radians(i)
                dx, dy, dz = math.sin(td) * math.cos(pd), math.sin(td) * math.sin(pd), math.cos(td)
                ox = -math.cos(theta_m) * dx - math.sin(theta_m) * dz  # ω_out = S(θm)·ω_d
                oy = -dy
                oz = -math.sin(theta_m) * dx + math.cos(theta_m) * dz
                theta_out = math.degrees(math.acos(max(-1.0, min(1.0, oz))))
                if theta_out > 89.0:
                    continue
                phi_out = math.degrees(math.atan2(oy, ox)) % 360.0
                lines.append(f"20 0 {theta_out:.12f} {phi_out:.12f}")
                where.append((j, i))
        r = subprocess.run([brdf, "eval", ktx2, "--pairs", "-"], input="\n".join(lines) + "\n",
                           capture_output=True, text=True, check=True)
        got = np.array([[float(x) for x in line.split()] for line in r.stdout.splitlines()])
        want = np.array([gpu[k, j, i] for j, i in where], dtype=np.float64)
        rel = np.abs(got - want).max(axis=1) / np.maximum(want.max(axis=1), 2.0 ** -14)
        if rel.max() > 1e-5:
            n = int(rel.argmax())
            raise AssertionError(f"brdf eval at texel {where[n]} of slice {k}: {got[n]} vs the "
                                 f"GPU's {want[n]}")
        print(f"brdf eval of the BC6H file reads the GPU's values at all {len(where)} texels of "
              f"the 20 deg slice with theta_out <= 89 deg (max relative difference "
              f"{rel.max():.2e})")

    # Certified error, recomputed.
    import OpenImageIO as oiio
    inp = oiio.ImageInput.open(os.path.join(out, "gold.exr"))
    image = inp.read_image(format="float")
    inp.close()
    ref = np.zeros((depth, height, width, 3), dtype=np.float32)
    grid_cols = math.ceil(math.sqrt(depth))  # the composite's grid (docs/design.md §5)
    for k in range(depth):
        c, r = k % grid_cols, k // grid_cols
        ref[k] = image[r * height:(r + 1) * height, c * width:(c + 1) * width, :3]
    sidecar = json.load(open(os.path.join(out, "gold.json")))
    cert = sidecar["compression"]["certified_error"]
    theta_b = cert["theta_b_deg"]
    ref64 = np.clip(ref.astype(np.float64), 0.0, 65504.0)
    ours64 = ours.astype(np.float64)
    floor = max(2.0 ** -14, float(np.float32(1e-4)) * ref64.max())
    scale = np.maximum(ref64.max(axis=3), floor)
    err = np.abs(ours64 - ref64).max(axis=3) / scale
    theta_in = np.radians(np.array(sidecar["theta_in_deg"], dtype=np.float64))[:, None, None]
    td = np.radians(np.arange(height, dtype=np.float64))[None, :, None]
    pd = np.radians(np.arange(width, dtype=np.float64))[None, None, :]
    cos_out = np.cos(theta_in) * np.cos(td) - np.sin(theta_in) * np.sin(td) * np.cos(pd)
    theta_out = np.degrees(np.arccos(np.clip(cos_out, -1, 1)))
    measured = theta_out <= theta_b + 1e-9
    for name, mask in (("measured", measured), ("filled", ~measured)):
        values = np.sort(err[mask])
        mine = {"max": float(values[-1]), "p99": nearest_rank(values, 0.99),
                "median": nearest_rank(values, 0.5), "texels": int(values.size)}
        rec = cert[name]
        if rec["texels"] != mine["texels"]:
            raise AssertionError(f"{name}: sidecar counts {rec['texels']} texels, numpy "
                                 f"{mine['texels']}")
        for key in ("max", "p99", "median"):
            if not math.isclose(rec[key], mine[key], rel_tol=1e-5, abs_tol=1e-9):
                raise AssertionError(f"{name} {key}: sidecar {rec[key]}, numpy {mine[key]}")
        print(f"certified error ({name}, {mine['texels']} texels): max {100 * mine['max']:.3f} %,"
              f" p99 {100 * mine['p99']:.3f} %, median {100 * mine['median']:.3f} % as recorded")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--brdf", required=True)
    ap.add_argument("--dump", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--gpu", help="tests/node/bc6h_gpu.mjs: also decode on a real GPU")
    ap.add_argument("--chromium", default="chromium")
    ap.add_argument("--node", default="node")
    ap.add_argument("--verbose", action="store_true")
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    check_modes(args)
    check_encoder(args)


if __name__ == "__main__":
    main()
