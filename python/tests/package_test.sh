#!/usr/bin/env bash
# The Python package installed like any other, in virtual environments
# (python3 -m venv --system-site-packages: Debian's NumPy and Dask),
# with Debian's build tools and no PyPI:
#   1. pip install --no-build-isolation ./python
#   2. python3 -m build --no-isolation --wheel, then pip install of that wheel
#      into a second environment
# Each environment imports sfcsampler from itself (not the source tree or the
# build tree; no PYTHONPATH) and passes Python tests run from outside the
# source tree (the ctest variant: one environment, the pip install replaced by
# the wheel's, the tests run once on the wheel). Prints the wheel's size and its declared dependencies.
#
# usage: package_test.sh SOURCE_DIR [PREBUILT_PYTHON_DIR]
#   with PREBUILT_PYTHON_DIR (a build's python/ folder) the extension is copied
#   from it (the ctest variant: seconds); without, setup.py configures and
#   builds the C++ engine with CMake (tools/python-package.sh: minutes).
# Environment: SFC_CLI, SFC_SERVER, SFC_CAD_FIXTURES for the tests;
# SFC_PACKAGE_TESTS (default "test_meshes.py test_many.py") which test files.
set -euo pipefail
source_dir=$(cd "$1" && pwd)
prebuilt=${2:-}
python=/usr/bin/python3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
unset PYTHONPATH

if [ -n "$prebuilt" ]; then
  # A clean copy of python/ (a build leaves build/ and *.egg-info beside setup.py),
  # so that the test leaves the source tree as it was.
  export SFCSAMPLER_PREBUILT=$(cd "$prebuilt" && pwd)
  mkdir -p "$work/src"
  cp -r "$source_dir/python" "$work/src/python"
  rm -rf "$work/src/python/build" "$work/src/python/dist" "$work/src/python"/*.egg-info
  src=$work/src
else
  # setup.py builds the repository above python/ (in python/build/cmake).
  src=$source_dir
fi

# A build with CAD puts the CAD kind's module in the package (kinds/module_kind.h).
if [ -z "$prebuilt" ] || [ -e "$prebuilt/sfcsampler/libsfcsampler-cad.so" ]; then
  export EXPECT_CAD=1
fi

check_env() {  # VENV LABEL [TESTS]: imports from the environment, runs the tests if TESTS=1
  local venv=$1 label=$2 tests=${3:-1}
  (cd "$work" && "$venv/bin/python" - "$venv" <<'PY'
import os, sys
import sfcsampler, sfcsampler.dask, sfcsampler._core, sfcsampler._client
venv = os.path.realpath(sys.argv[1])
for m in (sfcsampler, sfcsampler._core, sfcsampler._client):
    assert os.path.realpath(m.__file__).startswith(venv), m.__file__
s = sfcsampler.sample(surface="torus", count=12345)
assert len(s) == 12345
if os.environ.get("EXPECT_CAD") == "1":
    # The CAD kind's module travels with the package, and _core loads the
    # copy next to itself when a request first names a CAD model.
    import tempfile
    patch = os.path.join(tempfile.mkdtemp(), "sheet.nurbs")
    with open(patch, "w") as f:
        f.write("sfcsampler-nurbs 1\ndegree 1 1\ncount 2 2\nknots_u 0 0 1 1\nknots_v 0 0 1 1\n"
                "pole 0 0 0\npole 0 1 0\npole 1 0 0\npole 1 1 0.5\n")
    assert len(sfcsampler.sample(surface="nurbs:" + patch, count=1000)) == 1000
    loaded = [line.split()[-1] for line in open("/proc/self/maps") if "libsfcsampler-cad" in line]
    assert loaded and all(os.path.realpath(p).startswith(venv) for p in loaded), loaded
print("imported", sfcsampler.__file__, "algorithm", sfcsampler.ALGORITHM_VERSION)
PY
  )
  [ "$tests" = 1 ] || return 0
  mkdir -p "$work/tests-$label"
  cp "$source_dir"/python/tests/*.py "$work/tests-$label/"
  (cd "$work/tests-$label" && "$venv/bin/python" -m pytest -q -p no:cacheprovider \
      ${SFC_PACKAGE_TESTS:-test_meshes.py test_many.py})
}

echo "== pip install --no-build-isolation ./python"
$python -m venv --system-site-packages "$work/venv-pip"
(cd "$src" && "$work/venv-pip/bin/pip" install -q --no-build-isolation --no-index ./python)
# The ctest variant runs the tests once, on the wheel; the full run on both.
check_env "$work/venv-pip" pip "$([ -n "$prebuilt" ] && echo 0 || echo 1)"

echo "== python3 -m build --no-isolation --wheel"
if [ -n "$prebuilt" ]; then
  (cd "$src" && $python -m build --no-isolation --wheel --outdir "$work/dist" python >/dev/null)
else
  (cd "$src" && $python -m build --no-isolation --wheel --outdir "$work/dist" python)
fi
wheel=$(ls "$work"/dist/sfcsampler-*.whl)
if [ -n "$prebuilt" ]; then  # the same environment, the package replaced by the wheel's
  "$work/venv-pip/bin/pip" uninstall -q -y sfcsampler
  ln -s venv-pip "$work/venv-wheel"
else
  $python -m venv --system-site-packages "$work/venv-wheel"
fi
"$work/venv-wheel/bin/pip" install -q --no-index "$wheel"
check_env "$work/venv-wheel" wheel

echo "== the wheel"
$python - "$wheel" <<'PY'
import os, sys, zipfile
path = sys.argv[1]
z = zipfile.ZipFile(path)
meta = next(n for n in z.namelist() if n.endswith("METADATA"))
requires = [l.split(":", 1)[1].strip() for l in z.read(meta).decode().splitlines() if l.startswith("Requires-Dist:")]
core = next(i for i in z.infolist() if "/_core" in i.filename)
print(f"{os.path.basename(path)}: {os.path.getsize(path)} bytes ({os.path.getsize(path) / 2**20:.2f} MiB), "
      f"{len(z.namelist())} files; _core {core.file_size} bytes unpacked")
print("Requires-Dist:", "; ".join(requires))
PY
if [ -z "$prebuilt" ] && command -v ldd >/dev/null; then  # dpkg -S is slow: the full run only
  unzip -q -o "$wheel" 'sfcsampler/_core*' -d "$work/unpacked"
  libs=$(ldd "$work"/unpacked/sfcsampler/_core*.so | awk '/=>/ {print $3}' | sort -u)
  echo "shared libraries outside glibc/libstdc++, by Debian package:"
  for lib in $libs; do
    dpkg -S "$(readlink -f "$lib")" 2>/dev/null || dpkg -S "$lib" 2>/dev/null || echo "?: $lib"
  done | cut -d: -f1 | sort -u | grep -v -E '^(libc6|libstdc\+\+6|libgcc-s1)$' | tr '\n' ' '
  echo
fi
echo "package_test: OK"
