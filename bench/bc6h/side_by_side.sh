#!/bin/sh
# Encode time of several bench_bc6h builds side by side (docs/benchmarks/bc6h.md): each round
# runs every binary once, in turn, pinned to one core (taskset -c 1), 3 repetitions each, so a
# loaded machine's drift hits all of them alike; the load is logged before every run.
#   bench/bc6h/side_by_side.sh LUT_DIR OUT_DIR ROUNDS NAME=BINARY...
# then: bench/bc6h/side_by_side_table.py OUT_DIR
# (LUT_DIR: float EXR composites, e.g. WORK/out-noisy of bench/bc6h/run.sh; a baseline binary
# is bench_bc6h built from another commit in a separate folder.)
set -eu
dir=$1
out=$2
rounds=$3
shift 3
mkdir -p "$out"
for round in $(seq 1 "$rounds"); do
  for pair in "$@"; do
    name=${pair%%=*}
    bin=${pair#*=}
    uptime >> "$out/load.txt"
    BRDF_BC6H_LUTS=$dir taskset -c 1 "$bin" --benchmark_filter=EncodeBc6h \
      --benchmark_repetitions=3 --benchmark_report_aggregates_only=true --benchmark_format=csv \
      > "$out/$name-$round.csv" 2>/dev/null
  done
done
uptime >> "$out/load.txt"
