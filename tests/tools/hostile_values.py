"""Value classes of the hostile-input pass: files whose bytes are all in order but whose values
no material has, fits the data cannot determine, and θin lists the LUT textures cannot hold.

Each class is one file made from the pass's seeds (the reduced-geometry simulator capture
cap.bpc, its CSV cap.csv, the library's gold.json) and the verdict every reading command must
give it, written down here from the rule of docs/design.md §4 and §9 and docs/robustness.md
("One verdict per file"), not from the program's output:

  class                value change                              refused by
  value-neg-one        one sample's red f_r = −1e30              every reader (names slice+sample)
  value-huge-one       one sample's green f_r = 3e38             every reader
  value-negated        every value negated                       every reader
  value-times-1e30     every value × 1e30                        every reader
  value-denormal       every value a denormal float (1e-40)      nobody (a black surface)
  saturated-but-one    every sample flagged saturated but one    nobody; fit warns "1 usable
                                                                 sample for 3 parameters"
  one-per-slice        one sample per slice                      nobody; a ggx fit warns, and
                                                                 --extrapolate auto keeps p 1, l 0.5
  csv-one-row          a CSV with one data row                   nobody; fit warns
  theta-in-30          capture --theta-in 30                     convert, atlas (θin ≠ k·Δin);
  theta-in-10-30-50    capture --theta-in 10,30,50               capture warns, info exits 1
  material-bad-extrapolate  gold.json, "extrapolate": p = −1     every reader

`export-csv` copies every sample (a CSV can hold any finite number): it accepts the value classes
and says, in a warning naming slice and sample, what the other commands refuse. The readers are
info, eval, convert, atlas, preview, fit, export-csv, repair and capture --resume (captures; the
last two by the rule at REFUSED_BY_ALL), import (the CSV), when the pass
is given the viewer (--viewer) brdf-view drawing the lobe off screen, and when it is given the
Python module (--python-path) brdf.open(FILE).eval_deg, brdf.info, brdf.fit and brdf.convert
(the verdicts of eval, info, fit and convert).

Bad map texels (issue 20, finding 7) are classes of environment maps, read by every command
that reads a map: `brdf preview --env` and, when the pass is given the Python module's folder
(--python-path), the module's brdf.preview(env=...). (`brdf-view` lights with its built-in
studio map only and reads no map file.) Each map is a 64 × 32 EXR written by OpenImageIO with
numpy; the expected count and kinds come from the array as stored in the file (a half-float EXR
holds float16, where 1e6 is +Inf), counted by the first channel of a texel that is not a finite
value >= 0, in channel order (docs/robustness.md, finding 7):

  class              texels                                     verdict
  map-nan            3 NaN                                      accepted, one warning line
  map-inf            2 +Inf, 2 -Inf                             accepted, one warning line
  map-negative       4 negative (−1e-3 … −3)                    accepted, one warning line
  map-half-sun       a 2 × 2 sun of 1e6 in a half-float EXR     accepted, the warning names the
                                                                half-float overflow
  map-mixed          NaN, ±Inf and negative texels together     accepted, one warning line
  map-all-inf        every texel +Inf (half-float)              refused in one line naming the
                                                                file, "all 2048 hold"

Every run is also held to the pass's bounds: at most CPU_LIMIT_S (10 s) of CPU time, TIMEOUT_S of
wall time, and PEAK_RSS_BYTES of peak resident memory (ru_maxrss and ru_utime + ru_stime of that
one child, from wait4).
"""

import json
import math
import os
import re
import shutil
import struct

import hostile_inputs as hi

PEAK_RSS_BYTES = hi.PEAK_RSS_BYTES
CPU_LIMIT_S = hi.CPU_LIMIT_S


def run_measured(tool, args, cwd, env=None):
    """(exit code or "timeout", stdout, stderr, CPU seconds, peak RSS bytes) of one run, under
    the pass's address-space, CPU and wall-clock limits (hostile_inputs.run_measured)."""
    return hi.run_measured(tool, args, cwd, env)[:5]


# ---------------------------------------------------------------------------------------------
# Making the files.

