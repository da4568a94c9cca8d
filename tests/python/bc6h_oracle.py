"""A BC6H_UF16 decoder written from the specification, for checking the library's encoder.

Source: the BPTC_FLOAT section of the OpenGL extension ARB_texture_compression_bptc (the same
format Microsoft documents as "BC6H Format"), unsigned variant. Written independently of
export/src/bc6h.cpp: the block is unpacked to a bit array with numpy, each mode is a list of
(variable, high bit, low bit) runs typed in from Table.F, and all arithmetic is on Python ints.

decode_block(b) -> list of 16 [r, g, b] half-float bit patterns (texel y*4 + x)
decode_volume(data, width, height, depth) -> float32 array [depth, height, width, 3]
read_ktx2_bc6h(path) -> (width, height, depth, level bytes, key/value dict)
"""

import struct

import numpy as np

# Table.MF: mode number -> (transformed, partition bits, endpoint bits, delta bits R, G, B)
MODES = {
    0: (True, 5, 10, (5, 5, 5)),
    1: (True, 5, 7, (6, 6, 6)),
    2: (True, 5, 11, (5, 4, 4)),
    6: (True, 5, 11, (4, 5, 4)),
    10: (True, 5, 11, (4, 4, 5)),
    14: (True, 5, 9, (5, 5, 5)),
    18: (True, 5, 8, (6, 5, 5)),
    22: (True, 5, 8, (5, 6, 5)),
    26: (True, 5, 8, (5, 5, 6)),
    30: (False, 5, 6, (6, 6, 6)),
    3: (False, 0, 10, (10, 10, 10)),
    7: (True, 0, 11, (9, 9, 9)),
    11: (True, 0, 12, (8, 8, 8)),
    15: (True, 0, 16, (4, 4, 4)),
}

