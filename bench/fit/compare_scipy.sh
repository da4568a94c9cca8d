#!/bin/sh
# Fit benchmark, Ceres (bench_fit) and SciPy side by side on one full simulated capture of the
# reference geometry (4 x 76 x 360 = 109,440 samples): plastic_glossy_red at noise level 1.
# Interleaved per model: bench_fit's runs of a model, then SciPy's of the same model.
#   bench/fit/compare_scipy.sh BUILD_DIR [REPEATS [MODEL...]]
# BASELINE_BENCH_FIT=/path/to/an/older/bench_fit adds that build's runs of each model too (its
# lines are tagged "baseline").
set -eu
build=${1:?usage: compare_scipy.sh BUILD_DIR [REPEATS [MODEL...]]}
repeats=${2:-5}
shift $(( $# < 2 ? $# : 2 ))
models=${*:-ggx lafortune blinn-phong ward unreal-defaultlit unity-hdrp-lit unity-hdrp-lit-specular unity-urp-lit unity-urp-lit-specular}
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/brdf_bench_fit.XXXXXX")
trap 'rm -rf "$work"' EXIT
"$build/tools/brdf" capture --device sim --material plastic_glossy_red --sample bench --noise 1 --seed 3 \
  --out "$work/capture.bpc" --quiet > /dev/null
uptime >&2
for model in $models; do
  if [ -n "${BASELINE_BENCH_FIT:-}" ]; then
    "$BASELINE_BENCH_FIT" "$work/capture.bpc" "$work" "$repeats" "$model" | sed 's/^{/{"build": "baseline", /'
  fi
  "$build/bench/bench_fit" "$work/capture.bpc" "$work" "$repeats" "$model"
  OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 /usr/bin/python3 "$here/scipy_baseline.py" "$work" "$model" "$repeats"
done
uptime >&2