RECORD = struct.Struct("<7fB3x")  # θin, φin, θout, φout, r, g, b, flags (docs/formats/bpc.md)


def within_bounds(where, code, cpu, rss, findings):
    """Adds a finding for a run that timed out or exceeded the CPU or peak-memory bound; False
    when it timed out (its output says nothing more)."""
    if code == "timeout":
        findings.append(f"{where}: timed out after {hi.TIMEOUT_S} s")
        return False
    if cpu > CPU_LIMIT_S:
        findings.append(f"{where}: {cpu:.1f} s of CPU > {CPU_LIMIT_S} s")
    if rss > PEAK_RSS_BYTES:
        findings.append(f"{where}: peak RSS {rss / 2**20:.0f} MiB > "
                        f"{PEAK_RSS_BYTES / 2**20:.0f} MiB")
    return True


def edit_capture(data, edit):
    """`data` (a .bpc) with every slice's samples passed through edit(slice, records) ->
    records, each record [θin, φin, θout, φout, r, g, b, flags, σ (bytes)], CRCs and the end
    chunk's sample count rewritten so that only the values differ."""
    chunks = hi.bpc_chunks(data)
    total = 0
    # From the last chunk to the first, so earlier offsets stay valid.
    rewritten = []
    for offset, tag, _, size in chunks:
        if tag != b"SLCE":
            continue
        payload = data[offset + 24:offset + 24 + size]
        theta_in, phi_in, count, flags, record_size = struct.unpack_from("<ddQII", payload, 0)
        records = []
        for n in range(count):
            rec = payload[32 + n * record_size:32 + (n + 1) * record_size]
            records.append(list(RECORD.unpack_from(rec, 0)) + [rec[32:]])
        records = edit(len(rewritten), records)
        body = b"".join(RECORD.pack(*r[:8]) + r[8] for r in records)
        head = struct.pack("<ddQII", theta_in, phi_in, len(records), flags, record_size)
        rewritten.append((offset, head + body))
        total += len(records)
    for offset, payload in reversed(rewritten):
        data = hi.bpc_rewrite_chunk(data, offset, payload=payload)
    for offset, tag, _, size in hi.bpc_chunks(data):
        if tag == b"END ":
            end = json.loads(data[offset + 24:offset + 24 + size])
            end["sample_count"] = total
            data = hi.bpc_rewrite_chunk(data, offset, payload=json.dumps(end).encode())
    return data


def set_values(fn):
    def edit(_, records):
        for r in records:
            r[4], r[5], r[6] = fn(r[4]), fn(r[5]), fn(r[6])
        return records
    return edit


def one_sample(slice_index, channel, value):
    """Sets one channel of the first sample at θout 30° of slice `slice_index`."""
    def edit(i, records):
        if i == slice_index:
            r = next(r for r in records if abs(r[2] - 30) < 1e-3)
            r[4 + channel] = value
        return records
    return edit


