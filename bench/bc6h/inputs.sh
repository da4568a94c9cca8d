#!/bin/sh
# The inputs of the bench/bc6h scripts: every library material captured by the simulated
# scatterometer into WORK/noisy (the reference instrument's noise) and WORK/noise-free
# (--noise 0), and the RGL files of RGL_DIR imported into WORK/rgl.
#   bench/bc6h/inputs.sh BRDF WORK RGL_DIR
set -eu
brdf=$1
work=$2
rgl=$3
mkdir -p "$work/noisy" "$work/noise-free" "$work/rgl"
for m in $("$brdf" materials | awk 'NR > 1 { print $1 }'); do
  "$brdf" capture --device sim --material "$m" --sample "$m" --out "$work/noisy/$m.bpc" --quiet --force
  "$brdf" capture --device sim --material "$m" --sample "$m" --noise 0 \
    --out "$work/noise-free/$m.bpc" --quiet --force
done
for f in "$rgl"/*.bsdf; do
  "$brdf" import "$f" --out "$work/rgl/$(basename "$f" .bsdf).bpc" --force > /dev/null
done
