#!/usr/bin/env bash
# Time from starting brdf-view to its first picture (target < 1 s), median of N runs, with
# baselines in the same run:
#   window only   brdf-view on a file that does not exist: process start, VTK/X window, text,
#                 one render and the PNG, without opening or drawing any source;
#   brdf eval     opening the same material with the `brdf` tool and evaluating one pair
#                 (process start and file opening, no window).
# One Xvfb serves every run (xvfb-run around this script), so its start-up is not counted.
# usage: bench/viewer/first_picture.sh BUILD_DIR [RUNS]
set -euo pipefail
build=${1:?usage: first_picture.sh BUILD_DIR [RUNS]}
runs=${2:-5}
here=$(cd "$(dirname "$0")/../.." && pwd)
if [ -z "${DISPLAY:-}" ]; then exec xvfb-run -a -s "-screen 0 1280x1024x24" "$0" "$@"; fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
view=$build/tools/brdf-view
tool=$build/tools/brdf
gold=$here/data-samples/materials/gold.json
median() { sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }  # of one column
time_ms() {  # runs "$@" once, prints wall and CPU (user + system) milliseconds
  /usr/bin/time -f "%e %U %S" -o "$tmp/time.txt" "$@" >/dev/null 2>&1 || true
  tail -n 1 "$tmp/time.txt" | awk '{printf "%d %d\n", $1 * 1000, ($2 + $3) * 1000}'
}
declare -A results
for name in lobe slices window_only brdf_eval; do
  for i in $(seq "$runs"); do
    case $name in
      lobe) time_ms "$view" "$gold" --mode lobe --theta-in 30 --screenshot "$tmp/a.png" ;;
      slices) time_ms "$view" "$gold" --mode slices --screenshot "$tmp/b.png" ;;
      window_only) time_ms "$view" "$tmp/missing.bpc" --screenshot "$tmp/c.png" ;;
      brdf_eval) time_ms "$tool" eval "$gold" --in 30,0 --out 30,180 ;;
    esac
  done > "$tmp/$name.txt"
  results[$name]="$(cut -d' ' -f1 "$tmp/$name.txt" | median) $(cut -d' ' -f2 "$tmp/$name.txt" | median)"
done
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg)"
for name in lobe slices window_only brdf_eval; do
  read -r wall cpu <<< "${results[$name]}"
  printf '%-12s median wall %5d ms, CPU %5d ms over %d runs\n' "$name" "$wall" "$cpu" "$runs"
done
