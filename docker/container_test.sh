#!/usr/bin/env bash
# Builds the image, runs it, checks health, asks for samples from the host
# through the published port, and stops it gracefully. Uses docker where an
# engine answers, otherwise podman from Debian's packages with a base image
# made locally by debootstrap (no registry is reachable here) and a
# containers.conf for this machine (runc; fixed ulimits). Prints plainly and
# exits 0 when no container runtime works here.
#   bash docker/container_test.sh [BUILD_DIR]
set -uo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build}"
cli="$build/client/sfcsampler"
work="${SFC_CONTAINER_WORK:-/var/tmp/sfcsampler-container}"
mkdir -p "$work"
skip() { echo "container test SKIPPED: $*"; exit 0; }
fail() { echo "container test FAILED: $*" >&2; exit 1; }

base_arg=()
if docker info > /dev/null 2>&1; then
  engine=docker
else
  sudo=""; [ "$(id -u)" -eq 0 ] || sudo="sudo"
  if ! command -v podman > /dev/null || ! command -v debootstrap > /dev/null || ! command -v runc > /dev/null; then
    ($sudo apt-get update -qq && DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq podman runc debootstrap) \
      > "$work/install.log" 2>&1 || skip "podman could not be installed (see $work/install.log)"
  fi
  engine=podman
  cat > "$work/containers.conf" <<'CONF'
[containers]
default_ulimits = ["nofile=4096:4096", "nproc=4096:4096"]
[engine]
runtime = "runc"
CONF
  export CONTAINERS_CONF="$work/containers.conf"
  base=localhost/sfcsampler-base:bookworm
  if ! podman image exists "$base"; then
    mirror=$(sed -n 's/^URIs: *\(http[^ ]*debian\)$/\1/p' /etc/apt/sources.list.d/debian.sources 2>/dev/null | head -1)
    echo "making $base with debootstrap from ${mirror:-http://deb.debian.org/debian}"
    rm -rf "$work/rootfs"
    debootstrap --variant=minbase bookworm "$work/rootfs" "${mirror:-http://deb.debian.org/debian}" \
      > "$work/debootstrap.log" 2>&1 || skip "debootstrap failed (see $work/debootstrap.log)"
    tar -C "$work/rootfs" -c . | podman import - "$base" > /dev/null || skip "podman import failed"
    rm -rf "$work/rootfs"
  fi
  podman run --rm "$base" true > "$work/run.log" 2>&1 || skip "podman cannot run containers here: $(tail -1 "$work/run.log")"
  base_arg=(--build-arg "BASE_IMAGE=$base" --format docker)
fi
echo "engine: $engine"

start=$(date +%s)
$engine build --network host "${base_arg[@]}" -f "$root/docker/Dockerfile" -t sfcsampler:test "$root" \
  > "$work/build.log" 2>&1 || { tail -30 "$work/build.log"; fail "the image did not build"; }
build_seconds=$(( $(date +%s) - start ))
size=$($engine image inspect --format '{{.Size}}' sfcsampler:test)
echo "image built in ${build_seconds} s, $((size / 1000000)) MB"

port=$((20000 + RANDOM % 20000))
$engine rm -f sfcsampler-test > /dev/null 2>&1
$engine run -d --name sfcsampler-test -p "127.0.0.1:$port:50051" sfcsampler:test > /dev/null \
  || fail "the container did not start"
trap '$engine rm -f sfcsampler-test > /dev/null 2>&1' EXIT
healthy=""
for _ in $(seq 60); do
  if $engine exec sfcsampler-test /usr/local/bin/sfcsampler-health-probe > /dev/null 2>&1; then healthy=1; break; fi
  sleep 0.5
done
[ -n "$healthy" ] || { $engine logs sfcsampler-test | tail; fail "the health probe never answered SERVING"; }
[ "$engine" = podman ] && { podman healthcheck run sfcsampler-test > /dev/null || fail "HEALTHCHECK failed"; }
[ "$($engine exec sfcsampler-test id -u)" != 0 ] || fail "the server runs as root"
echo "healthy; the server runs as uid $($engine exec sfcsampler-test id -u)"

"$cli" sample -q --surface torus --density gaussian:floor=0.1 --count 200000 --seed 5 -o "$work/embedded.csv"
"$cli" sample -q --server "127.0.0.1:$port" --surface torus --density gaussian:floor=0.1 --count 200000 --seed 5 \
  -o "$work/container.csv" || fail "no samples through the published port"
cmp -s "$work/embedded.csv" "$work/container.csv" || fail "samples from the container differ from in-process ones"
echo "200000 samples through 127.0.0.1:$port, byte-identical to the in-process run"
# A mesh travels to the container once (uploaded by content hash) and samples alike.
printf 'v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\nf 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n' > "$work/octahedron.obj"
"$cli" sample -q --surface "obj:$work/octahedron.obj" --count 20000 --triangle -o "$work/mesh_embedded.csv"
"$cli" sample -q --server "127.0.0.1:$port" --surface "obj:$work/octahedron.obj" --count 20000 --triangle \
  -o "$work/mesh_container.csv" || fail "no mesh samples from the container"
cmp -s "$work/mesh_embedded.csv" "$work/mesh_container.csv" || fail "mesh samples from the container differ"
echo "20000 samples of an uploaded mesh, byte-identical to the in-process run"
# A CAD model likewise, when this build has CAD models.
if [ -x "$build/cad/make_cad_fixtures" ]; then
  "$build/cad/make_cad_fixtures" "$work" > /dev/null
  "$cli" sample -q --surface "step:$work/box_with_hole.step" --count 20000 --face -o "$work/cad_embedded.csv"
  "$cli" sample -q --server "127.0.0.1:$port" --surface "step:$work/box_with_hole.step" --count 20000 \
    --face -o "$work/cad_container.csv" || fail "no CAD samples from the container"
  cmp -s "$work/cad_embedded.csv" "$work/cad_container.csv" || fail "CAD samples from the container differ"
  echo "20000 samples of an uploaded STEP model, byte-identical to the in-process run"
fi

start=$(date +%s%N)
$engine stop -t 20 sfcsampler-test > /dev/null || fail "stop failed"
stop_ms=$(( ($(date +%s%N) - start) / 1000000 ))
code=$($engine inspect --format '{{.State.ExitCode}}' sfcsampler-test)
$engine logs sfcsampler-test > "$work/container.log" 2>&1
grep -q "stopped" "$work/container.log" || fail "no graceful shutdown in the logs"
[ "$code" = 0 ] || fail "the server exited with $code on SIGTERM"
echo "stopped gracefully (SIGTERM, exit 0) in ${stop_ms} ms"
echo "container test passed: engine $engine, image $((size / 1000000)) MB, build ${build_seconds} s"
