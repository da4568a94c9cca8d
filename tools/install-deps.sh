#!/usr/bin/env bash
# Installs every Debian 12 package brdf-toolchain needs to build, test, benchmark and render.
# Idempotent: packages already present are skipped, so a second run does nothing.
# Nothing is downloaded from outside Debian's archive (the npm package used by the KTX2 test
# is installed separately by tools/install-npm-deps.sh from the npm registry).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  ccache  # shares compiled objects between build trees (the emulation-off and fuzz sub-builds)
  libceres-dev libeigen3-dev
  libopenimageio-dev openimageio-tools libopenexr-dev
  libimath-dev libpng-dev zlib1g-dev python3-openimageio  # brdf::image_io and its oracle
  hyperfine time  # bench/startup.sh and the start-up test (GNU time's peak RSS)
  libvtk9-dev
  libusb-1.0-0-dev libhidapi-dev
  libcli11-dev nlohmann-json3-dev libfmt-dev libspdlog-dev libtbb-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  umockdev libumockdev-dev  # brdf::device_emulation and the usb tests (BRDF_BUILD_DEVICE_EMULATION)
  xvfb xauth
  clang libclang-rt-14-dev
  python3 python3-numpy python3-scipy
  python3-dev pybind11-dev python3-pybind11 python3-pytest  # the Python module (python/), its tests
  python3-matplotlib  # docs/python.md's worked example, run by tests/python_module (Agg backend)
  nodejs
  # Engine hand-off tests (tests/engines): real clients for the shipped files.
  chromium glslang-tools spirv-cross mono-mcs python3-openimageio
)
# brdf-view: DejaVu Sans draws the Greek letters (θ, φ) in the window's labels.
packages+=(fonts-dejavu-core)
# The interactive brdf-view test presses keys and moves the mouse in an Xvfb window.
packages+=(xdotool)
# The Debian package (cpack -G DEB): dpkg-shlibdeps computes Depends; its test checks it with
# lintian and renders the man pages with man-db.
packages+=(dpkg-dev lintian man-db)

# Debian's npm is a separate package; a Node.js that already ships npm (e.g. NodeSource's)
# conflicts with it, so npm is only requested when no npm command exists.
if ! command -v npm >/dev/null 2>&1; then
  packages+=(npm)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
  exit 0
fi

echo "install-deps: installing ${#missing[@]} package(s): ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -q
"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
