#!/bin/bash
# (docs/benchmarks.md, "Progress of the deterministic pass".)
# Progress reporting of the hierarchical pass: brdf preview with progress (stderr to a pipe, plain
# lines) and with --quiet (no callback), interleaved, N pairs; prints wall, user, sys per run.
# usage: progress_overhead.sh BRDF SOURCE [PAIRS]
B=$1; SRC=$2; N=${3:-5}; D=$(mktemp -d)
for i in $(seq $N); do
  for mode in progress quiet; do
    q=""; [ $mode = quiet ] && q="--quiet"
    /usr/bin/time -f "$mode %e %U %S" $B preview "$SRC" --size 256 --jobs 2 $q --force --out $D/o.exr 2>&1 >/dev/null | grep -E "^(progress|quiet) "
  done
done
rm -rf $D
