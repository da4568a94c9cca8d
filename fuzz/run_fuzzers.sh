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
# The run fails unless it built and ran exactly the eleven targets below (one per reader and the
# device link) and each executed at least BRDF_FUZZ_MIN_UNITS inputs (default 200; libFuzzer's
# stat::number_of_executed_units, seeds included): a target that silently dropped out of the
# build, or one that stopped after its seeds, is a failure, not a pass.
set -euo pipefail
expected_targets="bpc_fuzzer brdfc_fuzzer csv_fuzzer dds_fuzzer gonio_fuzzer ktx2_fuzzer lighttools_fuzzer merl_fuzzer protocol_fuzzer rgl_fuzzer zemax_fuzzer"
min_units="${BRDF_FUZZ_MIN_UNITS:-200}"
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
listed="$(cut -d'|' -f1 "$work/build/fuzzers.txt" | grep -v '^$' | LC_ALL=C sort | tr '\n' ' ' | sed 's/ $//')"
if [ "$listed" != "$expected_targets" ]; then
  echo "!! fuzz targets: expected the eleven '$expected_targets', the build lists '$listed'"
  exit 1
fi
failed=0
ran=0
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
    units="$(sed -n 's/^stat::number_of_executed_units: *\([0-9][0-9]*\).*/\1/p' "$work/$name.log" | tail -1)"
    if [ -z "$units" ] || [ "$units" -lt "$min_units" ]; then
      echo "!! $name executed ${units:-no} inputs, fewer than the floor of $min_units; log: $work/$name.log"
      failed=1
    fi
    ran=$((ran + 1))
  else
    echo "!! $name failed; log: $work/$name.log"
    tail -40 "$work/$name.log"
    failed=1
  fi
done < "$work/build/fuzzers.txt"
if [ "$ran" -ne 11 ]; then
  echo "!! $ran of the eleven fuzz targets ran to the end"
  failed=1
fi
exit "$failed"
