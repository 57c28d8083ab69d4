#!/usr/bin/env bash
# Sets up and builds all of sfcsampler in ./build (Release, two jobs): the
# server, the tests, the benchmarks, Python, CAD and meshes; the log goes to
# build/build.log. tools/sample.sh builds only the CLI.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup-debian.sh
mkdir -p build
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DSFC_BUILD_SERVER=ON -DSFC_BUILD_TESTS=ON \
  -DSFC_BUILD_BENCHMARKS=ON -DSFC_BUILD_PYTHON=ON -DSFC_BUILD_CAD=ON -DSFC_BUILD_MESH=ON \
  > build/build.log 2>&1 || { cat build/build.log; exit 1; }
cmake --build build -j2 >> build/build.log 2>&1 || { tail -50 build/build.log; exit 1; }
