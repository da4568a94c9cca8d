#!/usr/bin/env bash
# End-to-end batch benchmark of `brdf convert`: 216 simulated captures (the size of
# the reference paper's dataset) to every format (KTX2, DDS, EXR, PNG, JSON sidecar), compared
# with the I/O floor: reading the same inputs and writing the same number of files of the same
# sizes, doing nothing else (bench/e2e/io_floor.cpp), once plainly and once with the exporters'
# durability (temporary file, fsync, rename, fsync of the folder, per file).
#
#   bench/e2e/convert_batch.sh [BUILD_DIR [REPETITIONS [JOBS]]]
#
# BRDF_CONVERT_ARGS adds options to every `brdf convert` run (e.g. "--exr-type half").
#
# Needs the targets brdf and bench_e2e_io_floor built in BUILD_DIR (default: build). The 216
# captures are made once with `brdf capture --device sim` (18 library materials × 12 noise
# seeds, the reference instrument's geometry and noise) and cached in BUILD_DIR/bench-e2e/;
# delete that folder to make new ones. Each repetition converts into a fresh folder under
# /usr/bin/time -v; medians over REPETITIONS (default 3) are printed. Outputs are deleted after
# each run (about 1 GB each).
set -euo pipefail

build=${1:-build}
reps=${2:-3}
jobs=${3:-2}
count=216
read -r -a extra <<< "${BRDF_CONVERT_ARGS:-}"
brdf=$build/tools/brdf
floor=$build/bench/bench_e2e_io_floor
work=$build/bench-e2e
caps=$work/captures

for exe in "$brdf" "$floor"; do
  [[ -x $exe ]] || { echo "missing $exe: build the targets brdf and bench_e2e_io_floor" >&2; exit 2; }
done

median() { sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }
# /usr/bin/time -v prints "Elapsed (wall clock) time (h:mm:ss or m:ss): 0:12.34".
wall_seconds() {
  awk -F': ' '/Elapsed \(wall clock\)/ {n = split($2, p, ":"); s = 0; for (i = 1; i <= n; ++i) s = s * 60 + p[i]; print s}' "$1"
}
field() { awk -F': ' -v k="$2" '$1 ~ k {print $2}' "$1"; }

# ---- inputs (cached) ----
mkdir -p "$caps" "$work/tmp"
mapfile -t materials < <("$brdf" materials --json | /usr/bin/python3 -c \
  'import json,sys; d=json.load(sys.stdin); print("\n".join(m["name"] for m in (d["materials"] if isinstance(d, dict) else d)))')
existing=$(find "$caps" -maxdepth 1 -name '*.bpc' | wc -l)
if (( existing < count )); then
  echo "making $count simulated captures in $caps (once) ..." >&2
  for ((i = 0; i < count; ++i)); do
    m=${materials[i % ${#materials[@]}]}
    name=$(printf 'cap_%03d_%s' "$i" "$m")
    [[ -f $caps/$name.bpc ]] || echo "$i $m $name"
  done | xargs -P "$jobs" -L 1 bash -c '
    seed=$1; material=$2; name=$3
    "'"$brdf"'" capture --device sim --material "$material" --sample "$name" --seed $((seed + 1)) \
      --out "'"$work"'/tmp/$name.bpc" --force --quiet &&
    mv "'"$work"'/tmp/$name.bpc" "'"$caps"'/$name.bpc"' _
fi
n=$(find "$caps" -maxdepth 1 -name '*.bpc' | wc -l)
in_bytes=$(find "$caps" -maxdepth 1 -name '*.bpc' -printf '%s\n' | awk '{s += $1} END {print s}')
echo "inputs: $n captures, $in_bytes bytes" >&2

load_start=$(cut -d' ' -f1-3 /proc/loadavg)

# ---- brdf convert ----
walls=() cpus=() rss=()
for ((r = 1; r <= reps; ++r)); do
  out=$work/out_$r
  rm -rf "$out"
  sync
  /usr/bin/time -v -o "$work/time_$r.txt" "$brdf" convert "$caps" --out "$out" --jobs "$jobs" --quiet "${extra[@]}" \
    > "$work/convert_$r.log"
  walls+=("$(wall_seconds "$work/time_$r.txt")")
  cpus+=("$(awk -F': ' '/User time|System time/ {s += $2} END {print s}' "$work/time_$r.txt")")
  rss+=("$(field "$work/time_$r.txt" 'Maximum resident set size')")
  if (( r == 1 )); then
    find "$out" -type f -printf '%f %s\n' | sort | awk '{print $2}' > "$work/sizes.txt"
    out_files=$(wc -l < "$work/sizes.txt")
    out_bytes=$(awk '{s += $1} END {print s}' "$work/sizes.txt")
    tail -1 "$work/convert_$r.log" >&2
  fi
  rm -rf "$out"
  echo "convert run $r: wall ${walls[-1]} s, CPU ${cpus[-1]} s, peak RSS ${rss[-1]} KB" >&2
done

# ---- I/O floor ----
plain=() durable=()
for ((r = 1; r <= reps; ++r)); do
  for mode in plain durable; do
    out=$work/floor_$r
    rm -rf "$out"
    sync
    flag=()
    [[ $mode == durable ]] && flag=(--durable)
    t=$("$floor" "${flag[@]}" --jobs "$jobs" "$caps" "$work/sizes.txt" "$out" | cut -d' ' -f1)
    rm -rf "$out"
    if [[ $mode == plain ]]; then plain+=("$t"); else durable+=("$t"); fi
    echo "floor run $r ($mode): $t s" >&2
  done
done
load_end=$(cut -d' ' -f1-3 /proc/loadavg)

w=$(printf '%s\n' "${walls[@]}" | median)
c=$(printf '%s\n' "${cpus[@]}" | median)
m=$(printf '%s\n' "${rss[@]}" | median)
fp=$(printf '%s\n' "${plain[@]}" | median)
fd=$(printf '%s\n' "${durable[@]}" | median)
awk -v n="$n" -v w="$w" -v c="$c" -v m="$m" -v fp="$fp" -v fd="$fd" -v ib="$in_bytes" \
    -v ob="$out_bytes" -v of="$out_files" -v reps="$reps" -v jobs="$jobs" \
    -v l0="$load_start" -v l1="$load_end" -v x="${BRDF_CONVERT_ARGS:-}" 'BEGIN {
  printf "brdf convert: %d captures (%.0f MB) -> %d files (%.0f MB), --jobs %d %s, %d repetitions\n", n, ib / 1e6, of, ob / 1e6, jobs, x, reps
  printf "load average at start %s, at end %s\n", l0, l1
  printf "median wall              %8.2f s   (%.1f ms per capture)\n", w, 1000 * w / n
  printf "median CPU (user+sys)    %8.2f s   (%.1f ms per capture)\n", c, 1000 * c / n
  printf "median peak RSS          %8.1f MB\n", m / 1024
  printf "I/O floor, plain         %8.2f s   ratio convert/floor %.2f\n", fp, w / fp
  printf "I/O floor, durable       %8.2f s   ratio convert/floor %.2f\n", fd, w / fd
}'
