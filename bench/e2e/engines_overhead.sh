#!/usr/bin/env bash
# Time `brdf convert --engine all` adds to a 216-capture batch (target: under 25 %):
# the same captures converted with the default formats, alternately without and with
# --engine all, REPETITIONS times each, into fresh folders; medians of wall and CPU
# (user + system) time from /usr/bin/time -v. Alternating keeps both configurations under the
# same machine load.
#
#   bench/e2e/engines_overhead.sh [BUILD_DIR [REPETITIONS [JOBS [OTHER_BRDF]]]]
#
# BRDF_BENCH_OUT (optional) is the folder the outputs go to (default BUILD_DIR/bench-e2e), e.g.
# a tmpfs (/dev/shm/...) to time the work without the disk, whose contention on a shared
# machine dominates the wall times.
#
# OTHER_BRDF (optional): another build of the brdf tool (e.g. before a change) whose
# `--engine all` runs are interleaved with the others as a third configuration, "other".
#
# Uses the captures bench/e2e/convert_batch.sh makes and caches in BUILD_DIR/bench-e2e/captures
# (run it once first).
set -euo pipefail
build=${1:-build}
reps=${2:-3}
jobs=${3:-2}
other=${4:-}
brdf=$build/tools/brdf
configs=(base engines)
[[ -n $other ]] && configs+=(other)
work=$build/bench-e2e
caps=$work/captures
[[ -x $brdf ]] || { echo "missing $brdf: build the target brdf" >&2; exit 2; }
n=$(find "$caps" -maxdepth 1 -name '*.bpc' 2>/dev/null | wc -l)
(( n > 0 )) || { echo "no captures in $caps: run bench/e2e/convert_batch.sh $build once" >&2; exit 2; }

median() { sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }
wall_seconds() {
  awk -F': ' '/Elapsed \(wall clock\)/ {n = split($2, p, ":"); s = 0; for (i = 1; i <= n; ++i) s = s * 60 + p[i]; print s}' "$1"
}
cpu_seconds() { awk -F': ' '/User time|System time/ {s += $2} END {print s}' "$1"; }

declare -A walls cpus
load_start=$(cut -d' ' -f1-3 /proc/loadavg)
for ((r = 1; r <= reps; ++r)); do
  for config in "${configs[@]}"; do
    out=${BRDF_BENCH_OUT:-$work}/eng_$config
    rm -rf "$out"
    sync
    extra=()
    exe=$brdf
    [[ $config != base ]] && extra=(--engine all)
    [[ $config == other ]] && exe=$other
    /usr/bin/time -v -o "$work/eng_time.txt" "$exe" convert "$caps" --out "$out" --jobs "$jobs" \
      --quiet "${extra[@]}" > "$work/eng_convert.log"
    walls[$config]+="$(wall_seconds "$work/eng_time.txt") "
    cpus[$config]+="$(cpu_seconds "$work/eng_time.txt") "
    if (( r == 1 )); then
      echo "$config: $(find "$out" -type f | wc -l) files, $(du -sm "$out" | cut -f1) MB ($(find "$out" -type f -links +1 | wc -l) hard-linked)" >&2
    fi
    rm -rf "$out"
  done
done
load_end=$(cut -d' ' -f1-3 /proc/loadavg)
for config in "${configs[@]}"; do
  w=$(tr ' ' '\n' <<< "${walls[$config]}" | grep . | median)
  wmin=$(tr ' ' '\n' <<< "${walls[$config]}" | grep . | sort -g | head -1)
  c=$(tr ' ' '\n' <<< "${cpus[$config]}" | grep . | median)
  echo "$config: $n captures, jobs $jobs, $reps runs: wall median $w s, min $wmin s; cpu median $c s (walls: ${walls[$config]}; cpus: ${cpus[$config]})"
  eval "w_$config=$w m_$config=$wmin c_$config=$c"
done
# On a shared machine the minimum wall time is the least disturbed run; CPU time is load-proof.
awk -v wb="$w_base" -v we="$w_engines" -v mb="$m_base" -v me="$m_engines" -v cb="$c_base" -v ce="$c_engines" \
  'BEGIN {printf "--engine all adds %.1f %% wall (median), %.1f %% wall (minimum), %.1f %% cpu (median)\n", (we / wb - 1) * 100, (me / mb - 1) * 100, (ce / cb - 1) * 100}'
if [[ -n $other ]]; then
  awk -v wb="$w_base" -v we="$w_other" -v mb="$m_base" -v me="$m_other" -v cb="$c_base" -v ce="$c_other" \
    'BEGIN {printf "other --engine all adds %.1f %% wall (median), %.1f %% wall (minimum), %.1f %% cpu (median)\n", (we / wb - 1) * 100, (me / mb - 1) * 100, (ce / cb - 1) * 100}'
fi
echo "load average: start $load_start, end $load_end"