# Table.F, typed in as the specification prints it (LSB of the block first). Each entry
# "v[a:b]" fills bits b..a of v in block order; a < b is the reversed form (bits b, b-1, .., a).
TABLE_F = {
    0: "m[1:0],g2[4],b2[4],b3[4],r0[9:0],g0[9:0],b0[9:0],r1[4:0],g3[4],g2[3:0],g1[4:0],b3[0],"
       "g3[3:0],b1[4:0],b3[1],b2[3:0],r2[4:0],b3[2],r3[4:0],b3[3]",
    1: "m[1:0],g2[5],g3[4],g3[5],r0[6:0],b3[0],b3[1],b2[4],g0[6:0],b2[5],b3[2],g2[4],b0[6:0],"
       "b3[3],b3[5],b3[4],r1[5:0],g2[3:0],g1[5:0],g3[3:0],b1[5:0],b2[3:0],r2[5:0],r3[5:0]",
    2: "m[4:0],r0[9:0],g0[9:0],b0[9:0],r1[4:0],r0[10],g2[3:0],g1[3:0],g0[10],b3[0],g3[3:0],"
       "b1[3:0],b0[10],b3[1],b2[3:0],r2[4:0],b3[2],r3[4:0],b3[3]",
    6: "m[4:0],r0[9:0],g0[9:0],b0[9:0],r1[3:0],r0[10],g3[4],g2[3:0],g1[4:0],g0[10],g3[3:0],"
       "b1[3:0],b0[10],b3[1],b2[3:0],r2[3:0],b3[0],b3[2],r3[3:0],g2[4],b3[3]",
    10: "m[4:0],r0[9:0],g0[9:0],b0[9:0],r1[3:0],r0[10],b2[4],g2[3:0],g1[3:0],g0[10],b3[0],"
        "g3[3:0],b1[4:0],b0[10],b2[3:0],r2[3:0],b3[1],b3[2],r3[3:0],b3[4],b3[3]",
    14: "m[4:0],r0[8:0],b2[4],g0[8:0],g2[4],b0[8:0],b3[4],r1[4:0],g3[4],g2[3:0],g1[4:0],b3[0],"
        "g3[3:0],b1[4:0],b3[1],b2[3:0],r2[4:0],b3[2],r3[4:0],b3[3]",
    18: "m[4:0],r0[7:0],g3[4],b2[4],g0[7:0],b3[2],g2[4],b0[7:0],b3[3],b3[4],r1[5:0],g2[3:0],"
        "g1[4:0],b3[0],g3[3:0],b1[4:0],b3[1],b2[3:0],r2[5:0],r3[5:0]",
    22: "m[4:0],r0[7:0],b3[0],b2[4],g0[7:0],g2[5],g2[4],b0[7:0],g3[5],b3[4],r1[4:0],g3[4],"
        "g2[3:0],g1[5:0],g3[3:0],b1[4:0],b3[1],b2[3:0],r2[4:0],b3[2],r3[4:0],b3[3]",
    26: "m[4:0],r0[7:0],b3[1],b2[4],g0[7:0],b2[5],g2[4],b0[7:0],b3[5],b3[4],r1[4:0],g3[4],"
        "g2[3:0],g1[4:0],b3[0],g3[3:0],b1[5:0],b2[3:0],r2[4:0],b3[2],r3[4:0],b3[3]",
    30: "m[4:0],r0[5:0],g3[4],b3[0],b3[1],b2[4],g0[5:0],g2[5],b2[5],b3[2],g2[4],b0[5:0],g3[5],"
        "b3[3],b3[5],b3[4],r1[5:0],g2[3:0],g1[5:0],g3[3:0],b1[5:0],b2[3:0],r2[5:0],r3[5:0]",
    3: "m[4:0],r0[9:0],g0[9:0],b0[9:0],r1[9:0],g1[9:0],b1[9:0]",
    7: "m[4:0],r0[9:0],g0[9:0],b0[9:0],r1[8:0],r0[10],g1[8:0],g0[10],b1[8:0],b0[10]",
    11: "m[4:0],r0[9:0],g0[9:0],b0[9:0],r1[7:0],r0[10:11],g1[7:0],g0[10:11],b1[7:0],b0[10:11]",
    15: "m[4:0],r0[9:0],g0[9:0],b0[9:0],r1[3:0],r0[10:15],g1[3:0],g0[10:15],b1[3:0],b0[10:15]",
}

# Table.P2 rows 0..31 (subset of each texel, x fastest) and Table.A2 (second subset's anchor).
P2 = [
    "0011001100110011", "0001000100010001", "0111011101110111", "0001001100110111",
    "0000000100010011", "0011011101111111", "0001001101111111", "0000000100110111",
    "0000000000010011", "0011011111111111", "0000000101111111", "0000000000010111",
    "0001011111111111", "0000000011111111", "0000111111111111", "0000000000001111",
    "0000100011101111", "0111000100000000", "0000000010001110", "0111001100010000",
    "0011000100000000", "0000100011001110", "0000000010001100", "0111001100110001",
    "0011000100010000", "0000100010001100", "0110011001100110", "0011011001101100",
    "0001011111101000", "0000111111110000", "0111000110001110", "0011100110011100",
]
A2 = [15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15,
      15, 2, 8, 2, 2, 8, 8, 15, 2, 8, 2, 2, 8, 8, 2, 2]
W3 = [0, 9, 18, 27, 37, 46, 55, 64]
W4 = [0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64]


def _runs(fmt):
    runs = []
    for item in fmt.split(","):
        name, rng = item[:-1].split("[")
        hi, _, lo = rng.partition(":")
        hi = int(hi)
        lo = int(lo) if lo else hi
        runs.append((name, hi, lo))
    return runs


RUNS = {m: _runs(f) for m, f in TABLE_F.items()}


def mode_of(block):
    low = block[0]
    return low & 3 if (low & 3) < 2 else low & 31


