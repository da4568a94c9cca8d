#!/usr/bin/python3
"""Writes the hand-made broken RGL tensor files of this folder (each must fail to load with a
clear FormatError; tests/core/rgl_test.cpp lists the expected message of each) and, with
--seeds DIR, small valid files for the libFuzzer seed corpus (fuzz/corpus/rgl).

All files derive from one tiny synthetic material in the layout of the RGL database files
(README of ../shared/brdf-data): phi_i[1], theta_i[2], sigma/ndf[2, 4], vndf[1, 2, 5, 5],
rgb[1, 2, 3, 2, 2], jacobian[1]. Usage: make_broken.py [--out DIR] [--seeds DIR]
"""
import argparse
import math
import os
import struct

F32 = 10


def f32(values):
    return struct.pack('<%df' % len(values), *values)


def base_fields(p=1, t=2, vx=5, vy=5, n=2, jacobian=1, phi=None):
    phi = phi if phi is not None else [0.0]
    theta = [0.0, 1.0][:t] if t <= 2 else [i * 1.5 / (t - 1) for i in range(t)]
    vndf = [1.0 + x + y for _ in range(p * t) for y in range(vy) for x in range(vx)]
    rgb = [0.1 * (c + x + y) for _ in range(p * t) for c in range(3) for y in range(n)
           for x in range(n)]
    return [
        dict(name=b'version', dtype=5, shape=[2], data=struct.pack('<II', 1, 0)),
        dict(name=b'description', dtype=1, shape=[16], data=b'broken-file base'),
        dict(name=b'phi_i', dtype=F32, shape=[p], data=f32(phi)),
        dict(name=b'theta_i', dtype=F32, shape=[t], data=f32(theta)),
        dict(name=b'sigma', dtype=F32, shape=[2, 4], data=f32([0.5] * 8)),
        dict(name=b'ndf', dtype=F32, shape=[2, 4], data=f32([1.0, 0.8, 0.5, 0.2] * 2)),
        dict(name=b'vndf', dtype=F32, shape=[p, t, vy, vx], data=f32(vndf)),
        dict(name=b'rgb', dtype=F32, shape=[p, t, 3, n, n], data=f32(rgb)),
        dict(name=b'jacobian', dtype=1, shape=[1], data=bytes([jacobian])),
    ]


def encode(fields, magic=b'tensor_file\0', version=(1, 0), count=None):
    """Tensor file bytes; a field may override its header with 'rank', 'dims', 'offset'."""
    header = 12 + 2 + 4 + sum(2 + len(f['name']) + 2 + 1 + 8 +
                              8 * len(f.get('dims', f['shape'])) for f in fields)
    align = lambda v: (v + 7) & ~7
    out = bytearray(magic + bytes(version) + struct.pack('<I', len(fields) if count is None
                                                         else count & 0xFFFFFFFF))
    offset = align(header)
    offsets = []
    for f in fields:
        offsets.append(offset)
        offset = align(offset + len(f['data']))
    for f, off in zip(fields, offsets):
        dims = f.get('dims', f['shape'])
        out += struct.pack('<H', len(f['name'])) + f['name']
        out += struct.pack('<HBQ', f.get('rank', len(dims)), f['dtype'], f.get('offset', off))
        out += b''.join(struct.pack('<Q', d & 0xFFFFFFFFFFFFFFFF) for d in dims)
    for f in fields:
        out += bytes(align(len(out)) - len(out)) + f['data']
    return bytes(out)


def field(fields, name):
    return next(f for f in fields if f['name'] == name)


