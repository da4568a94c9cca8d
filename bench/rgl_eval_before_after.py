#!/usr/bin/python3
"""Two builds of bench_rgl side by side: RGL evaluation CPU time per call, interleaved rounds.

  rgl_eval_before_after.py BEFORE_BENCH AFTER_BENCH [--runs 7] [--filter REGEX]

Each round runs BEFORE then AFTER (Google Benchmark, --benchmark_min_time=0.3, JSON output);
prints the load average before and after and, per benchmark present in both builds, the median
CPU time per item over the rounds and the ratio before / after (docs/benchmarks.md, "RGL
and MERL evaluation"). The data folder is $BRDF_DATA_DIR when set.
"""
import json
import os
import statistics
import subprocess
import sys


def run(bench, regex):
    out = subprocess.run([bench, "--benchmark_filter=" + regex, "--benchmark_min_time=0.3",
                          "--benchmark_format=json"], check=True, capture_output=True, text=True)
    # items_per_second is a rate over CPU time (no UseRealTime in bench_rgl.cpp), so its
    # inverse is the CPU time per evaluation.
    return {b["name"]: 1e9 / b["items_per_second"]
            for b in json.loads(out.stdout)["benchmarks"] if b.get("items_per_second")}


def main(argv):
    runs, regex, positional, i = 7, "RglEval|RglVirtualCapture", [], 0
    while i < len(argv):
        if argv[i] == "--runs":
            runs = int(argv[i + 1]); i += 2
        elif argv[i] == "--filter":
            regex = argv[i + 1]; i += 2
        else:
            positional.append(argv[i]); i += 1
    if len(positional) != 2:
        sys.exit(__doc__.strip().split("\n\n")[1])
    rounds = [[], []]
    print("load average before: %.2f %.2f %.2f" % os.getloadavg())
    for _ in range(runs):
        for b, bench in enumerate(positional):
            rounds[b].append(run(bench, regex))
    print("load average after: %.2f %.2f %.2f" % os.getloadavg())
    print("| benchmark | before ns/eval (CPU) | after ns/eval (CPU) | before / after |")
    print("|---|---:|---:|---:|")
    for name in rounds[0][0]:
        if name not in rounds[1][0]:
            continue
        med = [statistics.median(r[name] for r in rounds[b]) for b in (0, 1)]
        print("| %s | %.1f | %.1f | %.2f |" % (name, med[0], med[1], med[0] / med[1]))


if __name__ == "__main__":
    main(sys.argv[1:])
