#!/usr/bin/python3
"""Writes the seed corpus of bpc_fuzzer (fuzz/corpus/bpc/) from docs/formats/bpc.md alone.

Tiny files, one per path through the reader: finished, unfinished, header only, cut inside a
slice, a corrupt payload followed by an intact slice, trailing bytes, and a later minor version
(unknown chunk tag, larger records, unknown slice flag bits). The name says what each is;
tests/core/bpc_corpus_test.cpp checks that the C++ reader agrees.

Usage:  fuzz/make_bpc_corpus.py [OUT_DIR]   (default: fuzz/corpus/bpc next to this script)
"""
import json
import math
import os
import struct
import sys
import zlib

MAGIC = bytes([0x89, 0x42, 0x50, 0x43, 0x0D, 0x0A, 0x1A, 0x0A])
NO_SLICE = 0xFFFFFFFF
HAS_SIGMA, INCOMPLETE = 1, 2

METADATA = {
    "sample_name": "seed tile",
    "instrument_model": "MiniDiff V2 (simulated)",
    "capture_start": "2026-11-22T10:00:00Z",
    "units": "1/sr",
    "extra": {"seed": "1"},
}


def chunk(tag, index, payload):
    head = tag + struct.pack("<IQI", index, len(payload), zlib.crc32(payload))
    return head + struct.pack("<I", zlib.crc32(head)) + payload


def preamble_and_head(minor=0, metadata=METADATA):
    head = {
        "format": "bpc",
        "version": [1, minor],
        "metadata": metadata,
        "units": {"angles": "deg", "f_r": "1/sr", "sigma": "1/sr"},
    }
    payload = json.dumps(head, separators=(",", ":")).encode("utf-8")
    return MAGIC + struct.pack("<HH", 1, minor) + chunk(b"HEAD", NO_SLICE, payload)


def slice_chunk(index, theta_in, samples, sigma=False, flags=0, record_size=None):
    """samples: (theta_out, phi_out, (r, g, b), sample_flags[, (sr, sg, sb)]) tuples."""
    flags |= HAS_SIGMA if sigma else 0
    size = record_size or (44 if sigma else 32)
    body = struct.pack("<ddQII", theta_in, 0.0, len(samples), flags, size)
    for s in samples:
        rec = struct.pack("<7fB3x", theta_in, 0.0, s[0], s[1], *s[2], s[3])
        if sigma:
            rec += struct.pack("<3f", *s[4])
        body += rec + bytes(size - len(rec))
    return chunk(b"SLCE", index, body)


def end_chunk(slices, samples, metadata=METADATA):
    final = dict(metadata, capture_end="2026-11-22T10:01:00Z")
    payload = json.dumps({"metadata": final, "slice_count": slices, "sample_count": samples},
                         separators=(",", ":")).encode("utf-8")
    return chunk(b"END ", NO_SLICE, payload)


def write_seeds(out, files):
    """Writes {file name: bytes} into OUT (also used by make_brdfc_corpus.py)."""
    for name, data in files.items():
        with open(os.path.join(out, name), "wb") as f:
            f.write(data)
    print(f"wrote {len(files)} seeds to {out}")


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "corpus", "bpc")
    os.makedirs(out, exist_ok=True)
    plain = [(0.0, 0.0, (0.3, 0.2, 0.1), 0), (30.0, 180.0, (0.25, 0.5, 0.125), 1),
             (75.0, 359.0, (0.01, 0.02, 0.03), 8)]
    # Values a lossless format must keep: -0, a denormal, infinity, NaN, a negative reading.
    awkward = [(20.0, 180.0, (-0.0, 1e-40, math.inf), 2, (0.001, 0.0, 1e-45)),
               (45.0, 90.0, (math.nan, -2.5e-4, 3.0e38), 4, (0.5, 0.25, 0.0))]
    s0 = slice_chunk(0, 0.0, plain)
    s1 = slice_chunk(1, 20.0, awkward, sigma=True)
    head = preamble_and_head()
    finished = head + s0 + s1 + end_chunk(2, 5)
    files = {
        "finished_two_slices.bpc": finished,
        "unfinished_incomplete_slice.bpc": head + slice_chunk(0, 40.0, plain, flags=INCOMPLETE),
        "unfinished_header_only.bpc": head,
        "truncated_inside_slice.bpc": (head + s0 + s1)[:len(head + s0) + 40],
        "corrupt_payload_then_intact_slice.bpc":
            head + s0[:30] + bytes([s0[30] ^ 0x40]) + s0[31:] + s1,
        "trailing_data_after_end.bpc": finished + b"\0\0junk",
        "finished_minor_version_1.bpc":
            preamble_and_head(minor=1) + chunk(b"NOTE", NO_SLICE, b"later minor version") +
            slice_chunk(0, 60.0, plain, flags=0x100, record_size=40) + end_chunk(1, 3),
    }
    write_seeds(out, files)


if __name__ == "__main__":
    main()
