#!/bin/sh
# Fit benchmark, Ceres (bench_fit) and SciPy side by side on one full simulated capture of the
# reference geometry (4 x 76 x 360 = 109,440 samples): plastic_glossy_red at noise level 1.
#   bench/fit/compare_scipy.sh BUILD_DIR [REPEATS]
set -eu
build=${1:?usage: compare_scipy.sh BUILD_DIR [REPEATS]}
repeats=${2:-3}
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/brdf_bench_fit.XXXXXX")
trap 'rm -rf "$work"' EXIT
"$build/tools/brdf" capture --device sim --material plastic_glossy_red --sample bench --noise 1 --seed 3 \
  --out "$work/capture.bpc" --quiet > /dev/null
"$build/bench/bench_fit" "$work/capture.bpc" "$work" "$repeats"
for model in ggx lafortune; do
  OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 /usr/bin/python3 "$here/scipy_baseline.py" "$work" "$model" "$repeats"
done
