#!/usr/bin/python3
"""Hostile inputs, second pass: every `brdf` command that reads a file, run on
damaged copies of valid files of every supported format, must neither crash, hang, misreport,
nor disagree with another command about the same file.

usage: hostile_inputs.py BRDF_TOOL SOURCE_DIR [--jobs N] [--keep] [--only REGEX] [--list]
                         [--data-default DIR]

Seed files are made valid first, into a private mkdtemp folder: a reduced-geometry capture from
the simulator and everything `brdf convert`, `export-csv`, `atlas` and `fit` make of it, material
files from data-samples/materials, a MERL file written here in the published layout, and
third-party files read from BRDF_DATA_DIR (default SOURCE_DIR/../shared/brdf-data; missing, the
run fails naming the variable): RGL .bsdf, Zemax, goniometer table. A LightTools table, PLY/OBJ
meshes and .hdr/.exr environment maps (flat and run-length RGBE, raw and ZIP EXR) are written
here in their published layouts.

Each seed gets variants, all derived from one fixed seed (the same files on every run):
truncations (0, 1, end of header, middle, last byte), bit flips at seeded positions, lying
headers (counts, dimensions and sizes larger and smaller than the data, negative, huge; CRCs
recomputed so the lie reaches the parser), wrong types (another format's bytes under this
extension; JSON with strings, null, NaN, 1e309 and nested objects where numbers go) and special
files (empty, FIFO, folder, /dev/zero, /dev/null, a sparse 3 GiB file with a valid head).

Every command that reads such a file runs under a CPU-time limit (10 s of user + system time,
RLIMIT_CPU: the machine's load does not count), a generous wall-clock limit (60 s, for a
command that blocks without computing) and an address-space cap (4 GiB) and is checked for:
  - peak resident memory (the kernel's ru_maxrss of that run) at most 1 GiB;
  - no signal, no timeout, exit code 0, 1 (error) or 2 (command line), never 3 (internal error);
  - positive control: every command accepts each seed's valid file (exit 0);
  - on failure: stderr is one line that names the file, with no C++ identifiers (`::`), no
    JSON-library text, no CLI11 internals, no "channel N" internals; for damaged files the line
    carries a position: a byte, line, column, offset, scanline, record, the header, or the
    member / chunk / field / level / slice / row it is in;
  - agreement: `info` exit 1 => `eval` and `convert` refuse; `info` exit 0 => `eval` and
    `convert` succeed unless `info` printed a warning; `eval` prints finite values; the θin
    list `info --json` reports equals the measured one in convert's sidecar (its "beyond"
    record's, when the LUT carries filled slices; a run where that check could not be made is a
    finding too);
  - accounting: every lie a seed's rules describe produced a file that was run (a rule whose
    pattern no longer matches its seed is a finding); the summary counts the lies per seed.
A summary prints the count of files and runs; each finding prints one line and the exit code
is 1 when there is any.
"""

import argparse
import concurrent.futures
import json
import math
import os
import random
import re
import resource
import shutil
import signal
import stat
import struct
import subprocess
import sys
import tempfile
import threading
import time
import zlib

CPU_LIMIT_S = 10   # user + system seconds per command (RLIMIT_CPU)
TIMEOUT_S = 60     # wall clock per command: only for a command that waits without computing
ADDRESS_SPACE_BYTES = 4 << 30
# Peak resident memory per command. The reading commands peak at 14–64 MiB on the pass's small
# files (info 14, convert 23, preview 37 on the intact capture; info of a capture builds the
# filled LUT, about 100 MB); 1 GiB leaves room for a slow machine's allocator and still catches
# memory that grows with a lying count or a value rather than with what the file holds.
PEAK_RSS_BYTES = 1 << 30
SEED = 20261201

FORBIDDEN = [
    ("C++ identifier", re.compile(r"::|nlohmann")),
    ("JSON library text", re.compile(r"json\.exception|\[json|parse_error|type_error")),
    ("CLI11 internals", re.compile(r"CLI::|CLI11|ParseError|ValidationError")),
    ("internal index", re.compile(r"\bchannel \d")),
    ("crash text", re.compile(r"terminate called|Segmentation|Aborted|AddressSanitizer|"
                              r"runtime error:|what\(\)|internal error|bad_alloc|"
                              r"std::|Assertion")),
]


# ---------------------------------------------------------------------------------------------
# Writers of the formats without a producer in the toolchain (published layouts).

def write_merl(path):
    """A MERL .binary (dims 90, 90, 180; 3 planes of float64, scaled by 1/1500, 1.15/1500,
    1.66/1500 when read): a constant, Lambertian-like BRDF."""
    n = 90 * 90 * 180
    with open(path, "wb") as f:
        f.write(struct.pack("<3i", 90, 90, 180))
        for value in (0.2 / math.pi * 1500, 0.3 / math.pi * 1500 / 1.15,
                      0.4 / math.pi * 1500 / 1.66):
            f.write(struct.pack("<d", value) * n)


LIGHTTOOLS = """# LightTools BSDF, written by hostile_inputs.py
Symmetry Asymmetrical
SpectralContent RGB
ScatterAzimuth 3 0 90 180
ScatterRadial 3 0 20 40
DataBegin
"""


def write_lighttools(path):
    text = LIGHTTOOLS
    for aoi in (0, 30):
        for channel, wavelength, value in (("R", 630, 0.1), ("G", 525, 0.2), ("B", 465, 0.3)):
            text += (f"AOI {aoi}\nPOI 0\nSide Front\nWavelength {wavelength}\nScatterType BRDF\n"
                     f"TristimulusValue {channel}\nTIS 0.5\n")
            for _ in range(3):
                text += "\t".join(f"{value:g}" for _ in range(3)) + "\n"
    text += "DataEnd\n"
    open(path, "w").write(text)


def write_ply_ascii(path):
    open(path, "w").write(
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
        "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 1\n1 0 -0.5\n-0.5 0.86 -0.5\n-0.5 -0.86 -0.5\n"
        "3 0 1 2\n3 0 2 3\n3 0 3 1\n3 1 3 2\n")


def write_ply_binary(path):
    header = ("ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\n"
              "property float y\nproperty float z\nelement face 4\n"
              "property list uchar int vertex_indices\nend_header\n").encode()
    body = b"".join(struct.pack("<3f", *v) for v in
                    ((0, 0, 1), (1, 0, -0.5), (-0.5, 0.86, -0.5), (-0.5, -0.86, -0.5)))
    body += b"".join(struct.pack("<B3i", 3, *f) for f in ((0, 1, 2), (0, 2, 3), (0, 3, 1), (1, 3, 2)))
    open(path, "wb").write(header + body)


def write_obj(path):
    open(path, "w").write(
        "# tetrahedron\nv 0 0 1\nv 1 0 -0.5\nv -0.5 0.86 -0.5\nv -0.5 -0.86 -0.5\n"
        "vn 0 0 1\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n")


def write_hdr(path, width=16, height=8):
    """Radiance RGBE, flat (not run-length encoded) scanlines."""
    header = f"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {height} +X {width}\n".encode()
    pixel = bytes((128, 128, 128, 129))  # 1.0 in every channel
    open(path, "wb").write(header + pixel * (width * height))


def write_hdr_rle(path, width=16, height=8):
    """Radiance RGBE with run-length encoded scanlines (2 2 W>>8 W&255, then per component one
    run of W equal bytes: count 128 + W, value), the layout most writers produce."""
    header = f"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {height} +X {width}\n".encode()
    line = bytes((2, 2, width >> 8, width & 255))
    for value in (128, 64, 32, 129):
        line += bytes((128 + width, value))
    open(path, "wb").write(header + line * height)


def write_exr_env(path, width=16, height=8, compression=None):
    import numpy as np
    import OpenImageIO as oiio
    spec = oiio.ImageSpec(width, height, 3, "float")
    if compression:
        spec.attribute("compression", compression)
    out = oiio.ImageOutput.create(path)
    if not out or not out.open(path, spec):
        raise SystemExit(f"hostile_inputs: cannot write {path} with OpenImageIO")
    if compression:  # smooth, so that the blocks hold real compressed streams
        y, x = np.mgrid[0:height, 0:width]
        out.write_image(np.stack([x / width, y / height, np.full(x.shape, 0.5)], -1)
                        .astype(np.float32))
    else:
        out.write_image(np.ones((height, width, 3), dtype=np.float32))
    out.close()


