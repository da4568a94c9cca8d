#!/usr/bin/env bash
# Builds every libFuzzer target with clang in a separate build tree and runs each for a bounded
# time over its seed corpus. Used by the `fuzz_readers` ctest test of the default (gcc) build,
# and by hand:  fuzz/run_fuzzers.sh [SOURCE_DIR] [WORK_DIR] [SECONDS_PER_FUZZER]
# New inputs go to WORK_DIR, never into the source tree; a crash leaves its input in
# WORK_DIR/artifacts/ (keep it as a regression file under fuzz/corpus/<format>/ once fixed)
# and makes the script fail.
# The mutation seed is fixed (BRDF_FUZZ_SEED, default 1) so that test runs repeat: with one seed a
# slower machine mostly explores a prefix of what a faster one does in the same time. Explore with
# other seeds by hand (BRDF_FUZZ_SEED=0 lets libFuzzer pick one) and longer runs.
set -euo pipefail
src="$(cd "${1:-$(dirname "$0")/..}" && pwd)"
work="${2:-$src/build/fuzz-run}"
seconds="${3:-15}"
seed="${BRDF_FUZZ_SEED:-1}"
cc="${BRDF_FUZZ_CC:-clang}"
cxx="${BRDF_FUZZ_CXX:-clang++}"
mkdir -p "$work"
cmake -S "$src" -B "$work/build" -G Ninja \
  -DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DBRDF_BUILD_FUZZERS=ON -DBRDF_BUILD_TESTS=OFF -DBRDF_BUILD_BENCH=OFF -DBRDF_BUILD_VIEWER=OFF \
  > "$work/configure.log" 2>&1 || { cat "$work/configure.log"; exit 1; }
cmake --build "$work/build" --target fuzzers -j "${BRDF_FUZZ_JOBS:-2}"
mkdir -p "$work/artifacts"
failed=0
while IFS='|' read -r name exe corpus dict; do
  [ -n "$name" ] || continue
  scratch="$work/corpus-$name"
  rm -rf "$scratch"
  mkdir -p "$scratch"
  args=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=65536
        -artifact_prefix="$work/artifacts/$name-" -print_final_stats=1 -seed="$seed")
  [ -n "$dict" ] && [ -f "$dict" ] && args+=(-dict="$dict")
  echo "== $name: ${seconds}s, seed $seed, over $corpus"
  if "$exe" "${args[@]}" "$scratch" "$corpus" > "$work/$name.log" 2>&1; then
    grep -E "stat::number_of_executed_units|stat::peak_rss_mb|cov:" "$work/$name.log" | tail -3 || true
  else
    echo "!! $name failed; log: $work/$name.log"
    tail -40 "$work/$name.log"
    failed=1
  fi
done < "$work/build/fuzzers.txt"
exit "$failed"
