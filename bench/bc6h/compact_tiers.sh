#!/bin/sh
# Which representation --max-error picks (docs/benchmarks/bc6h.md, "Compact form"): the library
# materials captured by the simulated scatterometer (noise-free and with the reference
# instrument's noise), with the default --beyond and with --beyond auto (9 slices), and the RGL
# files of /work/shared/brdf-data/rgl imported, each converted with --max-error 0.02 and 0.01.
# Prints convert's line per input (representation, bytes, ratio, measured max/p99/median).
#   bench/bc6h/compact_tiers.sh BUILD_DIR WORK_DIR [RGL_DIR]
set -eu
build=$1
work=$2
rgl=${3:-/work/shared/brdf-data/rgl}
brdf=$build/tools/brdf
"$(dirname "$0")/inputs.sh" "$brdf" "$work" "$rgl"
for set in noise-free noisy rgl; do
  for beyond in clamp auto; do
    for e in 0.02 0.01; do
      echo "## $set, --beyond $beyond, --max-error $e"
      /usr/bin/time -f "cpu %U s user + %S s system, wall %e s" \
        "$brdf" convert "$work/$set" --out "$work/out-$set-$beyond-$e" --beyond "$beyond" \
        --max-error "$e" --formats ktx2,json --jobs 2 --quiet --force 2>&1 | sort
    done
  done
done
