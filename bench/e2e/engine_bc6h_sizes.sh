#!/bin/bash
# The engine kit in the RGB9E5 and the BC6H form (docs/benchmarks/bc6h.md, "Engine kit"):
# `brdf convert gold.bpc --engine all` with --compress none and bc6h, alternating, 3 runs each
# (wall seconds, one job), then the bytes of every file in each engine folder.
# Usage: bench/e2e/engine_bc6h_sizes.sh [BRDF] [INPUT]
set -euo pipefail
B=${1:-build/dev/tools/brdf}
IN=${2:-data-samples/captures/gold.bpc}
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
for i in 1 2 3; do
  for form in none bc6h; do
    rm -rf "$W/$form"
    s=$(date +%s.%N)
    "$B" convert "$IN" --out "$W/$form" --engine all --compress $form --quiet --jobs 1 >/dev/null
    e=$(date +%s.%N)
    echo "time $form $(echo "$e - $s" | bc) s"
  done
done
for form in none bc6h; do
  for f in unity unreal godot web; do
    echo "bytes $form $f $(find "$W/$form/$f" -type f -printf '%s\n' | awk '{s+=$1} END {print s}')"
  done
done