def _unquantize(x, bits):
    if bits >= 15:
        return x
    if x == 0:
        return 0
    if x == (1 << bits) - 1:
        return 0xFFFF
    return ((x << 15) + 0x4000) >> (bits - 1)  # the specification's form


def decode_block(block):
    block = bytes(block)
    mode = mode_of(block)
    if mode not in MODES:
        return [[0, 0, 0] for _ in range(16)]  # reserved: (0, 0, 0)
    transformed, pbits, epb, delta = MODES[mode]
    bits = np.unpackbits(np.frombuffer(block, dtype=np.uint8), bitorder="little")
    pos = 0
    v = {}
    for name, hi, lo in RUNS[mode]:
        count = abs(hi - lo) + 1
        step = 1 if hi >= lo else -1
        for n in range(count):
            target = lo + n * step
            v[name] = v.get(name, 0) | (int(bits[pos]) << target)
            pos += 1
    two = pbits > 0
    partition = 0
    if two:
        for n in range(5):
            partition |= int(bits[pos]) << n
            pos += 1
    count = 4 if two else 2
    ends = [[v.get(c + str(e), 0) for c in "rgb"] for e in range(count)]
    if transformed:
        mask = (1 << epb) - 1
        for e in range(1, count):
            for c in range(3):
                d = ends[e][c]
                if d & (1 << (delta[c] - 1)):
                    d -= 1 << delta[c]
                ends[e][c] = (ends[0][c] + d) & mask
    ends = [[_unquantize(x, epb) for x in e] for e in ends]
    index_bits = 3 if two else 4
    weights = W3 if two else W4
    out = []
    for t in range(16):
        anchor = t == 0 or (two and t == A2[partition])
        n = index_bits - 1 if anchor else index_bits
        idx = 0
        for i in range(n):
            idx |= int(bits[pos]) << i
            pos += 1
        s = int(P2[partition][t]) if two else 0
        w = weights[idx]
        texel = []
        for c in range(3):
            a, b = ends[2 * s][c], ends[2 * s + 1][c]
            interp = ((64 - w) * a + w * b + 32) >> 6
            texel.append((interp * 31) >> 6)  # final unquantize: × 31/64
        out.append(texel)
    assert pos == 128
    return out


def decode_volume(data, width, height, depth):
    bw, bh = (width + 3) // 4, (height + 3) // 4
    assert len(data) == bw * bh * depth * 16, (len(data), bw, bh, depth)
    halves = np.zeros((depth, bh * 4, bw * 4, 3), dtype=np.uint16)
    for z in range(depth):
        for by in range(bh):
            for bx in range(bw):
                at = ((z * bh + by) * bw + bx) * 16
                texels = decode_block(data[at:at + 16])
                halves[z, by * 4:by * 4 + 4, bx * 4:bx * 4 + 4, :] = np.array(
                    texels, dtype=np.uint16).reshape(4, 4, 3)
    return halves[:, :height, :width, :].view(np.float16).astype(np.float32)


def read_ktx2_bc6h(path):
    data = open(path, "rb").read()
    assert data[:12] == b"\xabKTX 20\xbb\r\n\x1a\n", "not a KTX2 file"
    vk_format, type_size, width, height, depth = struct.unpack_from("<5I", data, 12)
    assert vk_format == 131 and type_size == 1, (vk_format, type_size)
    kvd_offset, kvd_length = struct.unpack_from("<2I", data, 56)
    level_offset, level_length = struct.unpack_from("<2Q", data, 80)
    kv = {}
    p = kvd_offset
    while p < kvd_offset + kvd_length:
        (n,) = struct.unpack_from("<I", data, p)
        key, _, value = data[p + 4:p + 4 + n].partition(b"\0")
        kv[key.decode()] = value.rstrip(b"\0").decode()
        p += 4 + ((n + 3) & ~3)
    return width, height, depth, data[level_offset:level_offset + level_length], kv
