#!/usr/bin/python3
"""Tabulates bench/bc6h/side_by_side.sh output: per material and binary, the median over rounds
of each run's median CPU time (ms), then the median and the worst over the materials."""
import collections
import csv
import glob
import os
import statistics
import sys

out = sys.argv[1]
times = collections.defaultdict(lambda: collections.defaultdict(list))  # name -> material -> ms
for path in sorted(glob.glob(os.path.join(out, "*.csv"))):
    name = os.path.basename(path).rsplit("-", 1)[0]
    lines = [l for l in open(path) if l.startswith('"EncodeBc6h/')]
    for row in csv.reader(lines):
        if row[0].endswith("_median"):
            times[name][row[0][len("EncodeBc6h/"):-len("_median")]].append(float(row[3]))
names = list(times)
# Materials every binary has a figure for (a run cut short leaves some out).
materials = sorted(set.intersection(*(set(times[n]) for n in names)))
print("| material | " + " | ".join(f"{n} (ms)" for n in names) + " |")
print("|---|" + "---:|" * len(names))
med = {n: {m: statistics.median(times[n][m]) for m in materials} for n in names}
for m in materials:
    print(f"| {m} | " + " | ".join(f"{med[n][m]:.1f}" for n in names) + " |")
for label, pick in (("median of the materials", statistics.median), ("worst material", max)):
    print(f"| **{label}** | " + " | ".join(f"{pick(med[n].values()):.1f}" for n in names) + " |")
rounds = {n: min(len(times[n][m]) for m in materials) for n in names}
print(f"\nrounds per binary: {rounds}")
