#!/usr/bin/python3
"""The default `brdf preview` (hierarchical quadrature) of two builds side by side: time, error
and BRDF evaluations, interleaved rounds (docs/benchmarks.md, "Environment-lit preview").

  before_after.py BEFORE_TOOL AFTER_TOOL OUT_DIR SOURCE... [--runs 5] [--ref-pixels 1500]
                  [--jobs 2] [--keep-reference]

Same render as bench/preview/fast_path.py (512² sphere, `studio` map 1024 × 512, --no-background)
and the same error definition against the same reference (the brute-force quadrature over every
map pixel at REF_PIXELS image pixels, made once by BEFORE_TOOL: the true source, independent of
the hierarchy and the interpolation). Each round runs BEFORE then AFTER; medians over RUNS of
wall clock and CPU (user + system) of the whole process. Prints the load average before and after
and one Markdown row per source and build.
"""
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from convergence import read, relative_rms  # noqa: E402
from fast_path import SIZE, parse, run  # noqa: E402


def counts(stderr):
    """(BRDF evaluations, integrated pixels) from the tool's summary line."""
    for line in stderr.splitlines():
        if "BRDF evaluations" in line:
            parts = line.split(", ")
            return parts[1].split(" ")[0], parts[2].split(" ")[0]
    return "?", "?"


def main(argv):
    positional, runs, ref_pixels, jobs, keep = parse(argv)
    tools, out_dir, sources = positional[0:2], positional[2], positional[3:]
    os.makedirs(out_dir, exist_ok=True)
    common = ["--size", str(SIZE), "--jobs", str(jobs), "--no-background", "--force"]
    print("load average before: %.2f %.2f %.2f" % os.getloadavg())
    print("| source | build | wall s | CPU s | error vs reference | BRDF evaluations | "
          "pixels integrated |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for source in sources:
        name = os.path.basename(source)
        ref_path = os.path.join(out_dir, name + ".reference.exr")
        if not (keep and os.path.exists(ref_path)):
            run([tools[0], "preview", source, "--estimator", "quadrature", "--subdivisions", "1",
                 "--sample-pixels", str(ref_pixels), "--quiet", "--out", ref_path] + common)
        ref = read(ref_path)
        rows = [[], []]
        info = [None, None]
        for _ in range(runs):
            for b, tool in enumerate(tools):
                path = os.path.join(out_dir, "%s.%d.exr" % (name, b))
                wall, cpu, err = run([tool, "preview", source, "--out", path] + common)
                rows[b].append((wall, cpu, relative_rms(read(path), ref)))
                info[b] = counts(err)
        for b, label in enumerate(("before", "after")):
            med = lambda k: statistics.median(r[k] for r in rows[b])
            print("| %s | %s | %.2f | %.2f | %.3f %% | %s | %s |" % (
                name, label, med(0), med(1), 100 * med(2), info[b][0], info[b][1]))
        sys.stdout.flush()
    print("load average after: %.2f %.2f %.2f" % os.getloadavg())


if __name__ == "__main__":
    main(sys.argv[1:])
