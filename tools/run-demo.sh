#!/usr/bin/env bash
# The main job on the built-in defaults: installs the Debian packages, builds the toolchain,
# captures every material of the virtual sample library with the simulated scatterometer and
# converts the captures into engine-ready lookup textures and engine kits (luts/web/index.html:
# the environment-lit viewer, served by any local static file server).
# Usage: tools/run-demo.sh [OUT_DIR]   (default: out/demo)
# The test suite runs this same script on a reduced job (tests/tools/CMakeLists.txt, run_demo):
#   BRDF_DEMO_TOOLS=DIR        use the brdf and brdf-view already built in DIR (no install, no build)
#   BRDF_DEMO_MATERIALS="a b"  capture only these library materials (must include gold,
#                              plastic_glossy_red, wood_oak and paper_white, which the pictures use)
#   BRDF_DEMO_PHI_OUT_STEP=N   detector azimuth step in degrees (default: the instrument's 1°)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-$root/out/demo}"
build="$root/build/release"

if [ -n "${BRDF_DEMO_TOOLS:-}" ]; then
  tools="$BRDF_DEMO_TOOLS"
else
  "$root/tools/install-deps.sh"
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DBRDF_BUILD_TESTS=OFF -DBRDF_BUILD_BENCH=OFF >/dev/null
  cmake --build "$build" -j "$(nproc)" --target brdf brdf-view brdf_python_module
  tools="$build/tools"
fi
brdf="$tools/brdf"
capture_options=()
if [ -n "${BRDF_DEMO_PHI_OUT_STEP:-}" ]; then
  capture_options+=(--phi-out-step "$BRDF_DEMO_PHI_OUT_STEP")
fi

mkdir -p "$out/captures"
echo "== capturing the virtual sample library with the simulated scatterometer -> $out/captures"
"$brdf" materials
materials="${BRDF_DEMO_MATERIALS:-$("$brdf" materials --json | /usr/bin/python3 -c 'import json,sys; print(" ".join(m["name"] for m in json.load(sys.stdin)))')}"
for material in $materials; do
  "$brdf" capture --device sim --material "$material" --sample "$material" \
    --out "$out/captures/$material.bpc" --seed 1 --force "${capture_options[@]}"
done
echo "== converting captures to RGB9E5 lookup textures and engine kits -> $out/luts"
"$brdf" convert "$out/captures" --out "$out/luts" --force --engine all
# The web kit's viewer loads three.js from ./node_modules/three/: the pinned copy the tests use
# (tools/install-npm-deps.sh, from the local npm cache), so the page works from a local file
# server with no network.
if [ -z "${BRDF_DEMO_TOOLS:-}" ]; then "$root/tools/install-npm-deps.sh"; fi
if "$root/tools/copy-web-three.sh" "$out/luts/web"; then
  echo "environment-lit viewer: python3 -m http.server -d $out/luts/web 8000, then open"
  echo "  http://localhost:8000/index.html?material=gold&env=studio&ibl=1&lights=0&tonemap=linear"
else
  echo "environment-lit viewer: without three.js; run tools/install-npm-deps.sh, or npm install in $out/luts/web"
fi
echo "== packing the library into one atlas -> $out/atlas"
mkdir -p "$out/atlas"
"$brdf" atlas "$out/captures" --out "$out/atlas/library" --force
echo "== environment-lit previews (studio map) -> $out/previews"
mkdir -p "$out/previews"
for material in gold plastic_glossy_red wood_oak; do
  "$brdf" preview "$root/data-samples/materials/$material.json" --size 384 --quiet --force \
    --out "$out/previews/$material.png"
done
"$brdf" preview "$out/luts/gold.ktx2" --compare "$root/data-samples/materials/gold.json" \
  --size 256 --quiet --force --out "$out/previews/gold_lut_vs_material.png"
# Pictures to look at: the reflection lobe of a few captures (brdf-view renders under
# xvfb-run by itself when there is no display).
mkdir -p "$out/pictures"
echo "== lobe pictures -> $out/pictures"
for material in gold plastic_glossy_red wood_oak paper_white; do
  "$tools/brdf-view" "$out/captures/$material.bpc" --mode lobe --theta-in 40 \
    --size 960x720 --force --screenshot "$out/pictures/$material-lobe.png"
done
"$tools/brdf-view" "$out/captures/gold.bpc" --mode slices --theta-in 40 \
  --size 960x600 --force --screenshot "$out/pictures/gold-slices.png"
echo "== done: $(ls "$out/captures" | wc -l) captures in $out/captures, LUTs in $out/luts, atlas in $out/atlas, previews in $out/previews, pictures in $out/pictures"
"$brdf" info "$out/luts/gold.ktx2"
