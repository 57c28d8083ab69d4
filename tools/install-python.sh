#!/usr/bin/env bash
# Sets up (Debian bookworm packages only), builds, and installs the Python
# package sfcsampler for Debian's python3 (/usr/local/lib/python3.X/dist-packages).
# Without installing, `PYTHONPATH=build/python python3` finds it after tools/build.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
$sudo cmake --install build --component python
cd / && /usr/bin/python3 -c 'import sfcsampler; print("sfcsampler", sfcsampler.ALGORITHM_VERSION, "installed at", sfcsampler.__path__[0])'