# ---------------------------------------------------------------------------------------------
# Lying headers, per format. Each returns [(label, bytes)].

def crc(data):
    return zlib.crc32(data) & 0xFFFFFFFF


def bpc_chunks(data):
    """[(offset, tag, index, payload_size)] of the well-formed chunks of a .bpc."""
    chunks, pos = [], 12
    while pos + 24 <= len(data):
        tag = data[pos:pos + 4]
        index, size = struct.unpack_from("<IQ", data, pos + 4)
        chunks.append((pos, tag, index, size))
        pos += 24 + size
    return chunks


def bpc_rewrite_chunk(data, offset, tag=None, index=None, payload=None, payload_size=None,
                      fix_payload_crc=True):
    """`data` with the chunk at `offset` changed and its CRCs recomputed."""
    old_tag = data[offset:offset + 4]
    old_index, old_size = struct.unpack_from("<IQ", data, offset + 4)
    old_payload = data[offset + 24:offset + 24 + old_size]
    new_payload = old_payload if payload is None else payload
    size = len(new_payload) if payload_size is None else payload_size
    pcrc = crc(new_payload) if fix_payload_crc else struct.unpack_from("<I", data, offset + 16)[0]
    head = (tag or old_tag) + struct.pack("<IQI", old_index if index is None else index, size, pcrc)
    head += struct.pack("<I", crc(head))
    return data[:offset] + head + new_payload + data[offset + 24 + old_size:]


def lies_bpc(data):
    out = []
    chunks = bpc_chunks(data)
    head = chunks[0]
    slices = [c for c in chunks if c[1] == b"SLCE"]
    end = [c for c in chunks if c[1] == b"END "]
    s0 = slices[0]
    payload = data[s0[0] + 24:s0[0] + 24 + s0[3]]
    count = struct.unpack_from("<Q", payload, 16)[0]
    record = struct.unpack_from("<I", payload, 28)[0]
    for label, value in (("count+1", count + 1), ("count-1", count - 1), ("count0", 0),
                         ("count-huge", (1 << 64) - 1), ("count2^40", 1 << 40)):
        p = payload[:16] + struct.pack("<Q", value) + payload[24:]
        out.append(("slice-" + label, bpc_rewrite_chunk(data, s0[0], payload=p)))
    for label, value in (("record16", 16), ("record-huge", 0xFFFFFFFF), ("record0", 0),
                         ("record64", 64)):
        p = payload[:28] + struct.pack("<I", value) + payload[32:]
        out.append(("slice-" + label, bpc_rewrite_chunk(data, s0[0], payload=p)))
    for label, value in (("theta-nan", float("nan")), ("theta-200", 200.0), ("theta--5", -5.0),
                         ("theta-inf", float("inf"))):
        p = struct.pack("<d", value) + payload[8:]
        out.append(("slice-" + label, bpc_rewrite_chunk(data, s0[0], payload=p)))
    # One sample with NaN / out-of-range angles / negative values.
    first = 32
    for label, off, value in (("sample-theta-out-nan", 8, float("nan")),
                              ("sample-theta-out-95", 8, 95.0), ("sample-phi-out-720", 12, 720.0),
                              ("sample-r-inf", 16, float("inf")), ("sample-r-neg", 16, -3.0),
                              ("sample-theta-in-wrong", 0, 33.0)):
        p = bytearray(payload)
        struct.pack_into("<f", p, first + off, value)
        out.append((label, bpc_rewrite_chunk(data, s0[0], payload=bytes(p))))
    # Chunk framing: payload size larger/smaller than the data, slice indices out of order.
    out.append(("payload-size-huge", bpc_rewrite_chunk(data, s0[0], payload_size=1 << 62,
                                                       fix_payload_crc=False)))
    out.append(("payload-size-small", bpc_rewrite_chunk(data, s0[0], payload_size=s0[3] - 8,
                                                        fix_payload_crc=False)))
    out.append(("slice-index-dup", bpc_rewrite_chunk(data, slices[1][0], index=0)))
    out.append(("slice-index-skip", bpc_rewrite_chunk(data, slices[1][0], index=7)))
    out.append(("slice-index-huge", bpc_rewrite_chunk(data, slices[1][0], index=0xFFFFFFFE)))
    # Two slices claiming one θin.
    p1 = data[slices[1][0] + 24:slices[1][0] + 24 + slices[1][3]]
    p1 = payload[:8] + p1[8:]
    out.append(("slice-theta-dup", bpc_rewrite_chunk(data, slices[1][0], payload=p1)))
    # HEAD JSON with wrong types and a version mismatch.
    hj = json.loads(data[head[0] + 24:head[0] + 24 + head[3]])
    for label, mutate in (
            ("head-version", lambda j: j.__setitem__("version", [1, 7])),
            ("head-version-str", lambda j: j.__setitem__("version", "1.0")),
            ("head-metadata-num", lambda j: j["metadata"].__setitem__("sample_name", 3.5)),
            ("head-metadata-null", lambda j: j.__setitem__("metadata", None)),
            ("head-extra-nested", lambda j: j["metadata"].__setitem__("extra", {"a": {"b": 1}})),
            ("head-theta-plan-bad", lambda j: j["metadata"].setdefault("extra", {})
             .__setitem__("theta_in_deg", "0,abc,1e309")),
            ("head-array", lambda j: j.clear())):
        j = json.loads(json.dumps(hj))
        mutate(j)
        text = json.dumps(j).encode() if label != "head-array" else b"[1,2]"
        out.append((label, bpc_rewrite_chunk(data, head[0], payload=text)))
    # END chunk lying about counts, or with broken JSON.
    if end:
        e = end[0]
        ej = json.loads(data[e[0] + 24:e[0] + 24 + e[3]])
        for label, key, value in (("end-slices+1", "slice_count", ej.get("slice_count", 0) + 1),
                                  ("end-samples-1", "sample_count", ej.get("sample_count", 0) - 1),
                                  ("end-samples-neg", "sample_count", -5),
                                  ("end-samples-str", "sample_count", "many"),
                                  ("end-samples-1e309", "sample_count", 1e308 * 10)):
            j = dict(ej)
            j[key] = value
            text = json.dumps(j).replace("Infinity", "1e309").encode()
            out.append((label, bpc_rewrite_chunk(data, e[0], payload=text)))
        out.append(("end-not-json", bpc_rewrite_chunk(data, e[0], payload=b"{\"metadata\": ")))
        out.append(("unfinished", data[:e[0]]))
        out.append(("after-end", data + data[slices[0][0]:slices[0][0] + 24 + slices[0][3]]))
    out.append(("preamble-major2", data[:8] + struct.pack("<H", 2) + data[10:]))
    return out


