#!/usr/bin/env bash
# The main job in one command: sets up, builds, and samples a surface
# in-process. Arguments go to `sfcsampler sample`; without any it writes
# 100000 jittered-Hilbert samples of the unit sphere to samples.ply.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bash "$root/tools/build.sh"
if [ $# -eq 0 ]; then
  set -- --surface sphere --density uniform --count 100000 --format ply --output samples.ply
fi
exec "$root/build/client/sfcsampler" sample "$@"
