#!/usr/bin/env bash
# Builds and installs the Python package the way a user would, from source,
# with Debian's tools only (no PyPI): pip install --no-build-isolation ./python
# and python3 -m build --no-isolation --wheel, each in a fresh virtual
# environment, each configuring and building the C++ engine through setup.py
# (CMake, Ninja, ccache when present). The installed packages pass the Python
# tests from outside the source tree; prints the wheel's size, its declared
# dependencies and the Debian packages of the shared libraries it links.
# Minutes on a cold ccache; the ctest variant (Python.package) copies the
# extension from ./build instead.
#
# usage: bash tools/python-package.sh    (after bash tools/build.sh)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/tools/setup-debian.sh"
export SFC_CLI=${SFC_CLI:-$root/build/client/sfcsampler}
export SFC_SERVER=${SFC_SERVER:-$root/build/server/sfcsampler-server}
export SFC_CAD_FIXTURES=${SFC_CAD_FIXTURES:-$root/build/cad/make_cad_fixtures}
export SFC_PACKAGE_TESTS=${SFC_PACKAGE_TESTS:-test_meshes.py test_many.py test_embedded.py}
export SFCSAMPLER_BUILD_JOBS=${SFCSAMPLER_BUILD_JOBS:-2}
# setup.py builds in python/build/cmake; start from a clean one each time.
rm -rf "$root/python/build" "$root/python"/*.egg-info
nice -n 5 bash "$root/python/tests/package_test.sh" "$root"
