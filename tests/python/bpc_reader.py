#!/usr/bin/python3
"""Independent .bpc reader written from docs/formats/bpc.md alone (not from the C++ code).

Usage as a program:  bpc_reader.py FILE.bpc...   prints a JSON list with one summary (slices with
every float as its bit pattern, problems) per file, which tests/python/bpc_python_test.cpp
compares with the C++ reader.  As a module:  read_bpc(path) -> dict.
"""
import json
import struct
import sys
import zlib

import numpy as np

MAGIC = bytes([0x89, 0x42, 0x50, 0x43, 0x0D, 0x0A, 0x1A, 0x0A])
CHUNK_HEADER = 24
SLICE_HEADER = 32
NO_SLICE = 0xFFFFFFFF
INT_MAX = 2**31 - 1
METADATA_KEYS = [
    "sample_name", "instrument_model", "instrument_serial", "firmware_version",
    "protocol_version", "calibration_reference", "calibration_time", "capture_start",
    "capture_end", "operator_notes", "units", "software_version",
]


class BpcFormatError(Exception):
    def __init__(self, path, offset, expected, got):
        super().__init__(f"{path}: byte {offset}: expected {expected}, got {got}")
        self.offset = offset


def _metadata(obj, path, offset):
    if not isinstance(obj, dict):
        raise BpcFormatError(path, offset, "a metadata object", type(obj).__name__)
    out = {k: "" for k in METADATA_KEYS}
    out["units"] = "1/sr"
    out["extra"] = {}
    for k in METADATA_KEYS:
        if k in obj:
            if not isinstance(obj[k], str):
                raise BpcFormatError(path, offset, f"a string for '{k}'", type(obj[k]).__name__)
            out[k] = obj[k]
    if "extra" in obj:
        extra = obj["extra"]
        if not isinstance(extra, dict) or not all(isinstance(v, str) for v in extra.values()):
            raise BpcFormatError(path, offset, "'extra' as an object of strings", repr(extra))
        out["extra"] = dict(extra)
    return out


