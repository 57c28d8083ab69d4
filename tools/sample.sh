#!/usr/bin/env bash
# The main job in one command: sets up what the CLI needs, builds the CLI
# alone, and samples a surface in process. Arguments go to `sfcsampler
# sample`; without any it writes 100000 jittered-Hilbert samples of the unit
# sphere to samples.ply.
#
# On a fresh clone it installs the few packages sampling needs
# (tools/setup-debian.sh sample) and builds the CLI with the formula kind
# only; a ./build configured by tools/build.sh (the tests command) is used as
# it is, with every kind (CAD models and meshes too).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bash "$root/tools/setup-debian.sh" sample
mkdir -p "$root/build"
if [ ! -f "$root/build/build.ninja" ]; then
  cmake -S "$root" -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DSFC_BUILD_SERVER=OFF \
    -DSFC_BUILD_TESTS=OFF -DSFC_BUILD_BENCHMARKS=OFF -DSFC_BUILD_PYTHON=OFF -DSFC_BUILD_CAD=OFF \
    -DSFC_BUILD_MESH=OFF > "$root/build/build.log" 2>&1 || { cat "$root/build/build.log"; exit 1; }
fi
cmake --build "$root/build" --target sfcsampler -j2 >> "$root/build/build.log" 2>&1 ||
  { tail -50 "$root/build/build.log"; exit 1; }
if [ $# -eq 0 ]; then
  set -- --surface sphere --density uniform --count 100000 --format ply --output samples.ply
fi
exec "$root/build/client/sfcsampler" sample "$@"
