#!/bin/sh
# The installed layout of the virtual sample library (brdf/sources/material_library.h):
# `cmake --install` puts the material files in <prefix>/share/brdf-toolchain/materials and the
# installed `brdf` finds them from its own folder, also after the whole tree is moved; a file of
# the same name in the current folder wins over a library name. The expected files are the
# source tree's own, byte for byte.
# Usage: installed_library_test.sh BUILD_DIR SOURCE_DIR
set -eu
build=$1
source=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/brdf-installed-XXXXXX")
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$work/prefix" >/dev/null
unset BRDF_MATERIALS_DIR
check() {  # check PREFIX: the library of the brdf installed under PREFIX
  lib="$1/share/brdf-toolchain/materials"
  for f in "$source"/data-samples/materials/*.json; do
    cmp -s "$f" "$lib/$(basename "$f")" || fail "$lib/$(basename "$f") differs from $f"
  done
  listed=$("$1/bin/brdf" materials --json | grep '"file"' | grep -c "\"$lib/") ||
    fail "brdf materials lists no file under $lib"
  want=$(ls "$source"/data-samples/materials/*.json | wc -l)
  [ "$listed" -eq "$want" ] || fail "brdf materials lists $listed files under $lib, expected $want"
  # A library name is read from the installed copy (and says so when it fails to parse).
  cp "$lib/gold.json" "$work/gold.json.saved"
  echo '{"model": ' >"$lib/gold.json"
  if "$1/bin/brdf" eval gold --in 30,0 --out 30,180 2>"$work/err"; then fail "broken gold.json read"; fi
  grep -q "$lib/gold.json" "$work/err" || fail "the error does not name $lib/gold.json: $(cat "$work/err")"
  cp "$work/gold.json.saved" "$lib/gold.json"
  "$1/bin/brdf" eval gold --in 30,0 --out 30,180 >/dev/null || fail "eval gold failed"
}
check "$work/prefix"
mv "$work/prefix" "$work/moved"
check "$work/moved"

# A file named like a library material, in the current folder, wins.
mkdir "$work/here"
echo '{"model": "lambert", "rho": [0.5, 0.5, 0.5]}' >"$work/here/gold"
got=$(cd "$work/here" && "$work/moved/bin/brdf" eval gold --in 30,0 --out 30,180)
# Lambert: ρ/π = 0.5/π = 0.159154943 in every channel.
[ "$got" = "0.159154943 0.159154943 0.159154943" ] || fail "./gold not read first: $got"
echo "ok"
