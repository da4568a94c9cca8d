#!/usr/bin/python3
"""Writes the seed corpus of protocol_fuzzer (fuzz/corpus/protocol/) from the frame layout in
device/include/brdf/device/protocol.h: sync 0xB7 0xDF, u8 type, u8 sequence, u16 payload
length, payload, CRC-32 (zlib's) of type..payload; little-endian throughout.

One file per conversation the fuzz entry replays: what an instrument answers during a
connect-dark-white-slice session (drives the host driver), what a host sends (drives the
simulated firmware), and an instrument error reply.

Usage:  fuzz/make_protocol_corpus.py [OUT_DIR]   (default: fuzz/corpus/protocol next to this script)
"""
import os
import struct
import sys
import zlib

IDENTIFY, GET_GEOMETRY, SET_EXPOSURE, MEASURE_DARK, MEASURE_WHITE, MEASURE_SLICE, ABORT = range(1, 8)
IDENTITY, GEOMETRY, ACK, DARK, WHITE, SLICE_BEGIN, ROW_DATA, SLICE_END = range(0x81, 0x89)
ERROR = 0xEE


def frame(kind, sequence, payload=b""):
    body = struct.pack("<BBH", kind, sequence, len(payload)) + payload
    return b"\xb7\xdf" + body + struct.pack("<I", zlib.crc32(body))


def string(s):
    return struct.pack("<B", len(s)) + s.encode()


def stream(frames):
    return b"".join(frame(kind, seq, payload) for seq, (kind, payload) in enumerate(frames))


def instrument_session():
    rows, columns, theta_in = 3, 4, 20.0
    frames = [
        (IDENTITY, string("BRDF-SIM MD2") + string("SIM-000001") + string("2.4.1-sim")
         + struct.pack("<HHfHf", 1, 0, 65535.0, 16, 2.0)),
        (GEOMETRY, struct.pack("<Bf", 1, theta_in) + struct.pack("<fffHH", 10, 5, 90, rows, columns)),
        (ACK, bytes([SET_EXPOSURE])),
        (DARK, struct.pack("<6fH", 500, 500, 500, 6, 6, 6, 64)),
        (WHITE, struct.pack("<ff3fBH", theta_in, 80, 50000, 50000, 50000, 0, 64)),
        (SLICE_BEGIN, struct.pack("<fHH", theta_in, rows, columns)),
    ]
    for row in range(rows):
        samples = b"".join(struct.pack("<3fB", 1000, 2000, 3000, 0) for _ in range(columns))
        frames.append((ROW_DATA, struct.pack("<HHHf", row, 0, columns, 10) + samples))
    frames.append((SLICE_END, struct.pack("<fII", theta_in, rows * columns, 0)))
    return stream(frames)


def instrument_session_v1_1():
    """Protocol 1.1 (device/PROTOCOL.md): GEOMETRY with the exposure range and ND filters,
    WHITE and ROW_DATA with a trailing ND index, a duplicated ROW_DATA and a lamp error."""
    rows, columns, theta_in = 2, 3, 40.0
    nd = [1.0, 0.1, 0.01]
    frames = [
        (IDENTITY, string("BRDF-SIM MD2") + string("SIM-000002") + string("2.5.0-sim")
         + struct.pack("<HHfHf", 1, 1, 65535.0, 16, 2.0)),
        (GEOMETRY, struct.pack("<Bf", 1, theta_in) + struct.pack("<fffHH", 5, 5, 120, rows, columns)
         + struct.pack("<ffB", 1.0, 2000.0, len(nd)) + b"".join(struct.pack("<f", t) for t in nd)),
        (ACK, bytes([SET_EXPOSURE])),
        (DARK, struct.pack("<6fH", 500, 500, 500, 6, 6, 6, 64)),
        (WHITE, struct.pack("<ff3fBHB", theta_in, 80, 50000, 50000, 50000, 0, 64, 0)),
        (SLICE_BEGIN, struct.pack("<fHH", theta_in, rows, columns)),
    ]
    for row in range(rows):
        samples = b"".join(struct.pack("<3fB", 1000, 2000, 3000, 0) for _ in range(columns))
        frames.append((ROW_DATA, struct.pack("<HHHf", row, 0, columns, 1.5) + samples + bytes([2])))
    data = stream(frames)
    data += data[-(len(frames[-1][1]) + 10):]  # the last ROW_DATA again: a duplicated transfer
    data += frame(ERROR, len(frames), struct.pack("<HB", 6, MEASURE_SLICE) + string("lamp failure"))
    return data


def host_session():
    return stream([
        (IDENTIFY, b""),
        (GET_GEOMETRY, b""),
        (SET_EXPOSURE, struct.pack("<Bf", 2, 10.0)),
        (MEASURE_DARK, b""),
        (MEASURE_WHITE, struct.pack("<f", 20.0)),
        (MEASURE_SLICE, struct.pack("<f", 20.0)),
        (ABORT, b""),
    ])


def error_reply():
    return stream([(ERROR, struct.pack("<HB", 3, MEASURE_SLICE) + string("theta_in out of range"))])


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "corpus", "protocol")
    os.makedirs(out, exist_ok=True)
    for name, data in [("instrument_session.bin", instrument_session()),
                       ("instrument_session_v1_1.bin", instrument_session_v1_1()),
                       ("host_session.bin", host_session()),
                       ("error_reply.bin", error_reply())]:
        with open(os.path.join(out, name), "wb") as f:
            f.write(data)


if __name__ == "__main__":
    main()
