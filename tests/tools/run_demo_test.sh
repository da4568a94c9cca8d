#!/usr/bin/env bash
# The README's main job (tools/run-demo.sh) on a reduced job, with the tools this build made,
# into a private folder; then its outputs are checked against the analytic materials they were
# captured from (demo_check.py, NumPy from the formulas).
# usage: run_demo_test.sh SOURCE_DIR TOOLS_DIR
set -euo pipefail
root="$1"
tools="$2"
out="$(mktemp -d "${TMPDIR:-/tmp}/brdf-demo-XXXXXX")"
trap 'rm -rf "$out"' EXIT
materials="gold paper_white wood_oak wood_walnut plastic_glossy_green plastic_glossy_red"
BRDF_DEMO_TOOLS="$tools" BRDF_DEMO_MATERIALS="$materials" BRDF_DEMO_PHI_OUT_STEP=2 \
  "$root/tools/run-demo.sh" "$out"
# shellcheck disable=SC2086
/usr/bin/python3 "$root/tests/tools/demo_check.py" "$out" "$root/data-samples/materials" $materials
