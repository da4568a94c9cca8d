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
and says, in a warning naming slice and sample, what the other commands refuse.

Every run is also held to the pass's bounds: at most CPU_LIMIT_S (10 s) of CPU time, TIMEOUT_S of
wall time, and PEAK_RSS_BYTES of peak resident memory (ru_maxrss and ru_utime + ru_stime of that
one child, from wait4). Bad map texels (NaN, ±Inf,
negative, an all-Inf map) are the environment-map reader's class and are checked with that
fix (issue 20, finding 7), not here.
"""

import json
import os
import shutil
import struct
import subprocess
import tempfile
import threading

import hostile_inputs as hi

# The reading commands peak at 14–64 MiB of resident memory on these small files (info 14,
# convert 23, preview 37 on the intact capture); a quarter of the pass's address-space limit
# leaves room for a slow machine's allocator and still catches memory that grows with a value
# rather than with the file.
PEAK_RSS_BYTES = 1 << 30
# 10 s of CPU per run (the pass's CPU_LIMIT_S where it has one, enforced with RLIMIT_CPU), and its
# wall-clock limit for a run that waits without computing.
CPU_LIMIT_S = getattr(hi, "CPU_LIMIT_S", 10)


def run_measured(tool, args, cwd):
    """(exit code or "timeout", stdout, stderr, CPU seconds, peak RSS bytes) of one run, under
    the pass's address-space, CPU and wall-clock limits."""
    with tempfile.TemporaryFile() as out_f, tempfile.TemporaryFile() as err_f:
        def limits():
            import resource
            resource.setrlimit(resource.RLIMIT_AS, (hi.ADDRESS_SPACE_BYTES, hi.ADDRESS_SPACE_BYTES))
            resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
            resource.setrlimit(resource.RLIMIT_CPU, (CPU_LIMIT_S, CPU_LIMIT_S + 1))
            os.setsid()

        proc = subprocess.Popen([tool] + args, cwd=cwd, stdin=subprocess.DEVNULL, stdout=out_f,
                                stderr=err_f, preexec_fn=limits)
        timed_out = []

        def kill():
            timed_out.append(True)
            try:
                os.killpg(proc.pid, 9)
            except ProcessLookupError:
                pass

        timer = threading.Timer(hi.TIMEOUT_S, kill)
        timer.start()
        _, status, usage = os.wait4(proc.pid, 0)
        timer.cancel()
        proc.returncode = os.waitstatus_to_exitcode(status)  # reaped here, not by Popen
        cpu = usage.ru_utime + usage.ru_stime
        out_f.seek(0)
        err_f.seek(0)
        code = "timeout" if timed_out else proc.returncode
        return (code, out_f.read().decode("utf-8", "replace"),
                err_f.read().decode("utf-8", "replace"), cpu, usage.ru_maxrss * 1024)


# ---------------------------------------------------------------------------------------------
# Making the files.

RECORD = struct.Struct("<7fB3x")  # θin, φin, θout, φout, r, g, b, flags (docs/formats/bpc.md)


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


REFUSED_BY_ALL = {"info": 1, "eval": 1, "convert": 1, "atlas": 1, "preview": 1, "fit": 1,
                  "export-csv": 0}
ACCEPTED_BY_ALL = {"info": 0, "eval": 0, "convert": 0, "atlas": 0, "preview": 0, "fit": 0,
                   "export-csv": 0}
CONVERT_ONLY = {"info": 1, "eval": 0, "convert": 1, "atlas": 1, "preview": 0, "fit": 0,
                "export-csv": 0}


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
                              {"info": 0, "eval": 0, "preview": 0, "fit": 0, "import": 0},
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
                               "fit": 1}))
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
    }[command]


def check_class(tool, vc, work, findings, counts):
    out = os.path.join(work, "values-out", vc.name)
    os.makedirs(out)
    results = {}
    commands = list(vc.expected) + (["convert-auto"] if vc.auto_defaults else [])
    for command in commands:
        code, stdout, stderr, cpu, rss = run_measured(tool, command_line(command, vc, out), work)
        results[command] = (code, stdout, stderr, cpu, rss)
        counts[command] = counts.get(command, 0) + 1
        where = f"value class {vc.name} {command}"
        if code == "timeout":
            findings.append(f"{where}: timed out after {hi.TIMEOUT_S} s")
            continue
        if cpu > CPU_LIMIT_S:
            findings.append(f"{where}: {cpu:.1f} s of CPU > {CPU_LIMIT_S} s")
        if rss > PEAK_RSS_BYTES:
            findings.append(f"{where}: peak RSS {rss / 2**20:.0f} MiB > "
                            f"{PEAK_RSS_BYTES / 2**20:.0f} MiB")
        hi.check_run(hi.Variant(hi.Seed(os.path.basename(vc.path), vc.path, "values", []),
                                vc.name, vc.path), command, code, stdout, stderr, findings)
        want = vc.expected.get(command, 0)
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
    if vc.capture is not None:
        code, _, stderr, _, _ = vc.capture
        if code != 0 or "warning" not in stderr or "convert" not in stderr:
            findings.append(f"value class {vc.name}: capture wrote a file convert refuses "
                            f"without a warning (exit {code}): {stderr.strip()[:300]}")
    return results


def run(tool, seeds_dir, work, table=False):
    """(findings, runs, counts) of every value class."""
    findings, counts = [], {}
    runs = 0
    for vc in make_classes(tool, seeds_dir, work):
        results = check_class(tool, vc, work, findings, counts)
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
