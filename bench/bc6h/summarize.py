#!/usr/bin/python3
"""Tabulates the certified BC6H errors recorded in the sidecars of `brdf convert --compress
bc6h` output folders (bench/bc6h/run.sh): per file and, per folder, the median over files of
each figure and the worst file. Markdown on stdout, percent."""
import json
import os
import statistics
import sys


def rows(folder):
    out = []
    for name in sorted(os.listdir(folder)):
        if not name.endswith(".json"):
            continue
        j = json.load(open(os.path.join(folder, name)))
        if "compression" not in j:
            continue
        c = j["compression"]["certified_error"]
        out.append((name[:-5], c["measured"], c["filled"], j["compression"]["bytes"]))
    return out


def pct(x):
    return f"{100 * x:.2f}"


for folder in sys.argv[1:]:
    r = rows(folder)
    print(f"\n### {os.path.basename(folder.rstrip('/'))} ({len(r)} files)\n")
    print("| file | measured median % | measured p99 % | measured max % | filled median % | "
          "filled p99 % | bytes |")
    print("|---|---|---|---|---|---|---|")
    for name, m, f, b in r:
        print(f"| {name} | {pct(m['median'])} | {pct(m['p99'])} | {pct(m['max'])} | "
              f"{pct(f['median'])} | {pct(f['p99'])} | {b} |")
    for label, pick in (("median over files", statistics.median), ("worst file", max)):
        print(f"| **{label}** | {pct(pick(m['median'] for _, m, _, _ in r))} | "
              f"{pct(pick(m['p99'] for _, m, _, _ in r))} | {pct(pick(m['max'] for _, m, _, _ in r))} | "
              f"{pct(pick(f['median'] for _, _, f, _ in r))} | {pct(pick(f['p99'] for _, _, f, _ in r))} | |")
    ok_med = sum(m["median"] <= 0.005 for _, m, _, _ in r)
    ok_p99 = sum(m["p99"] <= 0.03 for _, m, _, _ in r)
    print(f"\nTargets on the measured range: median ≤ 0.5 % met by {ok_med} of {len(r)} files, "
          f"p99 ≤ 3 % by {ok_p99} of {len(r)}.")
