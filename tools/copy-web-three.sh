#!/usr/bin/env bash
# Copies the pinned three.js the tests use (tests/node/node_modules/three, from
# tools/install-npm-deps.sh) into WEB_DIR/node_modules/three/, where the web kit's viewer
# (index.html) loads it from, so the page works from a local file server with no network.
# Used by tools/run-demo.sh and by the demo page's browser test (tests/engines/demo_web_test.py).
# Usage: tools/copy-web-three.sh WEB_DIR   (exit 1, copying nothing, when three.js is not installed)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
web="${1:?usage: tools/copy-web-three.sh WEB_DIR}"
three="$root/tests/node/node_modules/three"
if [ ! -f "$three/build/three.module.js" ]; then
  echo "copy-web-three: three.js not found ($three); run tools/install-npm-deps.sh" >&2
  exit 1
fi
mkdir -p "$web/node_modules/three/examples"
cp -r "$three/build" "$three/package.json" "$web/node_modules/three/"
cp -r "$three/examples/jsm" "$web/node_modules/three/examples/"
