#!/usr/bin/env bash
# The main job on the built-in defaults: installs the Debian packages, builds the toolchain,
# captures every material of the virtual sample library with the simulated scatterometer and
# converts the captures into engine-ready lookup textures.
# Usage: tools/run-demo.sh [OUT_DIR]   (default: out/demo)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-$root/out/demo}"
build="$root/build/release"

"$root/tools/install-deps.sh"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DBRDF_BUILD_TESTS=OFF -DBRDF_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" -j "$(nproc)" --target brdf
brdf="$build/tools/brdf"

mkdir -p "$out/captures"
echo "== capturing the virtual sample library with the simulated scatterometer -> $out/captures"
"$brdf" materials
for material in $("$brdf" materials --json | /usr/bin/python3 -c 'import json,sys; print(" ".join(m["name"] for m in json.load(sys.stdin)))'); do
  "$brdf" capture --device sim --material "$material" --sample "$material" \
    --out "$out/captures/$material.bpc" --seed 1 --force
done
echo "== converting captures to RGB9E5 lookup textures -> $out/luts"
"$brdf" convert "$out/captures" --out "$out/luts" --force
echo "== packing the library into one atlas -> $out/atlas"
mkdir -p "$out/atlas"
"$brdf" atlas "$out/captures" --out "$out/atlas/library" --force
echo "== environment-lit previews (studio map) -> $out/previews"
mkdir -p "$out/previews"
for material in gold plastic_glossy_red wood_oak; do
  "$brdf" preview "$root/data-samples/materials/$material.json" --size 384 --spp 64 --quiet \
    --out "$out/previews/$material.png"
done
"$brdf" preview "$out/luts/gold.ktx2" --compare "$root/data-samples/materials/gold.json" \
  --size 256 --spp 64 --quiet --out "$out/previews/gold_lut_vs_material.png"
# Pictures to look at: the reflection lobe of a few captures (brdf-view renders under
# xvfb-run by itself when there is no display).
cmake --build "$build" -j "$(nproc)" --target brdf-view
mkdir -p "$out/pictures"
echo "== lobe pictures -> $out/pictures"
for material in gold plastic_glossy_red wood_oak paper_white; do
  "$build/tools/brdf-view" "$out/captures/$material.bpc" --mode lobe --theta-in 40 \
    --size 960x720 --screenshot "$out/pictures/$material-lobe.png"
done
"$build/tools/brdf-view" "$out/captures/gold.bpc" --mode slices --theta-in 40 \
  --size 960x600 --screenshot "$out/pictures/gold-slices.png"
echo "== done: $(ls "$out/captures" | wc -l) captures in $out/captures, LUTs in $out/luts, atlas in $out/atlas, previews in $out/previews, pictures in $out/pictures"
"$brdf" info "$out/luts/gold.ktx2"