def _json_object(payload, path, offset):
    try:
        obj = json.loads(payload.decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as e:
        raise BpcFormatError(path, offset, "a UTF-8 JSON object", f"malformed JSON ({e})")
    if not isinstance(obj, dict):
        raise BpcFormatError(path, offset, "a UTF-8 JSON object", type(obj).__name__)
    return obj


def _header_crc_ok(data, q):
    return zlib.crc32(data[q:q + 20]) == struct.unpack_from("<I", data, q + 20)[0]


def _record_dtype(record_size, has_sigma):
    names = ["theta_in_deg", "phi_in_deg", "theta_out_deg", "phi_out_deg", "r", "g", "b", "flags"]
    formats = ["<f4"] * 7 + ["u1"]
    offsets = [0, 4, 8, 12, 16, 20, 24, 28]
    if has_sigma:
        names += ["sigma_r", "sigma_g", "sigma_b"]
        formats += ["<f4"] * 3
        offsets += [32, 36, 40]
    return np.dtype({"names": names, "formats": formats, "offsets": offsets,
                     "itemsize": record_size})


def _decode_slice(payload):
    """Returns (slice dict, None) or (None, reason)."""
    if len(payload) < SLICE_HEADER:
        return None, "payload shorter than the slice header"
    theta_in, phi_in, count, flags, record_size = struct.unpack_from("<ddQII", payload, 0)
    has_sigma = bool(flags & 1)
    min_record = 44 if has_sigma else 32
    if record_size < min_record:
        return None, f"record size {record_size}"
    body = len(payload) - SLICE_HEADER
    if count > body // record_size or count * record_size != body:
        return None, f"sample count {count}"
    records = np.frombuffer(payload, dtype=_record_dtype(record_size, has_sigma), count=count,
                            offset=SLICE_HEADER)
    return {
        "theta_in_deg": theta_in,
        "phi_in_deg": phi_in,
        "has_sigma": has_sigma,
        "complete": not (flags & 2),
        "records": records,
    }, None


def read_bpc(path):
    with open(path, "rb") as f:
        data = f.read()
    size = len(data)

    # 1. Header: every failure is fatal.
    if data[:8] != MAGIC:
        raise BpcFormatError(path, 0, "the .bpc magic", data[:8].hex(" "))
    if size < 12:
        raise BpcFormatError(path, 8, "a version", "end of file")
    major, minor = struct.unpack_from("<HH", data, 8)
    if major != 1:
        raise BpcFormatError(path, 8, "version 1.x", f"{major}.{minor}")
    if size - 12 < CHUNK_HEADER:
        raise BpcFormatError(path, 12, "the HEAD chunk header", "end of file")
    if data[12:16] != b"HEAD":
        raise BpcFormatError(path, 12, "tag HEAD", repr(data[12:16]))
    if not _header_crc_ok(data, 12):
        raise BpcFormatError(path, 32, "a matching header CRC", "a mismatch")
    _, _, n, pcrc, _ = struct.unpack_from("<4sIQII", data, 12)
    if n > size - 36:
        raise BpcFormatError(path, 20, f"{n} header JSON bytes", f"{size - 36}")
    payload = data[36:36 + n]
    if zlib.crc32(payload) != pcrc:
        raise BpcFormatError(path, 36, "a matching header JSON CRC", "a mismatch")
    head = _json_object(payload, path, 36)
    if head.get("version") != [major, minor]:
        raise BpcFormatError(path, 8, "the header JSON version", repr(head.get("version")))
    if "metadata" not in head:
        raise BpcFormatError(path, 36, "a metadata member", "none")
    metadata = _metadata(head["metadata"], path, 36)

    # 2. Chunks.
    slices, indices, problems = [], [], []
    pos = 36 + n
    valid_bytes = pos
    next_slice = 0
    damaged = False
    finished = False
    intact_after_damage = False

    def problem(kind, offset, length, slice_index):
        problems.append({"kind": kind, "offset": offset, "size": length, "slice": slice_index})

    while pos < size:
        remaining = size - pos
        if remaining < CHUNK_HEADER:
            problem("truncated", pos, remaining, -1)
            break
        tag = data[pos:pos + 4]
        index, payload_size, payload_crc = struct.unpack_from("<IQI", data, pos + 4)
        if not _header_crc_ok(data, pos):
            attributed = next_slice if (tag == b"SLCE" or index == next_slice) else -1
            if attributed >= 0:
                next_slice += 1
            q = pos + 1
            while q + CHUNK_HEADER <= size:
                if data[q:q + 4] in (b"SLCE", b"END ") and _header_crc_ok(data, q):
                    break
                q += 1
            else:
                q = size
            problem("corrupt", pos, q - pos, attributed)
            damaged = True
            pos = q
            continue
        slice_index = index if (tag == b"SLCE" and index <= INT_MAX) else -1
        if payload_size > remaining - CHUNK_HEADER:
            problem("truncated", pos, remaining, slice_index)
            break
        end = pos + CHUNK_HEADER + payload_size
        payload = data[pos + CHUNK_HEADER:end]
        if zlib.crc32(payload) != payload_crc:
            problem("corrupt", pos, end - pos, slice_index)
            if slice_index >= 0:
                next_slice = slice_index + 1
            damaged = True
            pos = end
            continue
        intact = True
        if tag == b"SLCE":
            s, why = (None, "slice index") if slice_index < 0 else _decode_slice(payload)
            if s is None:
                problem("corrupt", pos, end - pos, slice_index)
                intact = False
            else:
                slices.append(s)
                indices.append(slice_index)
            if slice_index >= 0:
                next_slice = slice_index + 1
        elif tag == b"END ":
            try:
                obj = _json_object(payload, path, pos + CHUNK_HEADER)
                if "metadata" not in obj:
                    raise BpcFormatError(path, pos + CHUNK_HEADER, "metadata", "none")
                end_metadata = _metadata(obj["metadata"], path, pos + CHUNK_HEADER)
                finished = True
                metadata = end_metadata
            except BpcFormatError:
                problem("corrupt", pos, end - pos, -1)
                intact = False
        # any other tag: a later minor version's chunk, skipped
        if intact and damaged:
            intact_after_damage = True
        if not intact:
            damaged = True
        pos = end
        if not damaged:
            valid_bytes = pos
        if finished:
            if pos < size:
                problem("trailing_data", pos, size - pos, -1)
            break

    return {
        "metadata": metadata,
        "slices": slices,
        "slice_indices": indices,
        "problems": problems,
        "finished": finished,
        "valid_bytes": valid_bytes,
        "intact_data_after_damage": intact_after_damage,
    }


def summary(result):
    """JSON-able summary: every float as its bit pattern, so comparisons are bit-exact."""
    out = {k: result[k] for k in ("metadata", "slice_indices", "problems", "finished",
                                  "valid_bytes", "intact_data_after_damage")}
    out["slices"] = []
    for s in result["slices"]:
        rec = s["records"]
        fields = {}
        for name in rec.dtype.names:
            col = np.ascontiguousarray(rec[name])
            fields[name] = (col.view("<u4") if col.dtype.kind == "f" else col).tolist()
        out["slices"].append({
            "theta_in_deg_bits": struct.unpack("<Q", struct.pack("<d", s["theta_in_deg"]))[0],
            "phi_in_deg_bits": struct.unpack("<Q", struct.pack("<d", s["phi_in_deg"]))[0],
            "has_sigma": s["has_sigma"],
            "complete": s["complete"],
            "samples": len(rec),
            "fields": fields,
        })
    return out


def _main(paths):
    results = []
    for path in paths:
        try:
            results.append(summary(read_bpc(path)))
        except BpcFormatError as e:
            results.append({"error": str(e), "offset": e.offset})
    print(json.dumps(results))


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: bpc_reader.py FILE.bpc...   (prints a JSON list, one summary per file)")
    _main(sys.argv[1:])