def broken_files():
    files = {}
    good = encode(base_fields())
    files['empty.bsdf'] = b''
    files['wrong_magic.bsdf'] = encode(base_fields(), magic=b'tensor_fiel\0')
    files['wrong_version.bsdf'] = encode(base_fields(), version=(2, 0))
    # Cut inside the rgb field's second dimension.
    pos = good.index(b'rgb') + 3 + 2 + 1 + 8 + 8 + 3
    files['truncated_header.bsdf'] = good[:pos]
    files['truncated_data.bsdf'] = good[:-1]
    files['huge_field_count.bsdf'] = encode(base_fields(), count=0x7FFFFFFF)
    files['negative_field_count.bsdf'] = encode(base_fields(), count=-3)
    fs = base_fields()
    field(fs, b'vndf')['dims'] = [1, 2, 1 << 31, 1 << 31]
    files['huge_dimensions.bsdf'] = encode(fs)
    fs = base_fields()
    field(fs, b'rgb')['dims'] = [1, 2, 3, -1, 2]
    files['negative_dimension.bsdf'] = encode(fs)
    fs = base_fields()
    field(fs, b'rgb')['rank'] = 65535
    files['huge_rank.bsdf'] = encode(fs)
    fs = base_fields()
    field(fs, b'sigma')['dtype'] = 12
    files['bad_dtype.bsdf'] = encode(fs)
    fs = base_fields()
    field(fs, b'ndf')['offset'] = len(good) + 100
    files['offset_past_end.bsdf'] = encode(fs)
    fs = base_fields()
    field(fs, b'ndf')['name'] = b'sigma'
    files['duplicate_field.bsdf'] = encode(fs)
    files['missing_vndf.bsdf'] = encode([f for f in base_fields() if f['name'] != b'vndf'])
    fs = base_fields()
    rgb = field(fs, b'rgb')
    rgb['dtype'], rgb['shape'] = 11, [1, 2, 3, 2, 1]
    files['wrong_dtype_rgb.bsdf'] = encode(fs)
    fs = base_fields()
    rgb = field(fs, b'rgb')
    rgb['shape'], rgb['data'] = [1, 1, 3, 2, 2], rgb['data'][:48]
    files['shape_mismatch.bsdf'] = encode(fs)

    def with_value(name, index, value):
        fs = base_fields()
        f = field(fs, name)
        data = bytearray(f['data'])
        data[4 * index:4 * index + 4] = struct.pack('<f', value)
        f['data'] = bytes(data)
        return encode(fs)
    files['nan_vndf.bsdf'] = with_value(b'vndf', 12, math.nan)
    files['inf_rgb.bsdf'] = with_value(b'rgb', 5, math.inf)
    files['negative_vndf.bsdf'] = with_value(b'vndf', 3, -1.0)
    files['zero_sigma.bsdf'] = with_value(b'sigma', 2, 0.0)
    files['absurd_ndf.bsdf'] = with_value(b'ndf', 1, 3e38)
    files['theta_not_increasing.bsdf'] = with_value(b'theta_i', 1, 0.0)
    fs = base_fields()
    field(fs, b'vndf')['data'] = f32([0.0] * 50)
    files['zero_vndf.bsdf'] = encode(fs)
    fs = base_fields()
    field(fs, b'description')['data'] = b'broken \xff\xfe base '
    files['bad_utf8_description.bsdf'] = encode(fs)
    fs = base_fields()
    field(fs, b'version')['name'] = b'ver\xc0\xafion'
    files['bad_utf8_field_name.bsdf'] = encode(fs)
    fs = base_fields()
    ndf = field(fs, b'ndf')
    ndf['shape'], ndf['data'] = [2, 0], b''
    files['zero_dimension.bsdf'] = encode(fs)
    return files


def seed_files():
    return {
        'tiny.bsdf': encode(base_fields()),
        'jacobian0.bsdf': encode(base_fields(jacobian=0)),
        'one_theta.bsdf': encode(base_fields(t=1)),
        'anisotropic.bsdf': encode(base_fields(p=3, phi=[-math.pi, 0.0, math.pi])),
        'finer.bsdf': encode(base_fields(t=3, vx=9, vy=7, n=4)),
    }


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--out', default=here)
    ap.add_argument('--seeds', help='also write valid seed files into this folder')
    args = ap.parse_args()
    for name, data in broken_files().items():
        with open(os.path.join(args.out, name), 'wb') as f:
            f.write(data)
    if args.seeds:
        for name, data in seed_files().items():
            with open(os.path.join(args.seeds, name), 'wb') as f:
                f.write(data)


if __name__ == '__main__':
    main()
