#!/usr/bin/env bash
# Proves that the production tool builds and runs without umockdev: configures the project with
# BRDF_BUILD_DEVICE_EMULATION=OFF in its own build folder (WORK_DIR, below the calling build
# tree), builds only the `brdf` target (compiled objects come from ccache when the top-level
# CMakeLists finds it; a rerun of the test is an up-to-date check), then checks that
#   - the configure step never looked for umockdev (no UMOCKDEV entry in its cache);
#   - `brdf` needs no libumockdev, neither directly (readelf -d) nor through another library
#     (ldd), while REFERENCE_BRDF, the tool of a build with the emulation, does (so the check
#     can tell the two apart);
#   - `brdf capture --device sim` over the loopback still writes a capture `brdf info` reads;
#   - asking for an emulated transport is refused in one line saying it is not in this build,
#     and `brdf capture --help` says the same.
# Used by the `brdf_builds_without_device_emulation` ctest test; by hand:
#   tests/device/build_without_emulation.sh SOURCE_DIR WORK_DIR [REFERENCE_BRDF]
set -euo pipefail
src="$(cd "$1" && pwd)"
work="$2"
reference="${3:-}"
mkdir -p "$work"
# The build folder is WORK_DIR itself (logs and scratch files inside it): placed beside the
# calling build tree, at the same depth below the source, the compile commands match that
# tree's (ccache's base_dir makes paths relative to the build folder), and with
# CCACHE_NOHASHDIR the build folder's own name is not hashed either, so the libraries come
# from the cache and only the tool's own objects are compiled.
build="$work"
export CCACHE_NOHASHDIR=1

fail() {
  echo "FAIL: $*" >&2
  exit 1
}

# The same compilers as the calling build, so ccache can serve its objects.
compilers=()
[ -n "${BRDF_CC:-}" ] && compilers+=("-DCMAKE_C_COMPILER=$BRDF_CC")
[ -n "${BRDF_CXX:-}" ] && compilers+=("-DCMAKE_CXX_COMPILER=$BRDF_CXX")
cmake -S "$src" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "${compilers[@]}" \
  -DBRDF_BUILD_DEVICE_EMULATION=OFF -DBRDF_BUILD_TESTS=OFF -DBRDF_BUILD_BENCH=OFF \
  -DBRDF_BUILD_VIEWER=OFF > "$work/brdf-configure.log" 2>&1 || { cat "$work/brdf-configure.log"; exit 1; }
cmake --build "$build" --target brdf -j "${BRDF_SUBBUILD_JOBS:-2}" > "$work/brdf-build.log" 2>&1 ||
  { tail -60 "$work/brdf-build.log"; exit 1; }
tool="$build/tools/brdf"
[ -x "$tool" ] || fail "the build produced no $tool"

lookup="$(grep -i '^UMOCKDEV' "$build/CMakeCache.txt" | head -1 || true)"
[ -z "$lookup" ] || fail "the configure step looked for umockdev: $lookup"

needs_umockdev() {  # $1: a program; prints what names umockdev in its dynamic section or ldd
  { readelf -d "$1" | grep NEEDED; ldd "$1"; } | grep -i umockdev || true
}
if [ -n "$reference" ]; then
  [ -n "$(needs_umockdev "$reference")" ] ||
    fail "the check cannot see umockdev even in the emulation build's $reference"
fi
found="$(needs_umockdev "$tool")"
[ -z "$found" ] || fail "brdf built without the emulation still needs umockdev: $found"
echo "brdf links no umockdev library ($(readelf -d "$tool" | grep -c NEEDED) direct dependencies)"

scratch="$(mktemp -d "$work/run.XXXXXX")"
trap 'rm -rf "$scratch"' EXIT
"$tool" capture --device sim --material gold --sample gold --theta-in 0,20 \
  --theta-out-step 5 --phi-out-step 10 --noise 0 --quiet --out "$scratch/gold.bpc" ||
  fail "brdf capture --device sim failed"
"$tool" info --json "$scratch/gold.bpc" > "$scratch/info.json" ||
  fail "brdf info of the capture failed"
/usr/bin/python3 - "$scratch/info.json" <<'EOF' || fail "the capture is not the one asked for"
import json, sys
info = json.load(open(sys.argv[1]))
# 2 slices of (75 / 5 + 1) θout rows × (360 / 10) φout columns, as requested.
assert info["theta_in_deg"] == [0.0, 20.0], info["theta_in_deg"]
assert info["sample_count"] == 2 * 16 * 36, info["sample_count"]
EOF

set +e
"$tool" capture --device sim --transport usb --material gold --sample gold --quiet \
  --out "$scratch/usb.bpc" > "$scratch/usb.out" 2> "$scratch/usb.err"
code=$?
set -e
[ "$code" -ne 0 ] || fail "--transport usb succeeded in a build without the emulation"
message="$(cat "$scratch/usb.err")"
[ "$(wc -l < "$scratch/usb.err")" -eq 1 ] || fail "expected one line, got: $message"
grep -q "not part of this build" <<< "$message" || fail "unexpected message: $message"
[ ! -e "$scratch/usb.bpc" ] || fail "the refused capture wrote a file"
"$tool" capture --help | grep -q "the emulated usb and hid transports are not part of this build" ||
  fail "capture --help does not say that this build has no emulated transports"
echo "ok: $message"
