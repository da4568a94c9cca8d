#!/usr/bin/env bash
# Installs the npm packages the tests use (ktx-parse, an independent KTX2 parser; three, the
# three.js the web hand-off is rendered with in Chromium; ws, the DevTools protocol client) into
# tests/node/node_modules from the npm registry, exactly as tests/node/package-lock.json pins
# them. Idempotent: when the pinned versions are already installed it does nothing.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
dir="$root/tests/node"

if ! command -v npm >/dev/null 2>&1; then
  echo "install-npm-deps: npm not found; install Node.js with npm (tools/install-deps.sh installs nodejs)" >&2
  exit 1
fi

installed_version() {
  node -e "try { console.log(require('$dir/node_modules/$1/package.json').version) } catch { console.log('') }"
}
wanted_version() {
  node -e "console.log(require('$dir/package-lock.json').packages['node_modules/$1'].version)"
}

all_installed=1
for package in ktx-parse three ws; do
  if [ "$(installed_version "$package")" != "$(wanted_version "$package")" ]; then all_installed=0; fi
done
if [ "$all_installed" = 1 ]; then
  echo "install-npm-deps: ktx-parse, three and ws already installed as pinned"
  exit 0
fi
echo "install-npm-deps: installing tests/node dependencies from package-lock.json"
cd "$dir"
npm ci --no-audit --no-fund --loglevel=error
