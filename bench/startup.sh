#!/usr/bin/env bash
# Start-up cost of `brdf` commands: median wall time (hyperfine, no shell) and median
# peak RSS (GNU time %M over 5 runs), for one build or two side by side.
#
#   bench/startup.sh NEW_BRDF [BASELINE_BRDF] [RUNS]
#
# BASELINE_BRDF is any other build of the tool, e.g. main's, copied before the change:
#   cmake --build build/dev --target brdf && cp build/dev/tools/brdf /tmp/brdf-main
# Prints a Markdown table (ratio = baseline / new). Needs hyperfine and GNU time
# (tools/install-deps.sh). Runs from a scratch folder that it removes.
set -euo pipefail

new=$(realpath "$1")
base=${2:+$(realpath "$2")}
runs=${3:-20}
repo=$(cd "$(dirname "$0")/.." && pwd)
samples=$repo/data-samples
work=$(mktemp -d "${TMPDIR:-/tmp}/brdf_startup_bench.XXXXXX")
trap 'rm -rf "$work"' EXIT
cd "$work"

# name|arguments (word-split; no argument contains a space)
commands=(
  "--version|--version"
  "materials|materials"
  "info|info $samples/captures/gold.bpc"
  "eval|eval $samples/materials/aluminium.json --in 40,0 --out 40,180"
  "capture (θin 0, 30°×15° grid)|capture --device sim --material gold --sample s --theta-in 0 --phi-out-step 30 --theta-out-step 15 --out c.bpc --force"
  "capture (full reference geometry, 109,440 samples)|capture --device sim --material gold --sample s --out c.bpc --force"
  "convert (writes EXR + PNG)|convert $samples/materials/aluminium.json --out luts --formats exr,png"
)

median_ms() {  # binary, args...: median wall time in ms
  local bin=$1
  shift
  # convert refuses to overwrite: each run starts without the previous outputs.
  hyperfine -N -w 2 -r "$runs" --prepare "rm -rf $work/luts" --export-json "$work/h.json" \
    "$bin $*" >/dev/null 2>&1
  /usr/bin/python3 -c 'import json,sys; print("%.1f" % (1000 * json.load(open(sys.argv[1]))["results"][0]["median"]))' "$work/h.json"
}

median_rss_mib() {  # binary, args...: median peak RSS in MiB over 5 runs
  local bin=$1
  shift
  local values=()
  for _ in 1 2 3 4 5; do
    rm -rf "$work/luts"
    /usr/bin/time -f %M -o "$work/t.txt" "$bin" "$@" >/dev/null 2>&1
    values+=("$(tail -n 1 "$work/t.txt")")
  done
  printf '%s\n' "${values[@]}" | sort -n | sed -n 3p | awk '{printf "%.1f", $1 / 1024}'
}

ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.0f×", a / b }'; }

if [ -n "$base" ]; then
  echo "| command | baseline median | new median | ratio | baseline peak RSS | new peak RSS | ratio |"
  echo "|---|---:|---:|---:|---:|---:|---:|"
else
  echo "| command | median | peak RSS |"
  echo "|---|---:|---:|"
fi
for entry in "${commands[@]}"; do
  name=${entry%%|*}
  read -r -a args <<<"${entry#*|}"
  t_new=$(median_ms "$new" "${args[@]}")
  m_new=$(median_rss_mib "$new" "${args[@]}")
  if [ -n "$base" ]; then
    t_base=$(median_ms "$base" "${args[@]}")
    m_base=$(median_rss_mib "$base" "${args[@]}")
    echo "| \`$name\` | $t_base ms | $t_new ms | $(ratio "$t_base" "$t_new") | $m_base MiB | $m_new MiB | $(ratio "$m_base" "$m_new") |"
  else
    echo "| \`$name\` | $t_new ms | $m_new MiB |"
  fi
done
echo
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg)"
