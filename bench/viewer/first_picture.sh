#!/usr/bin/env bash
# Time from starting brdf-view to its first picture (target < 1 s), medians of N runs.
#
#   first frame   `brdf-view gold.json --mode lobe --theta-in 30` opening a window on an X
#                 display that already runs: from the kernel's start of the process to the
#                 first frame rendered and processed by the X server, as the program reports it
#                 with BRDF_VIEW_TIMING=1 (wall and CPU of all its threads; 10 ms resolution for
#                 the start). The window is closed (SIGTERM) as soon as that line appears.
#   first frame, cold shader cache   the same with MESA_SHADER_CACHE_DISABLE=true: Mesa compiles
#                 every shader as on the first run after installing (or after a driver update);
#                 the other cases run with the cache in ~/.cache/mesa_shader_cache warm.
#   lobe / slices the whole `--screenshot` run (process start to exit, PNG written), measured
#                 from outside with /usr/bin/time: wall and user + system CPU.
#   window only   a screenshot of a file that does not exist: process start, window, text, one
#                 render and the PNG, without opening or drawing any source.
#   brdf eval     opening the same material with the `brdf` tool and evaluating one pair
#                 (process start and file opening, no window).
#
# With a second brdf-view (BASELINE, e.g. one built from an older commit), every case runs for
# both executables, interleaved run by run, so both see the same machine load.
# The X display is $DISPLAY if set; otherwise one Xvfb is started for the whole script (by
# xvfb-run around it), so starting an X server is never part of a figure.
# usage: bench/viewer/first_picture.sh BUILD_DIR [RUNS] [BASELINE_BRDF_VIEW]
set -euo pipefail
build=${1:?usage: first_picture.sh BUILD_DIR [RUNS] [BASELINE_BRDF_VIEW]}
runs=${2:-5}
baseline=${3:-}
here=$(cd "$(dirname "$0")/../.." && pwd)
if [ -z "${DISPLAY:-}" ]; then exec xvfb-run -a -s "-screen 0 1280x1024x24" "$0" "$@"; fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
tool=$build/tools/brdf
gold=$here/data-samples/materials/gold.json
declare -A views=([new]="$build/tools/brdf-view")
if [ -n "$baseline" ]; then views[baseline]=$baseline; fi
median() { sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }  # of one column
time_ms() {  # runs "$@" once, prints wall and CPU (user + system) milliseconds
  /usr/bin/time -f "%e %U %S" -o "$tmp/time.txt" "$@" >/dev/null 2>&1 || true
  tail -n 1 "$tmp/time.txt" | awk '{printf "%d %d\n", $1 * 1000, ($2 + $3) * 1000}'
}
first_frame_ms() {  # $1 = brdf-view [$2 = VAR=value]; prints the wall and CPU ms it reports
  local log=$tmp/first_frame.txt
  : > "$log"
  env BRDF_VIEW_TIMING=1 ${2:-} "$1" "$gold" --mode lobe --theta-in 30 > /dev/null 2> "$log" &
  local pid=$!
  for _ in $(seq 1500); do
    grep -q "first frame" "$log" && break
    kill -0 "$pid" 2> /dev/null || break
    sleep 0.02
  done
  kill "$pid" 2> /dev/null || true
  wait "$pid" 2> /dev/null || true
  # "brdf-view: timing: first frame at 734 ms wall, 301 ms CPU after process start"
  awk '/first frame/ {print $6, $9; found = 1} END {if (!found) print "-1 -1"}' "$log"
}
cases="first_frame first_frame_cold lobe slices window_only"
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
for i in $(seq "$runs"); do
  for name in $cases; do
    for which in "${!views[@]}"; do
      view=${views[$which]}
      case $name in
        first_frame) first_frame_ms "$view" ;;
        first_frame_cold) first_frame_ms "$view" MESA_SHADER_CACHE_DISABLE=true ;;
        lobe) time_ms "$view" "$gold" --mode lobe --theta-in 30 --screenshot "$tmp/a.png" ;;
        slices) time_ms "$view" "$gold" --mode slices --screenshot "$tmp/b.png" ;;
        window_only) time_ms "$view" "$tmp/missing.bpc" --screenshot "$tmp/c.png" ;;
      esac >> "$tmp/$name.$which.txt"
    done
  done
  time_ms "$tool" eval "$gold" --in 30,0 --out 30,180 >> "$tmp/brdf_eval.txt"
done
echo "load average after:  $(cut -d' ' -f1-3 /proc/loadavg)"
report() {  # $1 = label, $2 = file
  printf '%-30s median wall %5d ms, CPU %5d ms over %d runs\n' "$1" \
    "$(cut -d' ' -f1 "$2" | median)" "$(cut -d' ' -f2 "$2" | median)" "$runs"
}
for name in $cases; do
  for which in "${!views[@]}"; do report "$name ($which)" "$tmp/$name.$which.txt"; done
done
report "brdf eval" "$tmp/brdf_eval.txt"
