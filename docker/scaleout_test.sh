#!/usr/bin/env bash
# The scale-out recipe, tested on loopback only (127.0.0.1), bounded in time:
# three replicas behind nginx's consistent hash on x-surface-key.
#  1. every surface sticks to one replica: after warm-up every request hits;
#  2. killing a replica moves only its keys, and a stream cut by the kill
#     completes through the client's resume;
#  3. the samples are byte-identical to a single in-process run;
#  4. a replica killed while it builds a tree: the retry lands on another
#     replica and the samples are still byte-identical.
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
"$cli" sample -q --surface "$victim_surface" --count 1500000 --seed 9 -o "$dir/embedded.csv"
timeout 120 "$cli" sample --server "$proxy" --surface "$victim_surface" --count 1500000 --seed 9 \
  --batch-size 2000 -o "$dir/through-proxy.csv" 2> "$dir/client.log" &
client=$!
# Kill the replica once the stream is well under way (~100 000 rows written).
for _ in $(seq 400); do
  [ "$(stat -c %s "$dir/through-proxy.csv" 2>/dev/null || echo 0)" -gt 10000000 ] && break
  sleep 0.02
done
kill -9 "${rpids[$victim]}"
wait "$client" || fail "the stream did not complete after its replica died: $(cat "$dir/client.log")"
grep -q "[1-9][0-9]* resumes" "$dir/client.log" || fail "the client should have resumed: $(cat "$dir/client.log")"
cmp -s "$dir/embedded.csv" "$dir/through-proxy.csv" || fail "samples through the proxy differ from a single in-process run"
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
echo "scaleout_test: all checks passed"
