#!/usr/bin/env bash
# Installs what sfcsampler needs from Debian bookworm's packages.
#   bash tools/setup-debian.sh           everything: the server, tests, Python, CAD, meshes
#   bash tools/setup-debian.sh sample    only what the CLI needs to sample formula surfaces
#                                        in process (tools/sample.sh, the README's first command)
# Skips apt when every package is already installed. Safe to run again.
set -euo pipefail
mode="${1:-all}"

# The CLI with the formula kind: compiler, core maths, specs, flags, the
# client library it links (gRPC, Protobuf, OpenSSL) and its pictures.
sample_packages=(
  build-essential cmake ninja-build pkg-config   # compiler and build
  libabsl-dev                                    # Status, StatusOr, strings, Mutex (core)
  libsleef-dev                                   # sin, cos, pow with the same bits on every x86-64 machine and
                                                 # vector width (core/vector_math.h): glibc picks FMA variants
  libmuparser-dev                                # user-defined surface and density expressions
  libcli11-dev                                   # command-line flags
  libgrpc++-dev libgrpc-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler  # the CLI's --server
  libssl-dev                                     # SHA-256 of model files, constant-time token comparison
  libcairo2-dev libpng-dev                       # `render` and `eval` pictures
)
packages=(
  "${sample_packages[@]}"
  libgtest-dev libgmock-dev                      # tests
  libbenchmark-dev                               # benchmarks
  libspdlog-dev                                  # server logs
  prometheus-cpp-dev                             # server metrics
  libtinyobjloader-dev                           # OBJ meshes (mesh/): parses from a string, keeps vn
  libcgal-dev                                    # PLY meshes (mesh/): header-only reader from a stream, ASCII and
                                                 # binary, keeps every named vertex property (per-vertex weights);
                                                 # assimp keeps only PLY properties it knows; PCL/VTK are far heavier
  openssl                                        # a self-signed certificate for the TLS test
  nginx                                          # the consistent-hash gRPC proxy of the scale-out test
  python3-dev pybind11-dev                       # the Python extensions sfcsampler._core (embedded engine) and
                                                 # _client (the C++ client library: no Python gRPC or protobuf)
  python3-numpy                                  # samples come to Python as NumPy arrays
  python3-pytest                                 # the Python tests in the suite
  python3-matplotlib                             # the examples' plots (Monte Carlo error, torus picture)
  python3-distributed                            # sfcsampler.dask: tasks on a Dask cluster (its tests start a
                                                 # LocalCluster); the issue asks for Dask, not a scheduler of ours
  python3-build python3-wheel python3-setuptools # pip install ./python and python -m build --wheel
  python3-pip python3-venv python3-pybind11      # without PyPI: the packaging test's virtual environment,
                                                 # pybind11's Python side for the setuptools build
  python3-open3d                                 # mesh objects from Open3D in the tests; the peer of
                                                 # bench/many_meshes.py and bench/mesh_vs_open3d.py
  libocct-foundation-dev libocct-modeling-data-dev  # OpenCASCADE: STEP/IGES faces, exact derivatives,
  libocct-modeling-algorithms-dev libocct-data-exchange-dev  # trims, areas, test models (cad/)
  libtbb-dev                                     # OpenCASCADE's CMake targets link libtbb.so
)

case "$mode" in
  all) ;;
  sample) packages=("${sample_packages[@]}") ;;
  *) echo "usage: $0 [all|sample]" >&2; exit 2 ;;
esac
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
echo "setup: installing ${missing[*]}" >&2
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