def lies_ktx2(data):
    out = []
    # Header: identifier 12, vkFormat, typeSize, width, height, depth, layers, faces, levels,
    # supercompression (u32 each, from byte 12), then index u32 dfdOff, dfdLen, kvdOff, kvdLen,
    # u64 sgdOff, sgdLen, then the level index u64 byteOffset, byteLength, uncompressedLength.
    fields = {"width": 20, "height": 24, "depth": 28, "layers": 32, "faces": 36, "levels": 40,
              "dfd_len": 52, "kvd_off": 56, "kvd_len": 60}
    for name, off in fields.items():
        value = struct.unpack_from("<I", data, off)[0]
        for label, v in (("x2", value * 2), ("half", value // 2), ("0", 0), ("huge", 0xFFFFFFFF),
                         ("-1", 0xFFFFFFFF - 0)):
            if label == "-1":
                continue
            b = bytearray(data)
            struct.pack_into("<I", b, off, v & 0xFFFFFFFF)
            out.append((f"{name}-{label}", bytes(b)))
    for name, off in (("level-offset", 80), ("level-length", 88)):
        value = struct.unpack_from("<Q", data, off)[0]
        for label, v in (("x2", value * 2), ("half", value // 2), ("huge", (1 << 63) + 5)):
            b = bytearray(data)
            struct.pack_into("<Q", b, off, v)
            out.append((f"{name}-{label}", bytes(b)))
    return out


def lies_dds(data):
    out = []
    # "DDS " then DDS_HEADER: size 4, flags 8, height 12, width 16, pitch 20, depth 24, mips 28.
    for name, off in (("height", 12), ("width", 16), ("pitch", 20), ("depth", 24), ("mips", 28),
                      ("header-size", 4)):
        value = struct.unpack_from("<I", data, off)[0]
        for label, v in (("x2", value * 2), ("half", value // 2), ("0", 0), ("huge", 0xFFFFFFFF)):
            b = bytearray(data)
            struct.pack_into("<I", b, off, v & 0xFFFFFFFF)
            out.append((f"{name}-{label}", bytes(b)))
    if data[84:88] == b"DX10":
        for label, v in (("dxgi-0", 0), ("dxgi-2", 2), ("dxgi-huge", 0xFFFFFFFF)):
            b = bytearray(data)
            struct.pack_into("<I", b, 128, v)
            out.append((label, bytes(b)))
        for label, v in (("array-0", 0), ("array-9", 9), ("dim-2", 2)):
            b = bytearray(data)
            struct.pack_into("<I", b, 140 if "array" in label else 132, v)
            out.append((label, bytes(b)))
    return out


def lies_rgl(data):
    """tensor_file: magic 12, version 2 bytes, u32 field count, then per field u16 name length,
    name, u16 rank, u8 dtype, u64 offset, u64 per dimension."""
    out = []
    count = struct.unpack_from("<I", data, 14)[0]
    for label, v in (("fields+1", count + 1), ("fields-huge", 0xFFFFFFFF), ("fields0", 0)):
        out.append((label, data[:14] + struct.pack("<I", v) + data[18:]))
    pos = 18
    for _ in range(count):
        name_len = struct.unpack_from("<H", data, pos)[0]
        name = data[pos + 2:pos + 2 + name_len].decode("latin-1")
        p = pos + 2 + name_len
        rank, dtype = struct.unpack_from("<HB", data, p)
        offset_at = p + 3
        dims_at = offset_at + 8
        if name in ("rgb", "theta_i", "vndf", "ndf", "sigma", "phi_i"):
            for label, b in (
                    ("dtype-f64", data[:p + 2] + bytes((11,)) + data[p + 3:]),
                    ("dtype-99", data[:p + 2] + bytes((99,)) + data[p + 3:]),
                    ("rank0", data[:p] + struct.pack("<H", 0) + data[p + 2:]),
                    ("offset-huge", data[:offset_at] + struct.pack("<Q", 1 << 62) +
                     data[offset_at + 8:]),
                    ("offset-end", data[:offset_at] + struct.pack("<Q", len(data) - 4) +
                     data[offset_at + 8:])):
                out.append((f"{name}-{label}", b))
            if rank:
                dim = struct.unpack_from("<Q", data, dims_at)[0]
                for label, v in (("dim0-x2", dim * 2), ("dim0-0", 0), ("dim0-huge", 1 << 40),
                                 ("dim0-1", 1)):
                    out.append((f"{name}-{label}", data[:dims_at] + struct.pack("<Q", v) +
                                data[dims_at + 8:]))
        pos = dims_at + 8 * rank
    return out


def lies_merl(data):
    out = []
    for label, dims in (("dims-small", (90, 90, 90)), ("dims-neg", (-90, 90, 180)),
                        ("dims-huge", (1 << 30, 90, 180)), ("dims-zero", (0, 90, 180))):
        out.append((label, struct.pack("<3i", *dims) + data[12:]))
    # A NaN and a huge value among the data.
    b = bytearray(data)
    struct.pack_into("<d", b, 12 + 8 * 1000, float("nan"))
    struct.pack_into("<d", b, 12 + 8 * 2000, 1e300)
    out.append(("nan-and-huge-values", bytes(b)))
    return out


# Lie rules whose pattern matched nothing in their seed (label), filled while the variants are
# made: each is a finding (the rule no longer tests anything).
UNMATCHED_LIES = []
LIE_COUNTS = {}  # seed name: the number of lies its rules made (before max_lies sampling)


def text_lies(text, rules):
    """Applies regex substitutions (label, pattern, replacement) one at a time; a rule that
    matches nothing is recorded in UNMATCHED_LIES."""
    out = []
    for label, pattern, repl in rules:
        new, n = re.subn(pattern, repl, text, count=1, flags=re.M)
        if n:
            out.append((label, new.encode()))
        else:
            UNMATCHED_LIES.append(label)
    return out


def lies_zemax(data):
    t = data.decode("latin-1")
    return text_lies(t, [
        ("aoi-count+1", r"^(AngleOfIncidence\s+)(\d+)", lambda m: m[1] + str(int(m[2]) + 1)),
        ("aoi-count-1", r"^(AngleOfIncidence\s+)(\d+)", lambda m: m[1] + str(int(m[2]) - 1)),
        ("aoi-count-neg", r"^(AngleOfIncidence\s+)(\d+)", r"\g<1>-3"),
        ("aoi-count-huge", r"^(AngleOfIncidence\s+)(\d+)", r"\g<1>99999999999"),
        ("azimuth-count+1", r"^(ScatterAzimuth\s+)(\d+)", lambda m: m[1] + str(int(m[2]) + 1)),
        ("azimuth-count-1", r"^(ScatterAzimuth\s+)(\d+)", lambda m: m[1] + str(int(m[2]) - 1)),
        ("radial-count-huge", r"^(ScatterRadial\s+)(\d+)", r"\g<1>4000000000"),
        ("radial-count0", r"^(ScatterRadial\s+)(\d+)", r"\g<1>0"),
        ("rotation-count2", r"^(SampleRotation\s+)(\d+)", r"\g<1>2"),
        ("aoi-nan", r"^(AngleOfIncidence\s+\d+\s*\n)(\S+)", r"\1nan"),
        ("aoi-95", r"^(AngleOfIncidence\s+\d+\s*\n)(\S+)", r"\g<1>95"),
        ("value-word", r"^(DataBegin\s*\nTIS \S+\s*\n)(\S+)", r"\1abc"),
        ("value-1e309", r"^(DataBegin\s*\nTIS \S+\s*\n)(\S+)", r"\g<1>1e309"),
        ("value-neg", r"^(DataBegin\s*\nTIS \S+\s*\n)(\S+)", r"\g<1>-5"),
        ("tis-word", r"^(TIS )(\S+)", r"\1x"),
        ("no-dataend", r"^DataEnd.*$", ""),
        ("symmetry-bad", r"^(Symmetry\s+)(\S+)", r"\1Hexagonal"),
        ("scatter-brdf", r"^(ScatterType\s+)(\S+)", r"\1BRDF"),
    ])


def lies_lighttools(data):
    t = data.decode("latin-1")
    return text_lies(t, [
        ("azimuth-count+1", r"^(ScatterAzimuth )(\d+)", lambda m: m[1] + str(int(m[2]) + 1)),
        ("azimuth-count-1", r"^(ScatterAzimuth )(\d+)", lambda m: m[1] + str(int(m[2]) - 1)),
        ("azimuth-count-huge", r"^(ScatterAzimuth )(\d+)", r"\g<1>99999999999"),
        ("radial-count-neg", r"^(ScatterRadial )(\d+)", r"\g<1>-2"),
        ("radial-count0", r"^(ScatterRadial )(\d+)", r"\g<1>0"),
        ("aoi-nan", r"^(AOI )(\S+)", r"\1nan"),
        ("aoi-120", r"^(AOI )(\S+)", r"\g<1>120"),
        ("wavelength-word", r"^(Wavelength )(\S+)", r"\1blue"),
        ("channel-Q", r"^(TristimulusValue )(\S+)", r"\1Q"),
        ("value-1e309", r"^(TIS \S+\n)(\S+)", r"\g<1>1e309"),
        ("value-word", r"^(TIS \S+\n)(\S+)", r"\1abc"),
        ("side-back", r"^(Side )(\S+)", r"\1Back"),
        ("no-dataend", r"^DataEnd.*$", ""),
        ("radial-unsorted", r"^ScatterRadial 3 0 20 40", "ScatterRadial 3 40 20 0"),
    ])


def lies_csv(data):
    t = data.decode("latin-1")
    lines = t.split("\n")
    out = text_lies(t, [
        ("value-word", r"^([^#\n][^\n]*?\d),([-0-9.e+]+)$", r"\1,abc"),
        ("theta-nan", r"^(\d[-0-9.e]*),", "nan,"),
        ("theta-95", r"^(\d[-0-9.e]*),", "95,"),
        ("value-1e309", r"^(\d[^\n]*?),([-0-9.e+]+)(,|$)", r"\1,1e309\3"),
    ])
    header = lines[0]
    out.append(("header-missing", "\n".join(lines[1:]).encode()))
    out.append(("header-column-renamed", "\n".join([header.replace("theta", "tehta", 1)] +
                                                    lines[1:]).encode()))
    out.append(("row-short", "\n".join(lines[:2] + [lines[2].rsplit(",", 2)[0]] + lines[3:])
                .encode()))
    out.append(("row-long", "\n".join(lines[:2] + [lines[2] + ",1,2,3"] + lines[3:]).encode()))
    out.append(("crlf", t.replace("\n", "\r\n").encode()))
    out.append(("header-only", (header + "\n").encode()))
    return out


def lies_gonio(data):
    t = data.decode("latin-1")
    lines = t.split("\n")
    out = text_lies(t, [
        ("incidence-nan", r"^(\d+),", "nan,"),
        ("incidence-200", r"^(\d+),", "200,"),
        ("value-word", r"^(\d+,-?\d+,)([-0-9.e]+)", r"\1abc"),
        ("value-1e309", r"^(\d+,-?\d+,)([-0-9.e]+)", r"\g<1>1e309"),
        ("band-word", r"390nm", "purple"),
    ])
    out.append(("row-short", "\n".join(lines[:2] + [lines[2].rsplit(",", 5)[0]] + lines[3:])
                .encode()))
    out.append(("header-only", (lines[0] + "\n").encode()))
    return out


def lies_ply(data):
    t = data.decode("latin-1")
    is_binary = "binary" in t.split("end_header")[0]
    rules = [
        ("vertex-count+10", r"^(element vertex )(\d+)", lambda m: m[1] + str(int(m[2]) + 10)),
        ("vertex-count-1", r"^(element vertex )(\d+)", lambda m: m[1] + str(int(m[2]) - 1)),
        ("vertex-count-huge", r"^(element vertex )(\d+)", r"\g<1>4000000000"),
        ("vertex-count-neg", r"^(element vertex )(\d+)", r"\g<1>-4"),
        ("face-count-huge", r"^(element face )(\d+)", r"\g<1>99999999999"),
        ("face-count+1", r"^(element face )(\d+)", lambda m: m[1] + str(int(m[2]) + 1)),
        ("property-double", r"^property float x", "property double x"),
        ("property-unknown", r"^property float y", "property quaternion y"),
        ("format-big-endian", r"^format \S+", "format binary_big_endian"),
    ]
    if not is_binary:
        rules += [("index-out-of-range", r"^3 0 1 2$", "3 0 1 9"),
                  ("index-negative", r"^3 0 1 2$", "3 0 -1 2"),
                  ("list-count-huge", r"^3 0 1 2$", "200 0 1 2"),
                  ("coordinate-nan", r"^0 0 1$", "nan 0 1")]
    out = []
    if is_binary:
        head, body = data.split(b"end_header\n", 1)
        head_t = (head + b"end_header\n").decode()
        for label, pattern, repl in rules:
            new, n = re.subn(pattern, repl, head_t, count=1, flags=re.M)
            if n:
                out.append((label, new.encode() + body))
        faces = len(body) - 48
        b = bytearray(body)
        struct.pack_into("<i", b, 48 + 1 + 8, 1 << 30)
        out.append(("index-out-of-range", head + b"end_header\n" + bytes(b)))
        b = bytearray(body)
        b[48] = 255
        out.append(("list-count-255", head + b"end_header\n" + bytes(b)))
        del faces
    else:
        out += text_lies(t, rules)
    return out


def lies_obj(data):
    t = data.decode("latin-1")
    return text_lies(t, [
        ("index-out-of-range", r"^f 1 2 3$", "f 1 2 99"),
        ("index-zero", r"^f 1 2 3$", "f 0 2 3"),
        ("index-negative-far", r"^f 1 2 3$", "f -10 2 3"),
        ("index-huge", r"^f 1 2 3$", "f 1 2 99999999999999999999"),
        ("index-word", r"^f 1 2 3$", "f 1 b 3"),
        ("two-vertex-face", r"^f 1 2 3$", "f 1 2"),
        ("vertex-nan", r"^v 0 0 1$", "v nan 0 1"),
        ("vertex-short", r"^v 0 0 1$", "v 0 0"),
        ("normal-index-bad", r"^f 1 2 3$", "f 1//7 2//7 3//7"),
    ])


def lies_hdr(data):
    head, body = data.split(b"\n-Y ", 1)
    dims_line, pixels = body.split(b"\n", 1)
    h, _, w = dims_line.decode().split(" ")[0], None, dims_line.decode().split(" ")[2]
    out = []
    for label, line in (("height-x2", f"{int(h) * 2} +X {w}"), ("width-x2", f"{h} +X {int(w) * 2}"),
                        ("height-0", f"0 +X {w}"), ("height-neg", f"-{h} +X {w}"),
                        ("huge", f"1000000 +X 1000000"), ("orientation", f"{h} -X {w}"),
                        ("width-word", f"{h} +X wide")):
        out.append((label, head + b"\n-Y " + line.encode() + b"\n" + pixels))
    out.append(("format-xyz", data.replace(b"32-bit_rle_rgbe", b"32-bit_rle_xyze")))
    out.append(("no-magic", data.replace(b"#?RADIANCE", b"#?NOTHING!")))
    # A run-length scanline whose run overflows the row.
    rle = bytes((2, 2, 0, 16)) + bytes((200, 1)) * 4
    out.append(("rle-overflow", head + b"\n-Y " + dims_line + b"\n" + rle + pixels[len(rle):]))
    return out


def json_lies(data):
    """Wrong types in a JSON document: every numeric leaf (up to 6, seeded) replaced by a
    string, null, NaN, 1e309, -1e309, a nested object; arrays shortened and lengthened."""
    doc = json.loads(data)
    leaves = []

    def walk(node, path):
        if isinstance(node, dict):
            for k, v in node.items():
                walk(v, path + [k])
        elif isinstance(node, list):
            if node and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in node):
                leaves.append((path, "array"))
            for i, v in enumerate(node):
                walk(v, path + [i])
        elif isinstance(node, (int, float)) and not isinstance(node, bool):
            leaves.append((path, "number"))
        elif isinstance(node, str):
            leaves.append((path, "string"))

    walk(doc, [])
    rng = random.Random(SEED ^ len(data))
    numbers = [p for p in leaves if p[1] == "number"]
    arrays = [p for p in leaves if p[1] == "array"]
    strings = [p for p in leaves if p[1] == "string"]
    picked = sorted(rng.sample(numbers, min(6, len(numbers)))) if numbers else []
    out = []

    def replaced(path, value_text):
        copy = json.loads(data)
        node = copy
        for k in path[:-1]:
            node = node[k]
        node[path[-1]] = "@@VALUE@@"
        return json.dumps(copy).replace('"@@VALUE@@"', value_text).encode()

    def label_of(path):
        return ".".join(str(p) for p in path)[-40:]

    for path, _ in picked:
        for tag, text in (("str", '"12"'), ("null", "null"), ("nan", "NaN"), ("1e309", "1e309"),
                          ("-1e309", "-1e309"), ("obj", '{"value": 1}'), ("neg", "-1"),
                          ("huge", "1e300")):
            out.append((f"{label_of(path)}={tag}", replaced(path, text)))
    for path, _ in arrays[:4]:
        copy = json.loads(data)
        node = copy
        for k in path:
            node = node[k]
        n = len(node)
        for tag, text in (("short", json.dumps(node[:max(0, n - 1)])),
                          ("long", json.dumps(node + node[-1:] * 3)), ("empty", "[]"),
                          ("strings", json.dumps([str(x) for x in node]))):
            out.append((f"{label_of(path)}={tag}", replaced(path, text)))
    for path, _ in strings[:3]:
        out.append((f"{label_of(path)}=number", replaced(path, "7")))
        out.append((f"{label_of(path)}=array", replaced(path, "[1]")))
    if isinstance(doc, dict):
        for key in list(doc)[:6]:
            copy = dict(doc)
            del copy[key]
            out.append((f"without-{key}", json.dumps(copy).encode()))
        out.append(("top-array", json.dumps([doc]).encode()))
        out.append(("deep-nesting", (b"[" * 100000) + (b"]" * 100000)))
        out.append(("not-json", data[: len(data) // 2]))
    return out


# ---------------------------------------------------------------------------------------------
# Seeds and variants.

class Seed:
    def __init__(self, name, path, kind, commands, lies=None, header_end=None, binary=True,
                 companions=(), max_lies=None):
        self.name, self.path, self.kind, self.commands = name, path, kind, commands
        self.lies, self.header_end, self.binary = lies, header_end, binary
        self.companions = companions  # files copied beside every variant (texture, sidecar)
        self.max_lies = max_lies  # a seeded sample of the lies, to bound the run time


class Variant:
    def __init__(self, seed, label, path, special=False):
        self.seed, self.label, self.path, self.special = seed, label, path, special


READERS = ["info", "eval", "convert"]


def run_measured(tool, args, cwd, env=None):
    """(exit code or "timeout", stdout, stderr, CPU seconds, peak RSS bytes, wall seconds) of one
    run under the pass's limits: RLIMIT_AS, RLIMIT_CPU and the wall clock. CPU time (user +
    system) and peak RSS are the kernel's for that one child (wait4's rusage)."""
    def limits():
        resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE_BYTES, ADDRESS_SPACE_BYTES))
        # SIGXCPU at the soft limit, SIGKILL a second later (check_run names both).
        resource.setrlimit(resource.RLIMIT_CPU, (CPU_LIMIT_S, CPU_LIMIT_S + 1))
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
        os.setsid()

    start = time.monotonic()
    with tempfile.TemporaryFile() as out_f, tempfile.TemporaryFile() as err_f:
        proc = subprocess.Popen([tool] + args, cwd=cwd, stdin=subprocess.DEVNULL, stdout=out_f,
                                stderr=err_f, preexec_fn=limits, env=env)
        timed_out = []

        def kill():
            timed_out.append(True)
            try:
                os.killpg(proc.pid, 9)
            except ProcessLookupError:
                pass

        timer = threading.Timer(TIMEOUT_S, kill)
        timer.start()
        _, status, usage = os.wait4(proc.pid, 0)
        timer.cancel()
        proc.returncode = os.waitstatus_to_exitcode(status)  # reaped here, not by Popen
        out_f.seek(0)
        err_f.seek(0)
        code = "timeout" if timed_out else proc.returncode
        return (code, out_f.read().decode("utf-8", "replace"),
                err_f.read().decode("utf-8", "replace"), usage.ru_utime + usage.ru_stime,
                usage.ru_maxrss * 1024, time.monotonic() - start)


def run_tool(tool, args, cwd):
    """(exit code or "timeout", stdout, stderr, peak RSS bytes) of one run (run_measured)."""
    code, out, err, _, rss, _ = run_measured(tool, args, cwd)
    return code, out, err, rss


def must(tool, args, cwd):
    code, out, err, _ = run_tool(tool, args, cwd)
    if code != 0:
        raise SystemExit(f"hostile_inputs: seed command failed ({code}): brdf {' '.join(args)}\n"
                         f"{err}")
    return out


def make_seeds(tool, source_dir, data_dir, work):
    seeds_dir = os.path.join(work, "seeds")
    os.makedirs(seeds_dir)
    s = lambda name: os.path.join(seeds_dir, name)  # noqa: E731
    must(tool, ["capture", "--device", "sim", "--material", "gold", "--sample", "hostile",
                "--theta-in", "0,30,60", "--theta-out-step", "5", "--phi-out-step", "10",
                "--noise", "1", "--seed", "7", "--quiet", "--out", s("cap.bpc")], work)
    conv = os.path.join(work, "seed-convert")
    must(tool, ["convert", s("cap.bpc"), "--out", conv, "--quiet", "--formats",
                "ktx2,dds,exr,png,json"], work)
    for ext in ("ktx2", "dds", "exr", "png", "json"):
        shutil.copy(os.path.join(conv, "cap." + ext), s("lut." + ext))
    # The sidecar names its texture by file name: keep the copy consistent with its texture.
    side = json.load(open(s("lut.json")))
    text = json.dumps(side).replace("cap.ktx2", "lut.ktx2").replace("cap.dds", "lut.dds")
    open(s("lut.json"), "w").write(text)
    must(tool, ["export-csv", s("cap.bpc"), "--out", s("cap.csv")], work)
    must(tool, ["capture", "--device", "sim", "--material", "wood_oak", "--sample", "oak",
                "--theta-in", "0,30,60", "--theta-out-step", "5", "--phi-out-step", "10",
                "--noise", "0", "--quiet", "--out", os.path.join(work, "oak.bpc")], work)
    must(tool, ["atlas", s("cap.bpc"), os.path.join(work, "oak.bpc"), "--out", s("atlas"),
                "--quiet"], work)
    must(tool, ["fit", s("cap.bpc"), "--model", "lambert", "--starts", "1", "--quiet",
                "--out", s("fit.json")], work)
    for name in ("gold.json", "plastic_matte_blue.json"):
        shutil.copy(os.path.join(source_dir, "data-samples/materials", name), s(name))
    for rel, name in (("rgl/aurora_white_rgb.bsdf", "rgl.bsdf"),
                      ("zemax-imaging-sphere/test_13_planesymmetric_btdf_zemax.bsdf", "zemax.bsdf"),
                      ("goniometer-csv/test_brdf_viewer_2D_data.csv", "gonio.csv")):
        shutil.copy(os.path.join(data_dir, rel), s(name))
    write_merl(s("merl.binary"))
    write_lighttools(s("lt.bsdf"))
    write_ply_ascii(s("mesh_ascii.ply"))
    write_ply_binary(s("mesh_bin.ply"))
    write_obj(s("mesh.obj"))
    write_hdr(s("env.hdr"))
    write_exr_env(s("env.exr"))
    write_hdr_rle(s("env_rle.hdr"))
    write_exr_env(s("env_zip.exr"), 128, 64, "zip")

    bpc_head = bpc_chunks(open(s("cap.bpc"), "rb").read())[0]
    # convert reads captures and material files; third-party tables are imported first.
    measure = ["info", "eval", "convert", "fit", "preview", "atlas"]
    tables = ["info", "eval", "fit", "preview"]
    seeds = [
        Seed("cap.bpc", s("cap.bpc"), "capture",
             measure + ["repair", "export-csv", "resume"], lies_bpc,
             header_end=bpc_head[0] + 24 + bpc_head[3]),
        Seed("lut.ktx2", s("lut.ktx2"), "ktx2", ["info", "eval", "atlas", "preview"],
             lies_ktx2, header_end=104),
        Seed("lut.dds", s("lut.dds"), "dds", ["info", "eval", "atlas", "preview"],
             lies_dds, header_end=148, companions=("lut.json",)),
        Seed("lut.json", s("lut.json"), "sidecar", ["info", "eval", "atlas"], json_lies,
             binary=False, companions=("lut.ktx2", "lut.dds"), max_lies=40),
        Seed("atlas.json", s("atlas.json"), "manifest", ["info", "eval", "atlas"], json_lies,
             binary=False, companions=("atlas.ktx2",), max_lies=25),
        Seed("atlas.ktx2", s("atlas.ktx2"), "ktx2-atlas", ["info", "eval", "atlas"], lies_ktx2,
             header_end=104, max_lies=15),
        Seed("lut.exr", s("lut.exr"), "exr", ["info", "eval"], None, header_end=300),
        Seed("lut.png", s("lut.png"), "png", ["info", "eval"], None, header_end=33),
        Seed("gold.json", s("gold.json"), "material", measure, json_lies, binary=False),
        Seed("plastic_matte_blue.json", s("plastic_matte_blue.json"), "material",
             ["info", "eval", "convert"], json_lies, binary=False, max_lies=20),
        Seed("fit.json", s("fit.json"), "material", ["info", "eval", "convert"], json_lies,
             binary=False, max_lies=20),
        Seed("cap.csv", s("cap.csv"), "csv", tables + ["import"], lies_csv, binary=False),
        Seed("rgl.bsdf", s("rgl.bsdf"), "rgl", tables + ["import"], lies_rgl, header_end=400,
             max_lies=30),
        Seed("merl.binary", s("merl.binary"), "merl", ["info", "eval", "import"], lies_merl,
             header_end=12),
        Seed("zemax.bsdf", s("zemax.bsdf"), "zemax", ["info", "eval", "import"],
             lies_zemax, binary=False),
        Seed("lt.bsdf", s("lt.bsdf"), "lighttools", ["info", "eval", "import"],
             lies_lighttools, binary=False),
        Seed("gonio.csv", s("gonio.csv"), "gonio", ["info", "eval", "import"],
             lies_gonio, binary=False),
        Seed("mesh_ascii.ply", s("mesh_ascii.ply"), "mesh", ["mesh", "info"], lies_ply,
             binary=False),
        Seed("mesh_bin.ply", s("mesh_bin.ply"), "mesh", ["mesh"], lies_ply, header_end=200),
        Seed("mesh.obj", s("mesh.obj"), "mesh", ["mesh", "info"], lies_obj, binary=False),
        Seed("env.hdr", s("env.hdr"), "env", ["env", "info"], lies_hdr, header_end=60),
        Seed("env.exr", s("env.exr"), "env", ["env", "info"], None, header_end=300),
        Seed("env_rle.hdr", s("env_rle.hdr"), "env", ["env"], lies_hdr, header_end=60),
        Seed("env_zip.exr", s("env_zip.exr"), "env", ["env"], None, header_end=300),
    ]
    return seeds


def make_variants(seeds, work):
    vdir = os.path.join(work, "variants")
    os.makedirs(vdir)
    variants = []
    by_kind = {}
    for seed in seeds:
        by_kind.setdefault(seed.kind, seed)

    def add(seed, label, data):
        stem, ext = os.path.splitext(seed.name)
        safe = re.sub(r"[^A-Za-z0-9_.+=-]", "_", label)
        folder = os.path.join(vdir, f"{stem}-{len(variants):04d}")
        os.makedirs(folder)
        path = os.path.join(folder, f"{stem}.{safe}{ext}"[:120] if len(safe) < 80 else
                            f"{stem}.v{len(variants)}{ext}")
        if seed.kind in ("ktx2", "dds", "ktx2-atlas") and "sidecar" not in label:
            # A texture is read with its sidecar/manifest only under the seed's own name.
            path = os.path.join(folder, seed.name)
        with open(path, "wb") as f:
            f.write(data)
        for companion in seed.companions:
            shutil.copy(os.path.join(os.path.dirname(seed.path), companion),
                        os.path.join(folder, companion))
        if seed.companions and seed.kind in ("sidecar", "manifest"):
            # A sidecar or manifest is found by its texture's name: keep the seed's name.
            os.rename(path, os.path.join(folder, seed.name))
            path = os.path.join(folder, seed.name)
        variants.append(Variant(seed, label, path))

    for seed in seeds:
        data = open(seed.path, "rb").read()
        rng = random.Random(f"{SEED}:{seed.name}")
        add(seed, "valid", data)
        cuts = [0, 1, len(data) // 2, len(data) - 1]
        if seed.header_end and seed.header_end < len(data):
            cuts += [seed.header_end, seed.header_end - 1]
        if not seed.binary:
            nl = data.find(b"\n", len(data) // 3)
            if nl > 0:
                cuts.append(nl + 1)
        for cut in sorted(set(cuts)):
            add(seed, f"cut{cut}", data[:cut])
        limit = seed.header_end or min(len(data), 256)
        for i in range(4 if len(data) < 1_000_000 else 2):
            b = bytearray(data)
            region = limit if i < 2 else len(data)
            for _ in range(1 + i):
                pos = rng.randrange(region)
                b[pos] ^= 1 << rng.randrange(8)
            add(seed, f"flip{i}", bytes(b))
        if seed.lies:
            lies = seed.lies(data)
            LIE_COUNTS[seed.name] = len(lies)
            if seed.max_lies is not None and len(lies) > seed.max_lies:
                keep = set(rng.sample(range(len(lies)), seed.max_lies))
                lies = [lie for i, lie in enumerate(lies) if i in keep]
            for label, lie in lies:
                add(seed, label, lie)
    # Wrong types: one format's bytes under another's name (each kind once, seeded pairs).
    names = [s for s in seeds if s.kind not in ("env", "mesh")]
    rng = random.Random(SEED)
    for seed in seeds:
        for other in rng.sample([s for s in seeds if s.kind != seed.kind], 2):
            data = open(other.path, "rb").read()
            if len(data) > 2_000_000:
                data = data[:2_000_000]
            add(seed, f"bytes-of-{other.name}", data)
    del names
    # Special files.
    special = os.path.join(vdir, "special")
    os.makedirs(special)
    cap = by_kind["capture"]
    for name in ("fifo.bpc", "fifo.json", "fifo.ktx2", "fifo.ply", "fifo.hdr", "fifo.csv"):
        os.mkfifo(os.path.join(special, name))
        kind_seed = {"bpc": cap, "json": by_kind["material"], "ktx2": by_kind["ktx2"],
                     "ply": by_kind["mesh"], "hdr": by_kind["env"], "csv": by_kind["csv"]}[
            name.split(".")[1]]
        variants.append(Variant(kind_seed, "fifo", os.path.join(special, name), special=True))
    folder = os.path.join(special, "folder.bpc")
    os.makedirs(folder)
    variants.append(Variant(cap, "folder", folder, special=True))
    for dev in ("/dev/zero", "/dev/null"):
        variants.append(Variant(cap, dev, dev, special=True))
        variants.append(Variant(by_kind["mesh"], dev, dev, special=True))
        variants.append(Variant(by_kind["env"], dev, dev, special=True))
    sparse = os.path.join(special, "sparse.bpc")
    with open(sparse, "wb") as f:
        f.write(open(cap.path, "rb").read())
        f.truncate(3 << 30)
    variants.append(Variant(cap, "sparse-3GiB", sparse, special=True))
    sparse_json = os.path.join(special, "sparse.json")
    with open(sparse_json, "wb") as f:
        f.write(open(by_kind["material"].path, "rb").read())
        f.truncate(3 << 30)
    variants.append(Variant(by_kind["material"], "sparse-3GiB", sparse_json, special=True))
    return variants


# ---------------------------------------------------------------------------------------------
# Commands and checks.

def command_lines(variant, work, index, source_dir):
    """[(command, args)] to run on `variant`; fit, preview, atlas, resume on a deterministic
    subset (every 4th, 4th and 3rd variant of a seed)."""
    p = variant.path
    out = os.path.join(work, "out", f"{index:04d}")
    os.makedirs(out, exist_ok=True)
    gold = os.path.join(source_dir, "data-samples/materials/gold.json")
    wanted = variant.seed.commands
    # The seed's valid file (the positive control) runs every command of the seed.
    sub = index % 12 if variant.label != "valid" else None
    cmds = []
    if "info" in wanted:
        cmds.append(("info", ["info", p, "--json"]))
    if "eval" in wanted:
        cmds.append(("eval", ["eval", p, "--in", "30,0", "--out", "30,180"]))
    if "convert" in wanted:
        cmds.append(("convert", ["convert", p, "--quiet", "--formats", "json,ktx2", "--out",
                                 os.path.join(out, "conv")]))
    if "import" in wanted:
        cmds.append(("import", ["import", p, "--allow-btdf", "--out", os.path.join(out, "i.bpc")]))
    if "repair" in wanted:
        cmds.append(("repair", ["repair", p, "--out", os.path.join(out, "r.bpc")]))
    if "export-csv" in wanted:
        cmds.append(("export-csv", ["export-csv", p, "--out", os.path.join(out, "e.csv")]))
    if "fit" in wanted and sub in (None, 0, 6):
        cmds.append(("fit", ["fit", p, "--model", "lambert", "--starts", "1", "--quiet", "--jobs",
                             "1", "--out", os.path.join(out, "f.json")]))
    if "preview" in wanted and sub in (None, 1, 7):
        cmds.append(("preview", ["preview", p, "--size", "32", "--spp", "1", "--jobs", "1",
                                 "--quiet", "--out", os.path.join(out, "p.png")]))
    if "atlas" in wanted and sub in (None, 2, 5, 8, 11):
        cmds.append(("atlas", ["atlas", p, "--quiet", "--jobs", "1", "--out",
                               os.path.join(out, "atlas")]))
    if "resume" in wanted and sub in (None, 3, 9):
        # The resume copies the variant first: capture --resume appends to its --out.
        target = os.path.join(out, "resume.bpc")
        if not variant.special:
            shutil.copy(p, target)
        else:
            target = p
        cmds.append(("resume", ["capture", "--device", "sim", "--material", "gold", "--sample",
                                "hostile", "--theta-in", "0,30,60", "--theta-out-step", "5",
                                "--phi-out-step", "10", "--noise", "1", "--seed", "7",
                                "--sim-pace-ms", "0", "--quiet", "--resume", "--out", target]))
    if "mesh" in wanted:
        cmds.append(("preview-mesh", ["preview", gold, "--mesh", p, "--size", "32", "--spp", "1",
                                      "--jobs", "1", "--quiet", "--out",
                                      os.path.join(out, "m.png")]))
    if "env" in wanted:
        cmds.append(("preview-env", ["preview", gold, "--env", p, "--size", "32", "--spp", "1",
                                     "--jobs", "1", "--quiet", "--out",
                                     os.path.join(out, "v.png")]))
    return cmds


# The positive control's exceptions: (seed kind, command) pairs whose answer to an intact file
# is a refusal by design, with the words the refusal must contain. Any other refusal of a
# seed's valid file is a finding.
VALID_REFUSALS = {
    ("capture", "repair"): "nothing to repair",             # intact: repair has nothing to do
    ("manifest", "eval"): "holds many materials",            # atlases are evaluated per material
    ("ktx2-atlas", "eval"): "holds many materials",
    ("manifest", "atlas"): "got a atlas manifest",           # an atlas is not an atlas input
    ("ktx2-atlas", "atlas"): "an atlas, not a single material's LUT",
    ("exr", "info"): "a file of unknown type",               # images, meshes and maps are
    ("png", "info"): "a file of unknown type",               # not BRDF files
    ("exr", "eval"): "cannot evaluate a file of unknown type",
    ("png", "eval"): "cannot evaluate a file of unknown type",
    ("mesh", "info"): "a file of unknown type",
    ("env", "info"): "a file of unknown type",
}


def position_expected(variant, command):
    """Whether a refusal of this damaged file must name a position (byte/line/field)."""
    if (variant.special or variant.label.startswith("bytes-of") or variant.label == "cut0" or
            variant.label == "valid"):
        return False
    return command in ("info", "eval", "import", "repair", "export-csv", "preview-mesh",
                       "preview-env")


# Words that say where in a file: a byte, line, column or offset; a scanline, record or the
# header; a named part (member, chunk, field, level, slice, row, sample, block, entry, face,
# vertex, element, key, cell, texel, grid, sidecar, the file's size or content, the image size);
# a quoted name, a JSON path or an index.
POSITION_WORDS = re.compile(
    r"\b(bytes?|line|column|offset|scanline|record|header|member|chunk|field|level|slices?|rows?|"
    r"samples?|block|entry|faces?|vertex|element|key|part|cell|texel|grid|sidecar|size|"
    r"content)\b|\"[^\"]+\"|'[^']+'|\$\.|\[\d+\]")
# Refusals that are answers about the whole file, not errors at a place in it: a file no reader
# recognises, an intact capture `repair` has nothing to do for.
WHOLE_FILE_ANSWERS = re.compile(r"a (?:JSON )?file of unknown (?:type|purpose)|nothing to repair")
# Position-less messages known and left to their own fix (each one line of docs/robustness.md),
# so that the check stays strict for everything else.
KNOWN_POSITIONLESS = [
    # A capture whose slices repeat a θin: "values: expected values a LUT can be built from"
    # names no slice before "expected" (the slices follow in the text).
    re.compile(r": values: expected values a LUT can be built from, got .*duplicate incidence"),
]


def has_position(err, name):
    """A format error reads "FILE[ (part)]: POSITION: expected X, got Y". The position is the
    text between the file name and "expected" and must say where (POSITION_WORDS). A message
    without "expected" must say where anywhere, unless it is an answer about the whole file
    (WHOLE_FILE_ANSWERS). False otherwise (and for a message that does not name the file)."""
    at = err.find(name)
    if at < 0:
        return False
    rest = err[at + len(name):].split("\n")[0]
    if any(k.search(rest) for k in KNOWN_POSITIONLESS):
        return True
    m = re.match(r"((?: \([^)]*\))?: .*?)\bexpected\b", rest)
    if m:
        return POSITION_WORDS.search(m.group(1)) is not None
    return WHOLE_FILE_ANSWERS.search(rest) is not None or POSITION_WORDS.search(rest) is not None


def check_run(variant, command, code, out, err, findings):
    where = f"{variant.seed.name} [{variant.label}] {command}"
    if code == "timeout":
        findings.append(f"{where}: timed out after {TIMEOUT_S} s")
        return
    if code in (-signal.SIGXCPU, -signal.SIGKILL):
        findings.append(f"{where}: used more than {CPU_LIMIT_S} s of CPU time")
        return
    if isinstance(code, int) and code < 0:
        findings.append(f"{where}: killed by signal {-code}; stderr: {err.strip()[:300]}")
        return
    if variant.label == "valid" and code != 0:
        expected = VALID_REFUSALS.get((variant.seed.kind, command))
        if expected is None or expected not in err:
            findings.append(f"{where}: the seed's valid file is refused (exit {code}): "
                            f"{err.strip()[:300]}")
    if code not in (0, 1, 2):
        findings.append(f"{where}: exit code {code}; stderr: {err.strip()[:300]}")
    for what, pattern in FORBIDDEN:
        m = pattern.search(err)
        if m:
            findings.append(f"{where}: {what} '{m.group(0)}' in stderr: {err.strip()[:300]}")
    if code != 0:
        lines = [line for line in err.split("\n") if line.strip()]
        if len(lines) != 1:
            findings.append(f"{where}: failed with {len(lines)} stderr lines (want 1): "
                            f"{err.strip()[:400]!r}")
        name = os.path.basename(variant.path)
        if command == "resume" and not variant.special:
            name = "resume.bpc"  # the copy the resume appends to
        if variant.path not in err and name not in err:
            findings.append(f"{where}: error does not name the file: {err.strip()[:300]}")
        if "valid JSON" in err and not re.search(r"line \d+, column \d+", err):
            findings.append(f"{where}: JSON error without line and column: {err.strip()[:300]}")
        if position_expected(variant, command) and code == 1 and not has_position(err, name):
            findings.append(f"{where}: error names no position: {err.strip()[:300]}")
        # Environment maps: the position in the file's terms (byte, header line, scanline or
        # the header's image size), and no decoder library's words.
        if command == "preview-env" and code == 1 and not variant.special:
            if not re.search(r"\b(byte|line|scanline|header|image size)\b", err):
                findings.append(f"{where}: map error names no byte, line or scanline: "
                                f"{err.strip()[:300]}")
            if re.search(r"OpenImageIO|OpenEXR image|Iex|Imf", err):
                findings.append(f"{where}: map error in a decoder's words: {err.strip()[:300]}")
    if command == "eval" and code == 0:
        values = re.findall(r"[-+]?(?:nan|inf|\d[\d.e+-]*)", out, re.I)
        if any(v.lower().lstrip("+-") in ("nan", "inf") for v in values):
            findings.append(f"{where}: eval printed a non-finite value: {out.strip()[:200]}")


def theta_list_of_info(info_out):
    try:
        doc = json.loads(info_out)
    except ValueError:
        return None
    for key in ("theta_in_deg", "measured_theta_in_deg"):
        if isinstance(doc, dict) and isinstance(doc.get(key), list):
            return [round(float(x), 6) for x in doc[key]]
    slices = doc.get("slices") if isinstance(doc, dict) else None
    if isinstance(slices, list) and slices and isinstance(slices[0], dict):
        values = [s.get("theta_in_deg") for s in slices]
        if all(isinstance(v, (int, float)) for v in values):
            return sorted(round(float(v), 6) for v in values)
    return None


def check_agreement(variant, results, work, index, findings):
    where = f"{variant.seed.name} [{variant.label}]"
    info = results.get("info")
    if info is None or variant.seed.kind in ("mesh", "env", "exr", "png"):
        return
    code, out, err = info
    warned = "warning" in err.lower()
    doc = {}
    try:
        doc = json.loads(out)
        warned = warned or bool(doc.get("warnings")) or bool(doc.get("physical_problems"))
    except (ValueError, AttributeError):
        pass
    # What info says the file is decides which commands apply (the content, not the name):
    # convert reads captures and material files, eval everything but atlases.
    applies = {"eval": doc.get("format") != "atlas",
               "convert": doc.get("format") in ("bpc", "material") or code != 0}
    for other in ("eval", "convert"):
        if other not in results or not applies[other]:
            continue
        ocode, _, oerr = results[other]
        if not isinstance(code, int) or not isinstance(ocode, int):
            continue
        # A capture refused by the LUT exports alone (θin not k·Δin: "evaluable" true,
        # "convertible" false) is evaluated by eval by design (docs/robustness.md).
        export_only = doc.get("evaluable") is True and doc.get("convertible") is False
        if code != 0 and ocode == 0 and not (other == "eval" and export_only):
            findings.append(f"{where}: info refuses (exit {code}: {err.strip()[:200]}) but "
                            f"{other} accepts it")
        if code == 0 and ocode != 0 and not warned:
            findings.append(f"{where}: info accepts it without a warning but {other} refuses: "
                            f"{oerr.strip()[:250]}")
    # The capture-only commands: export-csv copies what info accepts (unless CSV cannot hold a
    # value), and repair acts on what info says to repair.
    csv = results.get("export-csv")
    if csv and code == 0 and doc.get("format") == "bpc" and csv[0] != 0 and "CSV" not in csv[2]:
        findings.append(f"{where}: info accepts it but export-csv refuses: {csv[2].strip()[:250]}")
    repair = results.get("repair")
    if repair and "brdf repair" in out and "nothing to repair" in repair[2]:
        findings.append(f"{where}: info advises 'brdf repair' but repair finds nothing to repair")
    if code == 0 and results.get("convert", (None,))[0] == 0:
        sidecar = os.path.join(work, "out", f"{index:04d}", "conv",
                               os.path.splitext(os.path.basename(variant.path))[0] + ".json")
        info_theta = theta_list_of_info(out)
        try:
            recorded = json.load(open(sidecar))
            # With the blind-spot fill the LUT's slices are the measured ones plus filled ones;
            # the sidecar's "beyond" record lists the measured θin, which is what info reports.
            beyond = recorded.get("beyond")
            measured = beyond.get("measured_theta_in") if isinstance(beyond, dict) else None
            conv_theta = [round(float(x), 6)
                          for x in (measured if measured is not None else recorded["theta_in_deg"])]
        except (OSError, ValueError, KeyError, TypeError):
            findings.append(f"{where}: convert succeeded but its sidecar {sidecar} is unreadable")
            return
        if info_theta is None and doc.get("format") != "material":
            # (A material file has no θin of its own: convert samples it at the reference
            # instrument's, so there is nothing of info's to compare.)
            findings.append(f"{where}: the θin check was skipped: info --json accepted the file "
                            f"but gives no θin list to compare with convert's sidecar")
        elif info_theta is not None and info_theta != conv_theta:
            findings.append(f"{where}: info reports θin {info_theta}, convert's sidecar "
                            f"{conv_theta}")
        # Saturated samples per slice: info's flag counts against the sidecar's record.
        side = json.load(open(sidecar))
        if isinstance(doc.get("slices"), list) and isinstance(side.get("saturated_samples"), list):
            info_sat = sorted((round(float(x["theta_in_deg"]), 6), x["flag_counts"]["saturated"])
                              for x in doc["slices"])
            side_sat = sorted((round(float(x["theta_in_deg"]), 6), x["count"])
                              for x in side["saturated_samples"])
            if info_sat != side_sat:
                findings.append(f"{where}: info counts saturated samples {info_sat}, convert's "
                                f"sidecar {side_sat}")
    if code == 0 and csv and csv[0] == 0 and isinstance(doc.get("sample_count"), int):
        rows = sum(1 for line in open(os.path.join(work, "out", f"{index:04d}", "e.csv"))
                   if line[:1].isdigit())
        if rows != doc["sample_count"]:
            findings.append(f"{where}: info reports {doc['sample_count']} samples, export-csv "
                            f"wrote {rows}")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("tool")
    parser.add_argument("source_dir")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--keep", action="store_true", help="keep the work folder")
    parser.add_argument("--only", default="", help="regex over 'seed [label]'")
    parser.add_argument("--list", action="store_true", help="list variants and exit")
    parser.add_argument("--table", action="store_true",
                        help="print each file's exit codes and first stderr line")
    parser.add_argument("--data-default", default="",
                        help="the build's BRDF_DATA_DIR, used when the variable is not set")
    parser.add_argument("--viewer", default="",
                        help="brdf-view, which then reads the value classes too")
    parser.add_argument("--python-path", default="",
                        help="the folder holding the Python module brdf: its brdf.preview reads "
                             "the bad-texel maps too")
    args = parser.parse_args()
    data_dir = (os.environ.get("BRDF_DATA_DIR") or args.data_default or
                os.path.join(args.source_dir, "..", "shared", "brdf-data"))
    if not os.path.isdir(os.path.join(data_dir, "rgl")):
        raise SystemExit(f"hostile_inputs: third-party data not found at {data_dir}: set "
                         f"BRDF_DATA_DIR to the brdf-data folder")
    start = time.monotonic()
    work = tempfile.mkdtemp(prefix="brdf-hostile-")
    try:
        env_dir = os.path.join(work, "home")
        os.makedirs(env_dir)
        seeds = make_seeds(args.tool, args.source_dir, data_dir, work)
        variants = make_variants(seeds, work)
        selected = [(i, v) for i, v in enumerate(variants)
                    if re.search(args.only, f"{v.seed.name} [{v.label}]")]
        if args.list:
            for i, v in selected:
                print(i, v.seed.name, v.label, v.path)
            return 0
        findings = []
        runs = 0
        counts = {}

        def one(item):
            i, v = item
            results, local = {}, []
            for command, cmd in command_lines(v, work, i, args.source_dir):
                code, out, err, rss = run_tool(args.tool, cmd, work)
                results[command] = (code, out, err)
                check_run(v, command, code, out, err, local)
                if rss > PEAK_RSS_BYTES:
                    local.append(f"{v.seed.name} [{v.label}] {command}: peak RSS "
                                 f"{rss / 2**20:.0f} MiB > {PEAK_RSS_BYTES / 2**20:.0f} MiB")
            check_agreement(v, results, work, i, local)
            return v, results, local

        with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
            for v, results, local in pool.map(one, selected):
                runs += len(results)
                for command in results:
                    counts[command] = counts.get(command, 0) + 1
                findings += local
                if args.table:
                    codes = " ".join(f"{c}={r[0]}" for c, r in results.items())
                    first = next((r[2].strip().split("\n")[0] for r in results.values() if r[2].strip()), "")
                    print(f"{v.seed.name} [{v.label}] {codes} | {first[:200]}")
        findings += [f"lie rule '{label}' matches nothing in its seed: it tests nothing"
                     for label in UNMATCHED_LIES]
        lie_files = sum(1 for _, v in selected if v.label != "valid" and not v.special)
        # The value classes (tests/tools/hostile_values.py): one verdict per file across the
        # commands for values no material has, under-determined fits and odd θin lists.
        if re.search(args.only, "value class"):
            import hostile_values
            value_findings, value_runs, value_counts = hostile_values.run(
                args.tool, os.path.join(work, "seeds"), work, args.table, args.python_path,
                args.viewer)
            findings += value_findings
            runs += value_runs
            for command, n in value_counts.items():
                counts["values " + command] = counts.get("values " + command, 0) + n
        for f in findings:
            print("FINDING:", f)
        print("hostile_inputs: lies per seed: " +
              ", ".join(f"{k} {n}" for k, n in sorted(LIE_COUNTS.items())) +
              f"; {lie_files} damaged files run")
        print(f"hostile_inputs: {len(seeds)} seeds, {len(selected)} files, {runs} runs "
              f"({', '.join(f'{k} {n}' for k, n in sorted(counts.items()))}), "
              f"{len(findings)} findings, {time.monotonic() - start:.1f} s")
        return 1 if findings else 0
    finally:
        if args.keep:
            print("work folder kept:", work)
        else:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
