#!/bin/bash
# The client library needs none of the sampler: a program built on it alone
# (sfcsampler-example-client) and the health probe link no OpenCASCADE,
# CGAL (GMP, MPFR), muparser, SLEEF or cairo (ldd), and the example client
# gets from a real server the samples the in-process CLI makes.
#   client_deps_test.sh EXAMPLE_CLIENT HEALTH_PROBE CLI SERVER
set -u
example="$1" probe="$2" cli="$3" server="$4"
tmp=$(mktemp -d)
trap 'kill $server_pid 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

for program in "$example" "$probe"; do
  ldd "$program" > "$tmp/ldd" || fail "ldd $program"
  if grep -E "libTK|muparser|libgmp|libmpfr|libsleef|libcairo|libCGAL|tinyobj" "$tmp/ldd"; then
    fail "$(basename "$program") links part of the sampler (above)"
  fi
done
# The check can fail: the CLI embeds the sampler and links muparser.
ldd "$cli" | grep -q muparser || fail "ldd does not show the CLI's muparser; the check above proves nothing"

"$server" --address 127.0.0.1:0 --health-address 127.0.0.1:0 --metrics-address 127.0.0.1:0 \
  > "$tmp/server.log" 2>&1 &
server_pid=$!
for _ in $(seq 100); do grep -q "listening" "$tmp/server.log" && break; sleep 0.05; done
port=$(sed -n 's/.* port=\([0-9]*\) health_port=.*/\1/p' "$tmp/server.log")
[ -n "$port" ] || fail "server did not start"

"$example" --server "127.0.0.1:$port" --surface torus --count 5000 --seed 4 > "$tmp/out" ||
  fail "example client: $(cat "$tmp/out")"
grep -q "^5000 samples of torus" "$tmp/out" || fail "count: $(cat "$tmp/out")"
"$cli" sample --surface torus --count 5000 --seed 4 -q -o "$tmp/a.csv" || fail "CLI sample"
first=$(sed -n 2p "$tmp/a.csv" | awk -F, '{printf "first (%.17g, %.17g, %.17g)", $4, $5, $6}')
remote=$(grep "^first" "$tmp/out")
# The CLI's CSV prints the shortest exact digits; both read back as the same doubles.
[ "$first" = "$remote" ] || fail "first sample differs: in process '$first', over the wire '$remote'"
echo "client deps: ok"
