#!/usr/bin/python3
"""Writes the reader corpus: small valid KTX2/DDS files crafted here from the specifications
(independently of the C++ writer) and broken variants that the readers must reject cleanly
with a FormatError. Run from anywhere; writes next to this script. Deterministic.

  valid-*.ktx2 / valid-*.dds    must parse
  broken-*.ktx2 / broken-*.dds  must fail with brdf::FormatError (never crash, hang or
                                allocate beyond the file size)
The same files seed the libFuzzer targets (tests/export/fuzz_*.cpp).
"""
import json
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
KTX2_ID = bytes([0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A])


def rgb9e5(r, g, b):
    """Exact for the small integers used here: mantissas at exponent 24 (scale 1)."""
    return r | (g << 9) | (b << 18) | (24 << 27)


def dfd_words():
    words = [124, 0, 2 | (120 << 16), 1 | (1 << 8) | (1 << 16), 0, 4, 0]
    for channel, offset in ((0, 0), (1, 9), (2, 18)):
        words += [offset | (8 << 16) | (channel << 24), 0, 0, 8448]
        words += [27 | (4 << 16) | ((channel | 0x20) << 24), 0, 15, 31]
    return words


def ktx2(width, height, depth, texels, kv):
    dfd = struct.pack('<31I', *dfd_words())
    kvd = b''
    for key in sorted(kv):
        entry = key.encode() + b'\0' + kv[key].encode() + b'\0'
        kvd += struct.pack('<I', len(entry)) + entry
        kvd += b'\0' * (-len(kvd) % 4)
    dfd_offset = 12 + 36 + 32 + 24
    kvd_offset = dfd_offset + len(dfd)
    level_offset = kvd_offset + len(kvd)
    level = struct.pack('<%dI' % len(texels), *texels)
    header = KTX2_ID + struct.pack('<9I', 123, 4, width, height, depth, 0, 1, 1, 0)
    index = struct.pack('<4I2Q', dfd_offset, len(dfd), kvd_offset, len(kvd), 0, 0)
    levels = struct.pack('<3Q', level_offset, len(level), len(level))
    return bytearray(header + index + levels + dfd + kvd + level), level_offset


def dds(width, height, depth, texels):
    flags = 0x1 | 0x2 | 0x4 | 0x8 | 0x1000 | 0x20000 | 0x800000
    head = struct.pack('<4s7I', b'DDS ', 124, flags, height, width, width * 4, depth, 1)
    head += b'\0' * 44
    head += struct.pack('<2I4s5I', 32, 0x4, b'DX10', 0, 0, 0, 0, 0)
    head += struct.pack('<5I', 0x1000, 0x200000, 0, 0, 0)
    head += struct.pack('<5I', 67, 4, 0, 1, 0)
    return bytearray(head + struct.pack('<%dI' % len(texels), *texels))


def sidecar(width, height, depth, level):
    return json.dumps({
        'kind': 'brdf-lut-sidecar', 'format_version': 1, 'name': 'tiny', 'source': 'make_corpus.py',
        'theta_in_deg': [20.0 * k for k in range(depth)],
        'grid': {'width': width, 'height': height, 'slices': depth},
        'extrapolation': None, 'fitted_models': [], 'tool': {'name': 'make_corpus.py', 'version': '1.0.0'},
        'payload': {'bytes': len(level), 'checksum': {'algorithm': 'crc32', 'value': '0x%08x' % zlib.crc32(level)}},
        'files': []})


def put32(b, at, v):
    b[at:at + 4] = struct.pack('<I', v)


def put64(b, at, v):
    b[at:at + 8] = struct.pack('<Q', v)


