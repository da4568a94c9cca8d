#!/usr/bin/env bash
# Installs dependencies, builds everything from a clean build directory and runs every test.
# Usage: tools/test.sh [BUILD_DIR]   (default: build/test)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build/test}"
"$root/tools/install-deps.sh"
if [ -x "$root/tools/install-npm-deps.sh" ]; then "$root/tools/install-npm-deps.sh"; fi
# The emulation-off build of the tests sits beside the build folder (tests/device/CMakeLists.txt).
rm -rf "$build" "$build-emulation-off"
# Compiled objects do not depend on the build folder's name: let ccache (when installed) share
# them between this build and the sub-builds the tests make.
export CCACHE_NOHASHDIR=1
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake --build "$build" -j "$(nproc)"
cd "$build"
ctest --output-on-failure -j "$(nproc)" --timeout 900