def saturate_all_but_one(i, records):
    for n, r in enumerate(records):
        if not (i == 0 and n == len(records) // 2):
            r[7] |= 0x01
    return records


def keep_one_per_slice(_, records):
    return [next(r for r in records if abs(r[2] - 30) < 1e-3 and abs(r[3]) < 1e-3)]


# `repair` and `capture --resume` read captures too. A slice whose values every reader refuses
# is dropped by repair (exit 0), so that a resume of the repaired file measures it again; the
# resume of the file itself is refused before anything is measured (exit 1, the file unchanged),
# naming slice and sample and the repair. An intact capture has nothing to repair (exit 1) and a
# finished one nothing to resume (exit 0).
REFUSED_BY_ALL = {"info": 1, "eval": 1, "convert": 1, "atlas": 1, "preview": 1, "fit": 1,
                  "export-csv": 0, "brdf-view": 1, "repair": 0, "resume": 1}
ACCEPTED_BY_ALL = {"info": 0, "eval": 0, "convert": 0, "atlas": 0, "preview": 0, "fit": 0,
                   "export-csv": 0, "brdf-view": 0, "repair": 1, "resume": 0}
# The capture command of the seed cap.bpc (hostile_inputs.make_seeds), resuming --out.
RESUME_SEED_CAPTURE = ["capture", "--device", "sim", "--material", "gold", "--sample", "hostile",
                       "--theta-in", "0,30,60", "--theta-out-step", "5", "--phi-out-step", "10",
                       "--noise", "1", "--seed", "7", "--sim-pace-ms", "0", "--quiet",
                       "--resume", "--out"]
CONVERT_ONLY = {"info": 1, "eval": 0, "convert": 1, "atlas": 1, "preview": 0, "fit": 0,
                "export-csv": 0, "brdf-view": 0}


class ValueClass:
    def __init__(self, name, path, expected, names_sample=False, fit_model="lambert",
                 fit_warns=False, auto_defaults=False, capture=None):
        self.name, self.path, self.expected = name, path, expected
        self.names_sample = names_sample  # refusals name "slice N" and "sample M"
        self.fit_model, self.fit_warns, self.auto_defaults = fit_model, fit_warns, auto_defaults
        self.capture = capture  # the capture run that made the file (its stderr is checked)


def make_classes(tool, seeds_dir, work):
    vdir = os.path.join(work, "values")
    os.makedirs(vdir)
    cap = open(os.path.join(seeds_dir, "cap.bpc"), "rb").read()
    classes = []

    def add_capture(name, edit, expected, **kw):
        path = os.path.join(vdir, name + ".bpc")
        open(path, "wb").write(edit_capture(cap, edit))
        classes.append(ValueClass(name, path, expected, **kw))

    add_capture("value-neg-one", one_sample(1, 0, -1e30), REFUSED_BY_ALL, names_sample=True)
    add_capture("value-huge-one", one_sample(1, 1, 3e38), REFUSED_BY_ALL, names_sample=True)
    add_capture("value-negated", set_values(lambda v: -v), REFUSED_BY_ALL, names_sample=True)
    add_capture("value-times-1e30", set_values(lambda v: v * 1e30), REFUSED_BY_ALL,
                names_sample=True)
    add_capture("value-denormal", set_values(lambda v: 1e-40), ACCEPTED_BY_ALL)
    add_capture("saturated-but-one", saturate_all_but_one, ACCEPTED_BY_ALL, fit_warns=True)
    add_capture("one-per-slice", keep_one_per_slice, ACCEPTED_BY_ALL, fit_model="ggx",
                fit_warns=True, auto_defaults=True)

    csv_lines = open(os.path.join(seeds_dir, "cap.csv")).read().split("\n")
    data_rows = [i for i, line in enumerate(csv_lines) if line[:1].isdigit()]
    one_row = [line for i, line in enumerate(csv_lines)
               if i not in data_rows or i == data_rows[len(data_rows) // 2]]
    path = os.path.join(vdir, "csv-one-row.csv")
    open(path, "w").write("\n".join(one_row))
    classes.append(ValueClass("csv-one-row", path,
                              {"info": 0, "eval": 0, "preview": 0, "fit": 0, "import": 0,
                               "brdf-view": 0},
                              fit_warns=True))

    for name, theta_in in (("theta-in-30", "30"), ("theta-in-10-30-50", "10,30,50")):
        path = os.path.join(vdir, name + ".bpc")
        run = run_measured(tool, ["capture", "--device", "sim", "--material", "gold", "--sample",
                                  name, "--theta-in", theta_in, "--theta-out-step", "5",
                                  "--phi-out-step", "10", "--noise", "0", "--sim-pace-ms", "0",
                                  "--quiet", "--out", path], work)
        classes.append(ValueClass(name, path, CONVERT_ONLY, capture=run))

    gold = json.load(open(os.path.join(seeds_dir, "gold.json")))
    gold["extrapolate"] = {"p": -1, "l": 0.5}
    path = os.path.join(vdir, "material-bad-extrapolate.json")
    json.dump(gold, open(path, "w"))
    classes.append(ValueClass("material-bad-extrapolate", path,
                              {"info": 1, "eval": 1, "convert": 1, "atlas": 1, "preview": 1,
                               "fit": 1, "brdf-view": 1}))
    return classes


# ---------------------------------------------------------------------------------------------
# Running and checking.

def command_line(command, vc, out):
    p = vc.path
    return {
        "info": ["info", p, "--json"],
        "eval": ["eval", p, "--in", "30,0", "--out", "30,180"],
        "convert": ["convert", p, "--quiet", "--formats", "json,ktx2", "--out",
                    os.path.join(out, "conv")],
        "atlas": ["atlas", p, "--quiet", "--jobs", "1", "--out", os.path.join(out, "atlas")],
        "convert-auto": ["convert", p, "--quiet", "--formats", "json", "--extrapolate", "auto",
                         "--out", os.path.join(out, "auto")],
        "preview": ["preview", p, "--size", "32", "--spp", "1", "--jobs", "1", "--quiet",
                    "--out", os.path.join(out, "p.png")],
        "fit": ["fit", p, "--model", vc.fit_model, "--starts", "1", "--quiet", "--jobs", "1",
                "--out", os.path.join(out, "f.json")],
        "export-csv": ["export-csv", p, "--out", os.path.join(out, "e.csv")],
        "import": ["import", p, "--out", os.path.join(out, "i.bpc")],
        "repair": ["repair", p, "--out", os.path.join(out, "r.bpc")],
        # A copy of the file: capture --resume appends to its --out (check_class makes it).
        "resume": RESUME_SEED_CAPTURE + [os.path.join(out, "resume.bpc")],
        # brdf-view's lobe, drawn off screen (it starts its own Xvfb when there is no display).
        "brdf-view": [p, "--screenshot", os.path.join(out, "v.png"), "--size", "64x64"],
    }[command]


# The Python module's reader: brdf.open(FILE) evaluated as `brdf eval FILE --in 30,0 --out
# 30,180`; exit 1 with the exception's message on stderr when it refuses.
PYTHON_EVAL = """
import sys
import brdf
try:
    brdf.open(sys.argv[1]).eval_deg(30, 0, 30, 180)
except Exception as e:
    print(f"{type(e).__name__}: {e}", file=sys.stderr)
    sys.exit(1)
"""


# The module's other readers of the same files, each held to the verdict of its command:
# brdf.info (the verdict is its "usable", printed as the exit code info gives), brdf.fit (the
# warning of an under-determined fit as a UserWarning or in the report's warnings) and
# brdf.convert.
PYTHON_READERS = {
    "python-info": ("info", """
import sys
import brdf
try:
    doc = brdf.info(sys.argv[1])
except Exception as e:
    print(f"{type(e).__name__}: {e}", file=sys.stderr)
    sys.exit(1)
if doc.get("usable") is False:
    print("; ".join(doc.get("refusals", [])), file=sys.stderr)
    sys.exit(1)
"""),
    "python-fit": ("fit", """
import json, sys, warnings
import brdf
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    try:
        report = brdf.fit(sys.argv[1], model=sys.argv[2], starts=1, jobs=1)["fit"]
    except Exception as e:
        print(f"{type(e).__name__}: {e}", file=sys.stderr)
        sys.exit(1)
print(json.dumps({"warnings": [str(w.message) for w in caught] + report.get("warnings", []),
                  "representable": report.get("representable")}))
"""),
    "python-convert": ("convert", """
import sys
import brdf
try:
    brdf.convert(sys.argv[1], sys.argv[2], formats="json,ktx2")
except Exception as e:
    print(f"{type(e).__name__}: {e}", file=sys.stderr)
    sys.exit(1)
"""),
}


def python_env(python_path):
    return dict(os.environ, PYTHONPATH=python_path, OPENBLAS_NUM_THREADS="1",
                PYTHONDONTWRITEBYTECODE="1")


def check_class(tool, vc, work, findings, counts, viewer="", python_path=""):
    out = os.path.join(work, "values-out", vc.name)
    os.makedirs(out)
    results = {}
    expected = dict(vc.expected)
    if python_path and "eval" in expected:
        expected["python-open"] = expected["eval"]
    if python_path:
        for reader, (command, _) in PYTHON_READERS.items():
            if command in expected:
                expected[reader] = expected[command]
    commands = [c for c in expected if c != "brdf-view" or viewer]
    commands += ["convert-auto"] if vc.auto_defaults else []
    if "resume" in expected:
        shutil.copy(vc.path, os.path.join(out, "resume.bpc"))
    for command in commands:
        if command == "python-open":
            code, stdout, stderr, cpu, rss = run_measured(
                "/usr/bin/python3", ["-c", PYTHON_EVAL, vc.path], work, python_env(python_path))
        elif command in PYTHON_READERS:
            extra = {"python-fit": [vc.fit_model],
                     "python-convert": [os.path.join(out, "pyconv")]}.get(command, [])
            code, stdout, stderr, cpu, rss = run_measured(
                "/usr/bin/python3", ["-c", PYTHON_READERS[command][1], vc.path] + extra, work,
                python_env(python_path))
        else:
            program = viewer if command == "brdf-view" else tool
            code, stdout, stderr, cpu, rss = run_measured(
                program, command_line(command, vc, out), work)
        results[command] = (code, stdout, stderr, cpu, rss)
        counts[command] = counts.get(command, 0) + 1
        where = f"value class {vc.name} {command}"
        if not within_bounds(where, code, cpu, rss, findings):
            continue
        hi.check_run(hi.Variant(hi.Seed(os.path.basename(vc.path), vc.path, "values", []),
                                vc.name, vc.path), command, code, stdout, stderr, findings)
        want = expected.get(command, 0)
        if code != want:
            findings.append(f"{where}: exit code {code}, the verdict is {want}: "
                            f"{stderr.strip()[:300]}")
        if vc.names_sample and command != "info" and want != 0 and code == want:
            if "slice" not in stderr or "sample" not in stderr:
                findings.append(f"{where}: the refusal names no slice and sample: "
                                f"{stderr.strip()[:300]}")
        if vc.names_sample and command == "export-csv" and code == 0:
            if "warning" not in stderr or "sample" not in stderr:
                findings.append(f"{where}: copied values every other command refuses without "
                                f"saying so: {stderr.strip()[:300]}")
    info = results.get("info")
    if info and isinstance(info[0], int):
        try:
            doc = json.loads(info[1]) if info[1].strip() else {}
        except ValueError:
            doc = None
            findings.append(f"value class {vc.name} info: --json printed no JSON")
        if isinstance(doc, dict) and "usable" in doc and doc["usable"] != (info[0] == 0):
            findings.append(f"value class {vc.name} info: \"usable\": {doc['usable']} but exit "
                            f"code {info[0]}")
        if isinstance(doc, dict) and vc.names_sample:
            text = " ".join(doc.get("refusals", []))
            if "slice" not in text or "sample" not in text:
                findings.append(f"value class {vc.name} info: the refusals name no slice and "
                                f"sample: {text[:300]}")
        if isinstance(doc, dict) and vc.expected is CONVERT_ONLY:
            if doc.get("evaluable") is not True or doc.get("convertible") is not False:
                findings.append(f"value class {vc.name} info: want evaluable true, convertible "
                                f"false, got {doc.get('evaluable')}, {doc.get('convertible')}")
    pyfit = results.get("python-fit")
    if pyfit and pyfit[0] == 0 and vc.fit_warns:
        try:
            doc = json.loads(pyfit[1])
            if not any("usable sample" in w for w in doc["warnings"]):
                findings.append(f"value class {vc.name} python-fit: an under-determined fit "
                                f"without the 'N usable samples' warning: {pyfit[1][:300]}")
            if doc["representable"] is not False:
                findings.append(f"value class {vc.name} python-fit: an under-determined fit "
                                f"recorded representable {doc['representable']}")
        except (ValueError, KeyError) as e:
            findings.append(f"value class {vc.name} python-fit: no report ({e}): "
                            f"{pyfit[1][:300]}")
    fit = results.get("fit")
    if fit and fit[0] == 0 and vc.fit_warns:
        if "usable sample" not in fit[1] + fit[2]:
            findings.append(f"value class {vc.name} fit: an under-determined fit without the "
                            f"'N usable samples for P parameters' warning: {fit[1][:300]}")
        try:
            report = json.load(open(os.path.join(out, "f.json")))["fit"]
            if report.get("representable") is not False:
                findings.append(f"value class {vc.name} fit: an under-determined fit recorded "
                                f"representable {report.get('representable')}")
        except (OSError, ValueError, KeyError) as e:
            findings.append(f"value class {vc.name} fit: result unreadable: {e}")
    if vc.auto_defaults:
        code, _, stderr = results["convert-auto"][:3]
        sidecar = os.path.join(out, "auto", os.path.splitext(os.path.basename(vc.path))[0] +
                               ".json")
        try:
            extrapolation = json.load(open(sidecar)).get("extrapolation") or {}
            if (code != 0 or "--extrapolate auto" not in stderr or
                    (extrapolation.get("p"), extrapolation.get("l")) != (1, 0.5)):
                findings.append(f"value class {vc.name} convert --extrapolate auto: relied on an "
                                f"under-determined fit (exit {code}, extrapolation "
                                f"{extrapolation}): {stderr.strip()[:300]}")
        except (OSError, ValueError) as e:
            findings.append(f"value class {vc.name} convert --extrapolate auto: no sidecar: {e}")
    check_repair_and_resume(tool, vc, work, out, results, findings)
    if vc.capture is not None:
        code, _, stderr, _, _ = vc.capture
        if code != 0 or "warning" not in stderr or "convert" not in stderr:
            findings.append(f"value class {vc.name}: capture wrote a file convert refuses "
                            f"without a warning (exit {code}): {stderr.strip()[:300]}")
    return results


def check_repair_and_resume(tool, vc, work, out, results, findings):
    """What the exit codes of repair and resume do not show: a refused resume measured nothing
    and names the repair; the repair named the slices it dropped for their values, and the
    repaired file, resumed with the seed's command, is a capture every reader accepts."""
    where = f"value class {vc.name}"
    resume, repair = results.get("resume"), results.get("repair")
    if resume and resume[0] == 1 and vc.expected.get("resume") == 1:
        if open(os.path.join(out, "resume.bpc"), "rb").read() != open(vc.path, "rb").read():
            findings.append(f"{where} resume: refused, but the file changed")
        if "brdf repair" not in resume[2]:
            findings.append(f"{where} resume: the refusal does not say how to go on (brdf "
                            f"repair): {resume[2].strip()[:300]}")
    if repair and repair[0] == 1 and vc.expected.get("repair") == 1:
        if "nothing to repair" not in repair[2]:
            findings.append(f"{where} repair: an intact capture refused for another reason: "
                            f"{repair[2].strip()[:300]}")
    if not (repair and repair[0] == 0 and vc.expected.get("repair") == 0):
        return
    dropped = [line for line in repair[1].split("\n") if "dropped slice" in line]
    if not dropped or not all("values" in line for line in dropped):
        findings.append(f"{where} repair: no slice dropped for its values: "
                        f"{repair[1].strip()[:300]}")
    fixed = os.path.join(out, "r.bpc")
    code, _, stderr, cpu, rss = run_measured(tool, RESUME_SEED_CAPTURE + [fixed], work)
    if within_bounds(f"{where} resume of the repair", code, cpu, rss, findings) and code != 0:
        findings.append(f"{where}: the repaired capture cannot be resumed (exit {code}): "
                        f"{stderr.strip()[:300]}")
    code, _, stderr, cpu, rss = run_measured(tool, ["info", fixed, "--json"], work)
    if within_bounds(f"{where} info of the resumed repair", code, cpu, rss, findings) and code:
        findings.append(f"{where}: the repaired and resumed capture is refused (exit {code}): "
                        f"{stderr.strip()[:300]}")


# ---------------------------------------------------------------------------------------------
# Bad map texels.

MAP_WIDTH, MAP_HEIGHT = 64, 32
# The kinds in the order and words of the warning; a texel counts as the first channel's kind.
MAP_KINDS = ("NaN", "+Inf", "-Inf", "negative")


def map_classes():
    """[(name, pixel format, edit(px))]: px is a float32 (32, 64, 3) array of 0.5."""
    import numpy as np

    def nan(px):
        px[1, 2, 0] = np.nan
        px[3, 4, 1] = np.nan
        px[30, 60, 2] = np.nan

    def inf(px):
        px[5, 6, :] = np.inf
        px[0, 0, 1] = np.inf
        px[7, 8, 2] = -np.inf
        px[31, 63, 0] = -np.inf

    def negative(px):
        px[9, 10, 1] = -0.25
        px[9, 11, 0] = -3
        px[9, 12, 2] = -1e-3
        px[20, 40, :] = -1

    def sun(px):
        px[4:6, 10:12, :] = 1e6  # beyond float16's 65504: +Inf in the file

    def mixed(px):
        nan(px)
        inf(px)
        negative(px)
        px[1, 2, 1] = -np.inf  # a NaN first: counted as NaN

    def all_inf(px):
        px[:] = np.inf

    return [("map-nan", "float", nan), ("map-inf", "float", inf),
            ("map-negative", "float", negative), ("map-half-sun", "half", sun),
            ("map-mixed", "float", mixed), ("map-all-inf", "half", all_inf)]


def write_map(path, fmt, edit):
    """Writes the map; returns (bad texels, {kind: count}) of what the file holds."""
    import numpy as np
    import OpenImageIO as oiio
    px = np.full((MAP_HEIGHT, MAP_WIDTH, 3), 0.5, np.float32)
    edit(px)
    out = oiio.ImageOutput.create(path)
    if not out or not out.open(path, oiio.ImageSpec(MAP_WIDTH, MAP_HEIGHT, 3, fmt)):
        raise SystemExit(f"hostile_values: cannot write {path} with OpenImageIO")
    out.write_image(px)
    out.close()
    with np.errstate(over="ignore"):  # the overflow to +Inf is the point
        stored = px.astype(np.float16).astype(np.float32) if fmt == "half" else px
    kinds = dict.fromkeys(MAP_KINDS, 0)
    bad = 0
    for texel in stored.reshape(-1, 3):
        for v in texel:
            v = float(v)
            kind = ("NaN" if math.isnan(v) else "+Inf" if v == math.inf else
                    "-Inf" if v == -math.inf else "negative" if v < 0 else None)
            if kind:
                kinds[kind] += 1
                bad += 1
                break
    return bad, kinds


PYTHON_PREVIEW = """
import json, sys, warnings
import brdf
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    try:
        brdf.preview("gold", env=sys.argv[1], size=16, spp=1, jobs=1)
        error = None
    except Exception as e:
        error = f"{type(e).__name__}: {e}"
print(json.dumps({"warnings": [str(w.message) for w in caught], "error": error}))
sys.exit(1 if error else 0)
"""


def check_maps(tool, work, python_path, findings, counts):
    """Every bad-texel map through every command that reads a map. Returns the results per
    class for the table."""
    mdir = os.path.join(work, "maps")
    os.makedirs(mdir)
    python = "/usr/bin/python3"
    table = {}
    for name, fmt, edit in map_classes():
        path = os.path.join(mdir, name + ".exr")
        bad, kinds = write_map(path, fmt, edit)
        texels = MAP_WIDTH * MAP_HEIGHT
        refused = bad == texels
        out_png = os.path.join(mdir, name + ".png")
        runs = {"preview-env": [tool, ["preview", "gold", "--env", path, "--size", "16", "--spp",
                                        "1", "--jobs", "1", "--quiet", "--out", out_png]]}
        if python_path:
            runs["python-preview"] = [python, ["-c", PYTHON_PREVIEW, path]]
        results = {}
        for command, (program, args) in runs.items():
            env = python_env(python_path) if command == "python-preview" else None
            code, stdout, stderr, cpu, rss = run_measured(program, args, mdir, env)
            results[command] = (code, stdout, stderr, cpu, rss)
            counts[command] = counts.get(command, 0) + 1
            where = f"map class {name} {command}"
            if not within_bounds(where, code, cpu, rss, findings):
                continue
            want = 1 if refused else 0
            if code != want:
                findings.append(f"{where}: exit code {code}, the verdict is {want}: "
                                f"{(stderr or stdout).strip()[:300]}")
            if command == "preview-env":
                # The pass's checks of every run (one line, the file named, no library words),
                # without its position rule for damaged bytes: these maps are intact files whose
                # values are wrong as a whole, which the line counts instead.
                hi.check_run(hi.Variant(hi.Seed(name + ".exr", path, "values", []), name, path,
                                        special=True),
                             command, code, stdout, stderr, findings)
                lines = [line for line in stderr.split("\n") if line.strip()]
                if len(lines) != 1:
                    findings.append(f"{where}: {len(lines)} stderr lines, want the one line of "
                                    f"the count: {stderr.strip()[:300]!r}")
                message = lines[0] if lines else ""
                if refused and os.path.exists(out_png):
                    findings.append(f"{where}: refused the map but wrote {out_png}")
            else:
                try:
                    doc = json.loads(stdout)
                except ValueError:
                    findings.append(f"{where}: no result: {stderr.strip()[:300]}")
                    continue
                texel_lines = [w for w in doc["warnings"] if "texels" in w]
                if refused:
                    message = doc["error"] or ""
                else:
                    if len(texel_lines) != 1:
                        findings.append(f"{where}: {len(texel_lines)} texel warnings, want one: "
                                        f"{doc['warnings']}")
                    message = texel_lines[0] if texel_lines else ""
            # The count and the kinds, in the file's terms, whoever reads it.
            said = {k: re.search(r"\b(\d+) " + re.escape(k) + r"(?:\W|$)", message)
                    for k in MAP_KINDS}
            if path not in message and os.path.basename(path) not in message:
                findings.append(f"{where}: the line does not name the map: {message[:300]}")
            if refused:
                if (f"all {texels} hold" not in message or
                        "expected texels with a finite radiance >= 0" not in message):
                    findings.append(f"{where}: a map with no usable texel not refused in the "
                                    f"file's terms: {message[:300]}")
            elif f"{bad} of {texels} texels" not in message:
                findings.append(f"{where}: want '{bad} of {texels} texels' counted, got: "
                                f"{message[:300]}")
            for k in MAP_KINDS:
                got = int(said[k].group(1)) if said[k] else 0
                if got != kinds[k]:
                    findings.append(f"{where}: {kinds[k]} {k} texels in the file, the line says "
                                    f"{got}: {message[:300]}")
            if kinds["+Inf"] and fmt == "half" and "half-float value beyond 65504" not in message:
                findings.append(f"{where}: a half-float map whose values overflowed to +Inf "
                                f"without saying so: {message[:300]}")
        table[name] = results
    return table


def run(tool, seeds_dir, work, table=False, python_path="", viewer=""):
    """(findings, runs, counts) of every value class and map class."""
    findings, counts = [], {}
    runs = 0
    for name, results in check_maps(tool, work, python_path, findings, counts).items():
        runs += len(results)
        if table:
            codes = " ".join(f"{c}={r[0]}" for c, r in results.items())
            cpu = max(r[3] for r in results.values())
            rss = max(r[4] for r in results.values())
            print(f"map class {name} {codes} (slowest {cpu:.2f} s CPU, peak RSS "
                  f"{rss / 2**20:.0f} MiB)")
    for vc in make_classes(tool, seeds_dir, work):
        results = check_class(tool, vc, work, findings, counts, viewer, python_path)
        runs += len(results)
        if table:
            codes = " ".join(f"{c}={r[0]}" for c, r in results.items())
            first = next((r[2].strip().split("\n")[0] for r in results.values() if r[2].strip()),
                         "")
            cpu = max(r[3] for r in results.values())
            rss = max(r[4] for r in results.values())
            print(f"value class {vc.name} {codes} (slowest {cpu:.2f} s CPU, peak RSS "
                  f"{rss / 2**20:.0f} MiB) | {first[:200]}")
    shutil.rmtree(os.path.join(work, "values-out"), ignore_errors=True)
    return findings, runs, counts