def main():
    files = {}
    w, h, d = 3, 2, 2
    texels = [rgb9e5(x + 1, y + 2, z + 3) for z in range(d) for y in range(h) for x in range(w)]
    level = struct.pack('<%dI' % len(texels), *texels)
    plain, plain_level = ktx2(w, h, d, texels, {'KTXwriter': 'make_corpus.py'})
    meta, meta_level = ktx2(w, h, d, texels, {'KTXwriter': 'make_corpus.py', 'brdf.sidecar': sidecar(w, h, d, level)})
    files['valid-plain.ktx2'] = plain
    files['valid-sidecar.ktx2'] = meta
    for n in (0, 5, 11, 12, 47, 48, 79, 80, 103, 104, 150, len(plain) - 1):
        files['broken-truncated-%03d.ktx2' % n] = plain[:n]
    def variant(name, base, fn):
        b = bytearray(base)
        fn(b)
        files['broken-%s.ktx2' % name] = b
    variant('magic-ktx1', plain, lambda b: b.__setitem__(5, ord('1')))
    variant('vkformat-97', plain, lambda b: put32(b, 12, 97))
    variant('typesize-2', plain, lambda b: put32(b, 16, 2))
    variant('width-0', plain, lambda b: put32(b, 20, 0))
    variant('width-huge', plain, lambda b: put32(b, 20, 0x7FFFFFFF))
    variant('depth-0', plain, lambda b: put32(b, 28, 0))
    variant('depth-mismatch', plain, lambda b: put32(b, 28, 3))
    variant('layers-3', plain, lambda b: put32(b, 32, 3))
    variant('faces-6', plain, lambda b: put32(b, 36, 6))
    variant('levels-5', plain, lambda b: put32(b, 40, 5))
    variant('zstd', plain, lambda b: put32(b, 44, 2))
    variant('dfd-offset-past-end', plain, lambda b: put32(b, 48, 0xFFFFFF00))
    variant('dfd-length-0', plain, lambda b: put32(b, 52, 0))
    variant('dfd-mantissa-upper', plain, lambda b: put32(b, 104 + 4 * 10, 511))
    variant('dfd-model-ycbcr', plain, lambda b: put32(b, 104 + 12, 2 | (1 << 8) | (1 << 16)))
    variant('dfd-block-size', plain, lambda b: put32(b, 104 + 8, 2 | (88 << 16)))
    variant('kvd-length-huge', plain, lambda b: put32(b, 60, 0xFFFFFFF0))
    variant('kvd-entry-length-huge', plain, lambda b: put32(b, 228, 0x7FFFFFFF))
    entry_length = struct.unpack_from('<I', plain, 228)[0]  # the first (only) key/value entry
    variant('kvd-key-unterminated', plain,
            lambda b: b.__setitem__(slice(232, 232 + entry_length), b'K' * entry_length))
    variant('sgd-present', plain, lambda b: put64(b, 72, 16))
    variant('level-offset-past-end', plain, lambda b: put64(b, 80, 1 << 40))
    variant('level-offset-unaligned', plain, lambda b: put64(b, 80, plain_level + 1))
    variant('level-length-short', plain, lambda b: put64(b, 88, 20))
    variant('level-uncompressed-differs', plain, lambda b: put64(b, 96, 8))
    variant('checksum-mismatch', meta, lambda b: b.__setitem__(meta_level + 3, b[meta_level + 3] ^ 0x10))
    json_at = bytes(meta).index(b'{"kind"')
    variant('sidecar-not-json', meta, lambda b: b.__setitem__(slice(json_at, json_at + 4), b'}}}}'))

    base = dds(w, h, d, texels)
    files['valid-plain.dds'] = base
    for n in (0, 3, 4, 60, 127, 128, 147, 148, len(base) - 1):
        files['broken-truncated-%03d.dds' % n] = base[:n]
    def dvariant(name, fn):
        b = bytearray(base)
        fn(b)
        files['broken-%s.dds' % name] = b
    dvariant('magic', lambda b: b.__setitem__(slice(0, 4), b'DDX '))
    dvariant('header-size', lambda b: put32(b, 4, 100))
    dvariant('no-depth-flag', lambda b: put32(b, 8, 0x1 | 0x2 | 0x4 | 0x1000))
    dvariant('height-0', lambda b: put32(b, 12, 0))
    dvariant('width-huge', lambda b: put32(b, 16, 0xFFFFFFFF))
    dvariant('pitch', lambda b: put32(b, 20, 7))
    dvariant('depth-0', lambda b: put32(b, 24, 0))
    dvariant('depth-mismatch', lambda b: put32(b, 24, 9))
    dvariant('mips-3', lambda b: put32(b, 28, 3))
    dvariant('pixelformat-size', lambda b: put32(b, 76, 24))
    dvariant('no-fourcc-flag', lambda b: put32(b, 80, 0x40))
    dvariant('fourcc-dxt1', lambda b: b.__setitem__(slice(84, 88), b'DXT1'))
    dvariant('no-volume-caps', lambda b: put32(b, 112, 0))
    dvariant('dxgi-71', lambda b: put32(b, 128, 71))
    dvariant('dimension-2d', lambda b: put32(b, 132, 3))
    dvariant('array-6', lambda b: put32(b, 140, 6))
    files['broken-extra-bytes.dds'] = base + b'\0\0\0\0'

    for name, data in files.items():
        with open(os.path.join(HERE, name), 'wb') as f:
            f.write(bytes(data))
    print('wrote %d files' % len(files))


if __name__ == '__main__':
    main()
