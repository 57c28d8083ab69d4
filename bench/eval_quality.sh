#!/bin/sh
# Issue 19's full quality report, with the CAD and mesh spheres made first:
#   bench/eval_quality.sh [BUILD_DIR=build] [OUT_DIR=eval-quality]
# Prints the report (also OUT_DIR/quality.md) and the blue-noise table with
# scipy's references (OUT_DIR/blue_noise.md). ~30 min on two busy cores.
set -eu
build="${1:-build}"
out="${2:-eval-quality}"
models="$out/models"
mkdir -p "$models"
"$build/cad/make_cad_fixtures" "$models" > /dev/null
"$build/bench/icosphere_ply" "$models/icosphere80k.ply" > /dev/null
nice -n 5 "$build/client/sfcsampler" eval --setting full --sections quality \
  --step-sphere "step:$models/sphere.step" --mesh-sphere "ply:$models/icosphere80k.ply" --out-dir "$out"
nice -n 5 /usr/bin/python3 "$(dirname "$0")/blue_noise.py" "$build/client/sfcsampler" 1,2,3 | tee "$out/blue_noise.md"
