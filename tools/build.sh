#!/usr/bin/env bash
# Configures and builds sfcsampler in ./build (Release, two jobs); the log
# goes to build/build.log.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup-debian.sh
mkdir -p build
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release > build/build.log 2>&1 || { cat build/build.log; exit 1; }
cmake --build build -j2 >> build/build.log 2>&1 || { tail -50 build/build.log; exit 1; }
