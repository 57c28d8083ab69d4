#!/usr/bin/env bash
# The scale-out recipe, tested on loopback only (127.0.0.1), bounded in time:
# three replicas behind nginx's consistent hash on x-surface-key.
#  1. every surface sticks to one replica: after warm-up every request hits;
#  2. killing a replica moves only its keys, and a stream cut by the kill
#     completes through the client's resume;
#  3. the samples are byte-identical to a single in-process run;
#  4. a replica killed while it builds a tree: the retry lands on another
#     replica and the samples are still byte-identical;
#  5. models (a STEP part and an OBJ mesh) on a fresh set of 3 replicas:
#     FindModel, UploadModel and the Sample carry the model's key, so each
#     model is stored on one replica and samples byte-identical to in-process;
#     the mesh's replica killed mid-stream, the client uploads the model to
#     the next replica and resumes, byte-identical;
#  6. a 2.8 MB mesh (over nginx's default 1 MiB body limit) through the
#     proxy, byte-identical to in-process.
#   bash docker/scaleout_test.sh BUILD_DIR
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build}"
cli="$build/client/sfcsampler"
dir=$(mktemp -d)
fail() { echo "FAIL: $*" >&2; tail -5 "$dir"/*.log "$dir/access.log" 2>/dev/null >&2; exit 1; }
cleanup() { kill "$scaleout" 2>/dev/null || true; wait "$scaleout" 2>/dev/null || true; rm -rf "$dir"; }

command -v nginx > /dev/null || fail "nginx is not installed (tools/setup-debian.sh installs it)"
proxy_port=$((20000 + RANDOM % 20000))
SFC_SCALEOUT_DIR="$dir" PATH="$PATH" bash "$root/docker/scaleout.sh" 3 "$proxy_port" > "$dir/scaleout.log" 2>&1 &
scaleout=$!
trap cleanup EXIT
for _ in $(seq 200); do [ -f "$dir/ready" ] && break; sleep 0.05; done
[ -f "$dir/ready" ] || fail "the replicas and proxy did not start"
proxy="127.0.0.1:$proxy_port"
mapfile -t replicas < "$dir/replicas"   # "pid port"
ports=(); rpids=()
for r in "${replicas[@]}"; do rpids+=("${r%% *}"); ports+=("${r##* }"); done

cache_stat() {  # cache_stat PORT FIELD
  timeout 10 "$cli" cache --server "127.0.0.1:$1" | awk -v f="$2:" '$1 == f {v = $2} END {print v + 0}'
}
sum_stat() { local s=0; for p in "${ports[@]}"; do s=$((s + $(cache_stat "$p" "$1"))); done; echo "$s"; }
# kill_mid_stream SURFACE PID OUT: streams 1.5 M samples of SURFACE through the
# proxy into OUT, kills the replica PID once ~100 000 rows are written, and
# checks that the client resumed and that the samples equal an in-process run.
kill_mid_stream() {
  local surface=$1 pid=$2 out=$3
  "$cli" sample -q --surface "$surface" --count 1500000 --seed 9 -o "$out/embedded.csv"
  timeout 120 "$cli" sample --server "$proxy" --surface "$surface" --count 1500000 --seed 9 \
    --batch-size 2000 -o "$out/through-proxy.csv" 2> "$out/client.log" &
  local client=$!
  for _ in $(seq 400); do
    [ "$(stat -c %s "$out/through-proxy.csv" 2>/dev/null || echo 0)" -gt 10000000 ] && break
    sleep 0.02
  done
  kill -9 "$pid"
  wait "$client" || fail "the stream of $surface did not complete after its replica died: $(cat "$out/client.log")"
  grep -q "[1-9][0-9]* resumes" "$out/client.log" || fail "the client should have resumed: $(cat "$out/client.log")"
  cmp -s "$out/embedded.csv" "$out/through-proxy.csv" || fail "samples of $surface through the proxy differ from an in-process run"
}
sample() { timeout 60 "$cli" sample -q --server "$proxy" "$@"; }

# 1. Warm-up: 12 surfaces, each asked once; record which replica built it.
surfaces=()
for i in $(seq 1 12); do surfaces+=("torus:R=1;r=0.$((i + 10))"); done
declare -A owner
for s in "${surfaces[@]}"; do
  before=(); for p in "${ports[@]}"; do before+=("$(cache_stat "$p" misses)"); done
  sample --surface "$s" --count 20000 -o /dev/null
  for j in 0 1 2; do
    [ "$(cache_stat "${ports[$j]}" misses)" -gt "${before[$j]}" ] && owner[$s]=$j
  done
  [ -n "${owner[$s]:-}" ] || fail "no replica built $s"
done
[ "$(sum_stat builds)" -eq 12 ] || fail "each surface should be built once across the replicas"
used=$(printf '%s\n' "${owner[@]}" | sort -u | wc -l)
hits_before=$(sum_stat hits)
for s in "${surfaces[@]}"; do sample --surface "$s" --count 20000 -o /dev/null; done
hits_after=$(sum_stat hits)
ratio=$(awk -v h=$((hits_after - hits_before)) 'BEGIN {printf "%.2f", h / 12}')
echo "warm-up: 12 surfaces over $used replicas; cache hit ratio after warm-up $ratio"
[ "$ratio" = "1.00" ] || fail "after warm-up every request should hit (ratio $ratio)"
[ "$(sum_stat builds)" -eq 12 ] || fail "a warm surface was built again"

# 2 and 3. A long stream whose replica is killed mid-way.
victim_surface="${surfaces[0]}"
victim=${owner[$victim_surface]}
kill_mid_stream "$victim_surface" "${rpids[$victim]}" "$dir"
echo "kill: $(grep -o '[0-9]* resumes' "$dir/client.log"); 1.5 M samples byte-identical to the in-process run"

# Only the victim's keys moved: the survivors' keys still hit.
survivors=(); for j in 0 1 2; do [ "$j" -ne "$victim" ] && survivors+=("$j"); done
moved=0; stayed_hits=0; stayed=0
for s in "${surfaces[@]}"; do
  if [ "${owner[$s]}" -eq "$victim" ]; then moved=$((moved + 1)); continue; fi
  stayed=$((stayed + 1))
  j=${owner[$s]}
  h=$(cache_stat "${ports[$j]}" hits)
  sample --surface "$s" --count 20000 -o /dev/null
  [ "$(cache_stat "${ports[$j]}" hits)" -gt "$h" ] && stayed_hits=$((stayed_hits + 1))
done
echo "after the kill: $stayed_hits of $stayed surviving keys still hit on their replica; $moved keys moved"
[ "$stayed_hits" -eq "$stayed" ] || fail "keys of surviving replicas moved"
# The proxy logs gRPC statuses, including a Trailers-Only error (a request
# rejected before any sample: its status travels in the headers).
timeout 10 "$cli" sample -q --server "$proxy" --surface klein -o /dev/null 2> /dev/null && fail "a bad surface was accepted"
sleep 0.2
grep -q 'grpc_status=-/3 ' "$dir/access.log" || fail "the proxy did not log the Trailers-Only INVALID_ARGUMENT"
grep -q 'grpc_status=0/- ' "$dir/access.log" || fail "the proxy did not log OK statuses from trailers"
echo "proxy log: gRPC status from trailers and from Trailers-Only responses"

# 4. A replica killed mid-build: a tree that takes a second or two to build
# (the eight surface by |K|, sized for 10^8 samples, of which we ask 10^5).
# Its owner is the replica whose miss count rises; it dies before a single
# sample is sent, the proxy answers the broken call, the client asks again,
# and the proxy sends the retry to the surviving replica, which builds the
# same tree.
slow_surface="eight"
slow_tree=(--density gaussian:floor=0.05 --tree-count 100000000)
alive=(); for j in 0 1 2; do [ "$j" -ne "$victim" ] && alive+=("$j"); done
misses=(); for j in "${alive[@]}"; do misses+=("$(cache_stat "${ports[$j]}" misses)"); done
"$cli" sample -q --surface "$slow_surface" "${slow_tree[@]}" --count 100000 --seed 3 -o "$dir/slow-embedded.csv"
timeout 120 "$cli" sample --server "$proxy" --surface "$slow_surface" "${slow_tree[@]}" --count 100000 --seed 3 \
  -o "$dir/slow-proxy.csv" 2> "$dir/slow-client.log" &
client=$!
builder=""
for _ in $(seq 200); do
  for i in "${!alive[@]}"; do
    j=${alive[$i]}
    [ "$(cache_stat "${ports[$j]}" misses)" -gt "${misses[$i]}" ] && builder=$j
  done
  [ -n "$builder" ] && break
  sleep 0.02
done
[ -n "$builder" ] || fail "no replica started building $slow_surface"
running=$(cache_stat "${ports[$builder]}" builds_running)
[ "$running" = 1 ] || fail "the replica was not building when it was to be killed (builds_running=$running): the build was too quick"
kill -9 "${rpids[$builder]}"
wait "$client" || fail "the request did not complete after the replica building its tree died: $(cat "$dir/slow-client.log")"
grep -q "[1-9][0-9]* resumes" "$dir/slow-client.log" || fail "the client should have retried: $(cat "$dir/slow-client.log")"
cmp -s "$dir/slow-embedded.csv" "$dir/slow-proxy.csv" || fail "samples after a mid-build kill differ from the in-process run"
echo "mid-build kill: replica $((builder + 1)) killed while building; $(grep -o '[0-9]* resumes' "$dir/slow-client.log"); samples byte-identical to the in-process run"

# 5. Models through the proxy, on a fresh set of replicas.
kill "$scaleout" 2>/dev/null || true; wait "$scaleout" 2>/dev/null || true
mdir="$dir/models"; mkdir -p "$mdir/cluster"
[ -x "$build/cad/make_cad_fixtures" ] || { echo "scaleout_test: all checks passed (no CAD build: models skipped)"; exit 0; }
"$build/cad/make_cad_fixtures" "$mdir" > /dev/null
torus_obj() {  # N M: a torus of N x M quads as OBJ on stdout
  awk -v n="$1" -v m="$2" 'BEGIN { pi = atan2(0, -1)
    for (i = 0; i < n; i++) for (j = 0; j < m; j++) {
      a = 2 * pi * i / n; b = 2 * pi * j / m
      printf "v %.9f %.9f %.9f\n", (1 + 0.3 * cos(b)) * cos(a), (1 + 0.3 * cos(b)) * sin(a), 0.3 * sin(b) }
    for (i = 0; i < n; i++) for (j = 0; j < m; j++) {
      p = i * m + j + 1; q = ((i + 1) % n) * m + j + 1; r = ((i + 1) % n) * m + (j + 1) % m + 1; t = i * m + (j + 1) % m + 1
      printf "f %d %d %d %d\n", p, q, r, t } }'
}
torus_obj 128 64 > "$mdir/torus.obj"
proxy_port=$((20000 + RANDOM % 20000))
SFC_SCALEOUT_DIR="$mdir/cluster" PATH="$PATH" bash "$root/docker/scaleout.sh" 3 "$proxy_port" > "$mdir/scaleout.log" 2>&1 &
scaleout=$!
for _ in $(seq 200); do [ -f "$mdir/cluster/ready" ] && break; sleep 0.05; done
[ -f "$mdir/cluster/ready" ] || fail "the second set of replicas did not start"
proxy="127.0.0.1:$proxy_port"
mapfile -t replicas < "$mdir/cluster/replicas"
ports=(); rpids=()
for r in "${replicas[@]}"; do rpids+=("${r%% *}"); ports+=("${r##* }"); done
models=("step:$mdir/box_with_hole.step" "obj:$mdir/torus.obj")
for m in "${models[@]}"; do
  for density in uniform "expr:1+z*z"; do
    "$cli" sample -q --surface "$m" --density "$density" --count 20000 --seed 5 -o "$mdir/embedded.csv"
    timeout 60 "$cli" sample -q --server "$proxy" --surface "$m" --density "$density" --count 20000 \
      --seed 5 -o "$mdir/proxy.csv" 2> "$mdir/client.log" || fail "model $m through the proxy: $(cat "$mdir/client.log")"
    cmp -s "$mdir/embedded.csv" "$mdir/proxy.csv" || fail "model $m ($density) through the proxy differs from in-process"
  done
done
stored=$(sum_stat models)
[ "$stored" -eq 2 ] || fail "each model should be stored on exactly one replica ($stored copies of 2 models)"
[ "$(sum_stat model_uploads)" -eq 2 ] || fail "each model should travel once ($(sum_stat model_uploads) uploads)"
echo "models: a STEP part and an OBJ mesh, 2 densities each, through the proxy on 3 replicas; each stored once; byte-identical to in-process"
# The Python client routes models by the same key: it is the C++ client library,
# bound as sfcsampler._client (python/bindings/client.cc).
py=/usr/bin/python3; [ -x "$py" ] || py=python3
if PYTHONPATH="$build/python" "$py" -c "import sfcsampler" 2> /dev/null; then
  PYTHONPATH="$build/python" timeout 120 "$py" - "$proxy" "$mdir/torus.obj" "$mdir/box_with_hole.step" <<'PY' || fail "the Python client's models through the proxy"
import sys, numpy as np, sfcsampler
proxy, obj, step = sys.argv[1:]
with sfcsampler.Client(proxy) as client:
    for surface in ("obj:" + obj, "step:" + step):
        for density in ("uniform", "expr:2+x"):
            wire = client.sample(surface=surface, density=density, count=5000, seed=11)
            local = sfcsampler.sample(surface=surface, density=density, count=5000, seed=11)
            for column in ("index", "u", "v", "x", "y", "z"):
                assert np.array_equal(getattr(wire, column), getattr(local, column)), (surface, column)
PY
  [ "$(sum_stat models)" -eq 2 ] || fail "the Python client stored a model on a second replica"
  echo "models: the Python client reaches the same replicas; samples equal to in-process"
fi
mesh_owner=""
for j in 0 1 2; do
  before=$(cache_stat "${ports[$j]}" models)
  [ "$before" -gt 0 ] && timeout 10 "$cli" sample -q --server "127.0.0.1:${ports[$j]}" \
    --surface "obj:sha256=$(sha256sum "$mdir/torus.obj" | cut -c1-64)" --count 10 -o /dev/null 2> /dev/null && mesh_owner=$j
done
[ -n "$mesh_owner" ] || fail "no replica holds the mesh"
kill_mid_stream "obj:$mdir/torus.obj" "${rpids[$mesh_owner]}" "$mdir"
echo "model kill: the mesh's replica killed mid-stream; $(grep -o '[0-9]* resumes' "$mdir/client.log") (the model uploaded again to the next replica); 1.5 M samples byte-identical"

# 6. A model over nginx's default body limit (1 MiB): a 300 x 150 torus,
# about 2.8 MB of OBJ, uploads through the proxy (client_max_body_size 0)
# and samples byte-identical to in-process.
torus_obj 300 150 > "$mdir/large_torus.obj"
large_bytes=$(stat -c %s "$mdir/large_torus.obj")
[ "$large_bytes" -gt $((2 * 1024 * 1024)) ] || fail "the large mesh has only $large_bytes bytes"
"$cli" sample -q --surface "obj:$mdir/large_torus.obj" --count 50000 --seed 6 -o "$mdir/large-embedded.csv"
timeout 60 "$cli" sample -q --server "$proxy" --surface "obj:$mdir/large_torus.obj" --count 50000 --seed 6 \
  -o "$mdir/large-proxy.csv" 2> "$mdir/large-client.log" || fail "a $large_bytes-byte mesh through the proxy: $(cat "$mdir/large-client.log")"
cmp -s "$mdir/large-embedded.csv" "$mdir/large-proxy.csv" || fail "the large mesh through the proxy differs from in-process"
echo "large model: a $large_bytes-byte OBJ uploaded through the proxy; samples byte-identical to in-process"
echo "scaleout_test: all checks passed"
