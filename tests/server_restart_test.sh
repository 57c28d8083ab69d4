#!/usr/bin/env bash
# Fault: the server dies (SIGKILL) in the middle of a stream and comes back on
# the same port a moment later. The client library resumes from the first
# missing index and the file it writes is byte-identical to an in-process run.
#   tests/server_restart_test.sh SFCSAMPLER SFCSAMPLER_SERVER
set -euo pipefail
cli="$1"
server="$2"
tmp=$(mktemp -d)
pid=""
client=""
cleanup() {
  [ -n "$client" ] && kill "$client" 2>/dev/null
  [ -n "$pid" ] && kill "$pid" 2>/dev/null
  wait 2>/dev/null || true
  rm -rf "$tmp"
}
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; tail -n 5 "$tmp"/*.log "$tmp/client.err" >&2 2>/dev/null; exit 1; }

start_server() {  # start_server ADDRESS LOG
  "$server" --address "$1" --health-address "" --metrics-address "" > "$2" 2>&1 &
  pid=$!
  for _ in $(seq 200); do grep -q "listening" "$2" && return 0; sleep 0.05; done
  fail "the server did not start on $1"
}

# The first server picks a free port; its replacement binds the same one.
start_server 127.0.0.1:0 "$tmp/server1.log"
port=$(sed -n 's/.* port=\([0-9]*\) .*/\1/p' "$tmp/server1.log")
[ -n "$port" ] || fail "no port in the server log"

request=(--surface torus --density gaussian:floor=0.1 --count 600000 --seed 11)
"$cli" sample "${request[@]}" -q -o "$tmp/embedded.csv"

"$cli" sample "${request[@]}" --server "127.0.0.1:$port" --batch-size 1000 \
  -o "$tmp/wire.csv" 2> "$tmp/client.err" &
client=$!
# Kill once the stream is well under way (about 30 000 rows written).
for _ in $(seq 500); do
  [ "$(stat -c %s "$tmp/wire.csv" 2>/dev/null || echo 0)" -gt 3000000 ] && break
  sleep 0.01
done
kill -0 "$client" 2>/dev/null || fail "the stream ended before the server could be killed"
kill -KILL "$pid"
wait "$pid" 2>/dev/null || true
rows_at_kill=$(wc -l < "$tmp/wire.csv")
sleep "${SFC_DOWN_SECONDS:-2}"  # the server is down: the client's resumes meet a refused connection
start_server "127.0.0.1:$port" "$tmp/server2.log"

wait "$client" || fail "the stream did not complete after the restart"
client=""
grep -q "[1-9][0-9]* resumes" "$tmp/client.err" || fail "the client should have resumed"
[ "$rows_at_kill" -lt 600001 ] || fail "the kill came after the stream had ended"
cmp -s "$tmp/embedded.csv" "$tmp/wire.csv" || fail "samples after the restart differ from the in-process run"
echo "server_restart_test: killed at $rows_at_kill rows, $(grep -o '[0-9]* resumes' "$tmp/client.err"); 600 000 samples byte-identical"
