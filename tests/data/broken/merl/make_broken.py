#!/usr/bin/python3
"""Writes the hand-made broken MERL .binary files of this folder (each must fail to load
with a clear FormatError; tests/core/merl_test.cpp lists the expected message of each) and,
with --seeds DIR, seeds for the libFuzzer corpus (fuzz/corpus/merl).

A valid MERL file is 34,992,012 bytes (three int32 90, 90, 180 and 3 x 1,458,000 float64),
too large for the repository; the broken files are the small ways a file goes wrong, and the
NaN/inf cases are built in memory by the test. Usage: make_broken.py [--out DIR] [--seeds DIR]
"""
import argparse
import os
import struct


def header(a=90, b=90, c=180):
    return struct.pack('<iii', a, b, c)


def broken_files():
    return {
        'empty.binary': b'',
        'short_header.binary': header()[:7],
        'wrong_dims.binary': header(90, 90, 360) + struct.pack('<4d', 1, 2, 3, 4),
        'swapped_dims.binary': header(180, 90, 90),
        'negative_dims.binary': header(90, -90, 180),
        'huge_dims.binary': header(2147483647, 90, 180),
        'truncated.binary': header() + struct.pack('<512d', *([0.5] * 512)),
        'text_file.binary': b'hello, this is not a MERL file\n',
    }


def seed_files():
    # The fuzzer reads inputs of any size through the same checks; a full valid file is too
    # large for a seed, so seeds are the header and the start of the value planes.
    return {
        'header_only.binary': header(),
        'header_and_values.binary': header() + struct.pack('<8d', 0.1, -1, 2, 3, 0, 1e3, 5, 6),
    }


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--out', default=here)
    ap.add_argument('--seeds', help='also write seed files into this folder')
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
