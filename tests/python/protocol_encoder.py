#!/usr/bin/python3
"""An instrument's side of the scatterometer protocol, written from device/PROTOCOL.md alone.

Shares no code with the C++ codec: framing (§2), data types (§3) and payloads (§5) are encoded
here with struct and zlib, and the expected calibrated values with the formula of §9.

usage: protocol_encoder.py OUT_DIR RHO_R RHO_G RHO_B
writes OUT_DIR/replies.bin   the instrument's frames for IDENTIFY, GET_GEOMETRY, SET_EXPOSURE,
                             MEASURE_DARK, MEASURE_WHITE 30, MEASURE_SLICE 30 (with noise bytes
                             between some frames and sequence numbers wrapping past 255)
       OUT_DIR/expected.txt  one line per sample: row column f_r(R G B) saturated below_floor
"""
import math
import struct
import sys
import zlib


class Instrument:
    def __init__(self):
        self.seq = 250  # any start (§2); 250 makes the numbers wrap within the session
        self.out = bytearray()

    def frame(self, msg_type, payload):
        header = struct.pack("<BBH", msg_type, self.seq, len(payload))
        crc = zlib.crc32(header + payload) & 0xFFFFFFFF
        self.out += b"\xb7\xdf" + header + payload + struct.pack("<I", crc)
        self.seq = (self.seq + 1) % 256

    def noise(self, data):
        self.out += data  # bytes between frames are ignored (§2)


def string(s):
    b = s.encode("utf-8")
    return struct.pack("<B", len(b)) + b


def rgb(v):
    return struct.pack("<3f", *v)


def f32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


def main():
    out_dir = sys.argv[1]
    rho = [float(x) for x in sys.argv[2:5]]
    dev = Instrument()

    frames_per_reading = 4
    dev.frame(0x81, string("PY-ENC 1") + string("PY-0001") + string("0.1-py") +
              struct.pack("<HHfHf", 1, 1, 65535.0, frames_per_reading, 2.0))
    nd = [1.0, 0.1]
    dev.frame(0x82, struct.pack("<B", 1) + struct.pack("<f", 30.0) +
              struct.pack("<fffHH", 10.0, 5.0, 120.0, 3, 3) +
              struct.pack("<ffB", 1.0, 2000.0, len(nd)) + b"".join(struct.pack("<f", t) for t in nd))
    dev.noise(b"\x00\x11\xb7\x22")  # a stray sync byte without its partner
    dev.frame(0x83, struct.pack("<B", 0x03))
    dark = [100.0, 110.0, 120.0]
    read_noise = [5.0, 5.0, 5.0]
    dev.frame(0x84, rgb(dark) + rgb(read_noise) + struct.pack("<H", 64))
    white_ms, white_counts = 50.0, [40000.0, 45000.0, 30000.0]
    dev.frame(0x85, struct.pack("<ff", 30.0, white_ms) + rgb(white_counts) +
              struct.pack("<BHB", 0, 64, 0))
    dev.frame(0x86, struct.pack("<fHH", 30.0, 3, 3))

    # rows: (exposure_ms, nd_index, [(counts, clip bits)] for columns 0, 1, 2)
    rows = [
        (10.0, 1, [([30000.0, 20000.0, 12000.0], 0), ([60000.0, 65535.0, 50000.0], 0b010),
                   ([5000.0, 4000.0, 3000.0], 0)]),
        (200.0, 0, [([1200.5, 900.25, 700.125], 0), ([2000.0, 2100.0, 1900.0], 0),
                    ([150.0, 160.0, 170.0], 0)]),
        (2000.0, 0, [([104.0, 140.0, 150.0], 0), ([300.0, 320.0, 330.0], 0),
                     ([110.0, 119.0, 130.0], 0)]),
    ]
    expected = []
    clipped = 0
    floor = 3 * read_noise[0] / math.sqrt(frames_per_reading)
    for r, (ms, k, samples) in enumerate(rows):
        # row 0 in two segments (columns 0-1, then 2), the others whole (§7)
        segments = [(0, samples[:2]), (2, samples[2:])] if r == 0 else [(0, samples)]
        for first, seg in segments:
            payload = struct.pack("<HHHf", r, first, len(seg), ms)
            for counts, bits in seg:
                payload += rgb(counts) + struct.pack("<B", bits)
            payload += struct.pack("<B", k)
            dev.frame(0x87, payload)
            if r == 1:
                dev.noise(b"\xb7\xdf\xff\xff\xff\xff")  # a header claiming 65535 bytes: damaged
        for c, (counts, bits) in enumerate(samples):
            f = []
            below = False
            for ch in range(3):
                # §9, with every input as the float32 the wire carries
                s = f32(counts[ch]) - f32(dark[ch])
                w = f32(white_counts[ch]) - f32(dark[ch])
                t_s = f32(ms) * f32(nd[k])
                t_w = f32(white_ms) * f32(nd[0])
                f.append((s / t_s) / (w / t_w) * rho[ch] / math.pi)
                below = below or s < floor
            clipped += bits != 0
            expected.append((r, c, f, bits != 0, below))
    dev.frame(0x88, struct.pack("<fII", 30.0, 9, clipped))

    with open(out_dir + "/replies.bin", "wb") as fh:
        fh.write(dev.out)
    with open(out_dir + "/expected.txt", "w") as fh:
        for r, c, f, sat, below in expected:
            fh.write("%d %d %.17g %.17g %.17g %d %d\n" % (r, c, f[0], f[1], f[2], sat, below))


if __name__ == "__main__":
    main()
