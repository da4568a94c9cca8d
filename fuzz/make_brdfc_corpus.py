#!/usr/bin/python3
"""Writes the seed corpus of brdfc_fuzzer (fuzz/corpus/brdfc/) from docs/formats/compact.md alone.

Small `.brdfc` files, one per path through the reader. `valid_*` seeds are well-formed (one
slice with the smallest grid, two mirrored slices, three slices with an embedded sidecar);
`bad_at<N>_*` seeds break one rule of the format and the reader must refuse them at byte N (the
first byte of the offending field). tests/export/brdfc_corpus_test.cpp checks that the C++
reader agrees, and reads the values of the valid seeds against the format's reading rule.

Usage:  fuzz/make_brdfc_corpus.py [OUT_DIR]   (default: fuzz/corpus/brdfc next to this script)
"""
import json
import math
import os
import struct
import sys
import zlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_bpc_corpus import write_seeds  # noqa: E402

MAGIC = b"BRDFCLUT"
HEADER = 36  # magic, version, K, flags, S, epsilon, CRC, L


def half(x):
    return struct.unpack("<H", struct.pack("<e", x))[0]


def payload(theta_in, grids):
    """grids: per slice (rows, cols, values) with values rows*cols*3 floats (g, log2)."""
    out = b"".join(struct.pack("<d", t) for t in theta_in)
    out += b"".join(struct.pack("<HH", len(r), len(c)) for r, c, _ in grids)
    for r, c, _ in grids:
        out += struct.pack(f"<{len(r)}H", *r) + struct.pack(f"<{len(c)}H", *c)
    for r, c, v in grids:
        assert len(v) == len(r) * len(c) * 3
        out += struct.pack(f"<{len(v)}H", *(half(x) for x in v))
    return out


def container(theta_in, grids, mirrored=False, scale=2.0, epsilon=2.0 ** -10, sidecar=b"",
              version=1, flags=None, crc=None):
    body = payload(theta_in, grids)
    head = MAGIC + struct.pack("<III", version, len(theta_in), (1 if mirrored else 0)
                               if flags is None else flags)
    head += struct.pack("<ff", scale, epsilon)
    head += struct.pack("<II", zlib.crc32(body) if crc is None else crc, len(sidecar))
    assert len(head) == HEADER
    return head + body + sidecar


def sidecar_json(theta_in, payload_bytes, crc):
    """The members docs/design.md §7 asks of a sidecar, for a compact payload."""
    doc = {
        "kind": "brdf-lut-sidecar",
        "name": "seed",
        "source": "fuzz/make_brdfc_corpus.py",
        "theta_in_deg": theta_in,
        "grid": {"width": 361, "height": 181, "slices": len(theta_in),
                 "delta_in_deg": theta_in[1] - theta_in[0] if len(theta_in) > 1 else 0},
        "extrapolation": {"p": 2.0, "l": 0.5, "theta_b_deg": 80.0},
        "tool": {"version": "seed"},
        "payload": {"bytes": payload_bytes, "format": "compact_log_grid",
                    "checksum": {"algorithm": "crc32", "value": f"0x{crc:08x}"}},
    }
    return json.dumps(doc, separators=(",", ":")).encode("utf-8")


# The smallest grid: rows 0 and 180, columns 0 and 360; g = 0, -1, -2, -3 at the four corners
# (R), the G and B channels a half and a quarter of R's g.
MINIMAL = ([0, 180], [0, 360],
           [g * s for g in (0.0, -1.0, -2.0, -3.0) for s in (1.0, 0.5, 0.25)])


def grid(rows, cols, seed):
    vals = []
    for j, r in enumerate(rows):
        for i, c in enumerate(cols):
            g = -((r / 30.0 + c / 45.0 + seed) % 9.0)  # within [log2 eps, 0]
            vals += [g, g * 0.75, g * 0.5]
    return rows, cols, vals


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "corpus", "brdfc")
    os.makedirs(out, exist_ok=True)
    mirrored = [grid([0, 30, 90, 180], [0, 60, 180], 0), grid([0, 45, 180], [0, 10, 20, 180], 1)]
    three_theta = [0.0, 30.0, 60.0]
    three = [grid([0, 90, 180], [0, 120, 240, 360], k) for k in range(3)]
    body3 = payload(three_theta, three)
    side = sidecar_json(three_theta, HEADER + len(body3), zlib.crc32(body3))
    minimal = container([0.0], [MINIMAL])
    files = {
        "valid_one_slice_minimal.brdfc": minimal,
        "valid_mirrored_two_slices.brdfc": container([0.0, 45.0], mirrored, mirrored=True),
        "valid_three_slices_sidecar.brdfc": container(three_theta, three, sidecar=side),
        # Header fields (offsets from the layout table).
        "bad_at0_magic.brdfc": b"BRDFCLUX" + minimal[8:],
        "bad_at8_version.brdfc": container([0.0], [MINIMAL], version=2),
        "bad_at12_slice_count.brdfc": minimal[:12] + struct.pack("<I", 0) + minimal[16:],
        "bad_at16_flags.brdfc": container([0.0], [MINIMAL], flags=2),
        "bad_at20_scale.brdfc": container([0.0], [MINIMAL], scale=math.nan),
        "bad_at24_epsilon.brdfc": container([0.0], [MINIMAL], epsilon=1.0),
        "bad_at28_checksum.brdfc": container([0.0], [MINIMAL], crc=0x12345678),
        # θin list (36), row/column counts (36 + 8K), lists, grid values.
        "bad_at36_theta_in.brdfc": container([91.0], [MINIMAL]),
        "bad_at52_theta_in_step.brdfc": container([0.0, 10.0, 25.0], [MINIMAL] * 3),
        "bad_at44_row_count.brdfc": container([0.0], [([0], [0, 360], [0.0] * 6)]),
        "bad_at48_rows_not_ascending.brdfc": container([0.0], [([0, 90, 90, 180], [0, 360],
                                                                [0.0] * 24)]),
        "bad_at52_columns_end.brdfc": container([0.0], [([0, 180], [0, 180], [0.0] * 12)]),
        "bad_at56_grid_value.brdfc": container([0.0], [([0, 180], [0, 360],
                                                         [2.0] + [0.0] * 11)]),
        # The file cut inside the grid values, and bytes after the (empty) sidecar.
        "bad_at56_truncated.brdfc": minimal[:60],
        "bad_at80_trailing_bytes.brdfc": minimal + b"\0junk",
    }
    write_seeds(out, files)


if __name__ == "__main__":
    main()
