#!/bin/sh
# Instructions inside EncodeBc6hVolume (callgrind: repeatable on a loaded machine) of two
# bench_bc6h builds on the same LUTs, one LUT per run (docs/benchmarks/bc6h.md):
#   bench/bc6h/callgrind_pair.sh LUT_DIR OUT_DIR BASE_BINARY NEW_BINARY NAME...
# NAME is a composite LUT_DIR/NAME.exr; prints one line per NAME: base and new instruction
# counts and new / base. bench_bc6h --checksums encodes every composite of its folder once, so
# each NAME gets a folder of its own under OUT_DIR.
set -eu
dir=$1
out=$2
base=$3
new=$4
shift 4
mkdir -p "$out"
count() {  # BINARY LUT_FOLDER CALLGRIND_OUT
  BRDF_BC6H_LUTS=$2 valgrind --tool=callgrind --callgrind-out-file="$3" \
    '--toggle-collect=brdf::exporter::EncodeBc6hVolume*' "$1" --checksums 2>&1 |
    awk '/Collected/ { print $4 }'
}
printf '%-24s %15s %15s %8s\n' lut base new ratio
for name in "$@"; do
  mkdir -p "$out/luts/$name"
  ln -sf "$(realpath "$dir/$name.exr")" "$out/luts/$name/$name.exr"
  b=$(count "$base" "$out/luts/$name" "$out/base-$name.callgrind")
  n=$(count "$new" "$out/luts/$name" "$out/new-$name.callgrind")
  printf '%-24s %15s %15s %8.3f\n' "$name" "$b" "$n" "$(echo "$n / $b" | bc -l)"
done
