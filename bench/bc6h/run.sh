#!/bin/sh
# BC6H on real data (docs/benchmarks/bc6h.md): every library material captured by the simulated
# scatterometer (reference noise, and noise-free) and the 18 RGL files imported, converted with
# --compress bc6h; the certified errors their sidecars record are tabulated by summarize.py
# (checked against the numpy recomputation in tests/python/bc6h_check.py), and bench_bc6h
# times encoding on one core.
#   bench/bc6h/run.sh BUILD_DIR WORK_DIR [RGL_DIR]     (RGL_DIR default /work/shared/brdf-data/rgl)
set -eu
build=$1
work=$2
rgl=${3:-/work/shared/brdf-data/rgl}
brdf=$build/tools/brdf
here=$(dirname "$0")
"$(dirname "$0")/inputs.sh" "$brdf" "$work" "$rgl"
for set in noisy noise-free rgl; do
  "$brdf" convert "$work/$set" --out "$work/out-$set" --compress bc6h --formats ktx2,exr,json \
    --exr-type float --jobs 2 --quiet --force
done
/usr/bin/python3 "$here/summarize.py" "$work/out-noisy" "$work/out-noise-free" "$work/out-rgl"
BRDF_BC6H_LUTS="$work/out-noisy" taskset -c 0 "$build/bench/bench_bc6h" \
  --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
