#!/usr/bin/env bash
# The CLI over the wire against a real sfcsampler-server on loopback: the same
# files as the embedded mode, prepare/cache/health, and a graceful SIGTERM
# that lets an in-flight stream finish.
set -euo pipefail
cli="$1"
server="$2"
probe="$3"
fixtures="${4:-}"  # make_cad_fixtures, when the build has CAD models
tmp=$(mktemp -d)
pid=""
cleanup() { [ -n "$pid" ] && kill "$pid" 2>/dev/null; rm -rf "$tmp"; }
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; [ -f "$tmp/server.log" ] && tail -5 "$tmp/server.log" >&2; exit 1; }

# Pick free loopback ports by binding port 0 through the server itself.
"$server" --address 127.0.0.1:0 --health-address 127.0.0.1:0 --metrics-address 127.0.0.1:0 \
  --shutdown-grace 20 > "$tmp/server.log" 2>&1 &
pid=$!
for _ in $(seq 100); do grep -q "listening" "$tmp/server.log" && break; sleep 0.05; done
port=$(sed -n 's/.* port=\([0-9]*\) health_port=.*/\1/p' "$tmp/server.log")
health=$(sed -n 's/.*health_port=\([0-9]*\).*/\1/p' "$tmp/server.log")
[ -n "$port" ] || fail "server did not start"
addr="127.0.0.1:$port"

[ "$("$cli" health --server "$addr")" = SERVING ] || fail "health on the main port"
[ "$("$cli" health --server "127.0.0.1:$health")" = SERVING ] || fail "health on the probe port"
[ "$("$probe" --address "127.0.0.1:$health" --timeout 2)" = SERVING ] || fail "the health probe"
set +e
"$probe" --address "127.0.0.1:$health" --bogus 1 > /dev/null 2>&1; [ $? -eq 2 ] || fail "the probe's unknown flag should exit 2"
"$probe" --address "127.0.0.1:$health" --timeout -1 > /dev/null 2>&1; [ $? -eq 2 ] || fail "the probe's bad timeout should exit 2"
"$probe" --address "127.0.0.1:1" --timeout 0.5 > /dev/null 2>&1; [ $? -eq 2 ] || fail "an unreachable server should exit 2"
set -e

# float32 columns that cannot hold the values, refused by the server.
. "$(dirname "$0")/cli_float32_checks.sh"
f32_refusals --server "$addr"

# A mesh (an octahedron) travels once, by content hash, and gives the same
# bytes over the wire as in process.
printf 'v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\nf 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n' > "$tmp/octahedron.obj"

models=""
if [ -n "$fixtures" ]; then
  # A CAD model too: the box with a fillet and a hole, STEP, with its faces.
  "$fixtures" "$tmp" > /dev/null
  models="--surface step:$tmp/box_with_hole.step --density mean:floor=0.05 --count 5000 --face --normals"
  "$cli" inspect "step:$tmp/box_with_hole.step" | grep -q "8 faces" || fail "inspect the box with a hole"
  # eval's model mode, over the wire: the STEP sphere's slope is as steep as the built-in's.
  slope=$("$cli" eval --model "step:$tmp/sphere.step" --seeds 1 --server "$addr" | awk -F'|' '/slope/ {gsub(/[* ]/, "", $3); print $3}')
  awk -v s="$slope" 'BEGIN { exit !(s != "" && s <= -0.65) }' || fail "eval --model: slope '$slope'"
fi

for args in "--surface torus --density gaussian:floor=0.1 --count 20000 --seed 4" \
            "--surface obj:$tmp/octahedron.obj --density expr:1+x*x --count 5000 --triangle --normals" \
            ${models:+"$models"} \
            "--surface sphere --count 20000 --region box:0,0,0,1,1,1 --normals --curve-position" \
            "--surface plane --density expr:u+v --count 5000 --sequence progressive --shard 1/3"; do
  # shellcheck disable=SC2086
  "$cli" sample $args -q -o "$tmp/embedded.csv"
  # shellcheck disable=SC2086
  "$cli" sample $args -q -o "$tmp/wire.csv" --server "$addr"
  cmp -s "$tmp/embedded.csv" "$tmp/wire.csv" || fail "embedded and wire CSV differ for: $args"
  # shellcheck disable=SC2086
  "$cli" sample $args -q --format ply -o "$tmp/embedded.ply"
  # shellcheck disable=SC2086
  "$cli" sample $args -q --format ply -o "$tmp/wire.ply" --server "$addr"
  cmp -s "$tmp/embedded.ply" "$tmp/wire.ply" || fail "embedded and wire PLY differ for: $args"
done

"$cli" prepare --surface eight --count 100000 --server "$addr" > "$tmp/key" 2> "$tmp/prepare.err"
"$cli" sample --surface eight --count 100000 --server "$addr" -o /dev/null 2> "$tmp/hit.err"
grep -q "cache hit" "$tmp/hit.err" || fail "a prepared tree should be a cache hit"
"$cli" cache --server "$addr" | grep -q "hits: " || fail "cache statistics"

# SIGTERM during a stream: the stream still completes within the grace period.
"$cli" sample --surface sphere --count 3000000 --batch-size 1000 -q -o "$tmp/long.csv" --server "$addr" &
client=$!
sleep 1
kill -TERM "$pid"
wait "$client" || fail "the in-flight stream did not survive a graceful shutdown"
[ "$(wc -l < "$tmp/long.csv")" -eq 3000001 ] || fail "the in-flight stream lost samples"
wait "$pid" || fail "the server did not exit cleanly"
pid=""
grep -q "stopped" "$tmp/server.log" || fail "no shutdown log"
# TLS and a bearer token: a second server with a self-signed certificate.
openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=localhost \
  -addext "subjectAltName=IP:127.0.0.1,DNS:localhost" \
  -keyout "$tmp/key.pem" -out "$tmp/cert.pem" > /dev/null 2>&1 || fail "openssl could not make a certificate"
echo "s3cret-token" > "$tmp/token"
"$server" --address 127.0.0.1:0 --health-address 127.0.0.1:0 --metrics-address "" \
  --tls-cert "$tmp/cert.pem" --tls-key "$tmp/key.pem" --token-file "$tmp/token" > "$tmp/tls.log" 2>&1 &
pid=$!
for _ in $(seq 100); do grep -q "listening" "$tmp/tls.log" && break; sleep 0.05; done
tls_port=$(sed -n 's/.* port=\([0-9]*\) health_port=.*/\1/p' "$tmp/tls.log")
tls_health=$(sed -n 's/.*health_port=\([0-9]*\).*/\1/p' "$tmp/tls.log")
"$cli" sample --surface torus --count 1000 -q -o "$tmp/tls.csv" --server "127.0.0.1:$tls_port" \
  --tls-roots "$tmp/cert.pem" --token-file "$tmp/token" || fail "TLS with the token"
"$cli" sample --surface torus --count 1000 -q -o "$tmp/plain.csv"
cmp -s "$tmp/tls.csv" "$tmp/plain.csv" || fail "TLS samples differ"
"$cli" sample --surface torus --count 10 -q -o /dev/null --server "127.0.0.1:$tls_port" \
  --tls-roots "$tmp/cert.pem" 2> "$tmp/noauth.err" && fail "a request without the token was served"
grep -q UNAUTHENTICATED "$tmp/noauth.err" || fail "no UNAUTHENTICATED without the token"
"$cli" sample --surface torus --count 10 -q -o /dev/null --server "127.0.0.1:$tls_port" \
  --token-file "$tmp/token" 2> /dev/null && fail "a plaintext client reached the TLS port"
[ "$("$cli" health --server "127.0.0.1:$tls_health")" = SERVING ] || fail "the probe port needs no TLS or token"
[ "$("$cli" health --server "127.0.0.1:$tls_port" --tls-roots "$tmp/cert.pem")" = SERVING ] \
  || fail "health on the TLS port needs no token (the auth processor lets it through)"
echo "s3cret-tokeX" > "$tmp/wrong"
"$cli" sample --surface torus --count 10 -q -o /dev/null --server "127.0.0.1:$tls_port" \
  --tls-roots "$tmp/cert.pem" --token-file "$tmp/wrong" 2> "$tmp/wrong.err" && fail "a wrong token was served"
grep -q UNAUTHENTICATED "$tmp/wrong.err" || fail "no UNAUTHENTICATED for a wrong token"
kill -TERM "$pid"; wait "$pid" || true; pid=""

# Mutual TLS: a CA signs the server's and a client's certificate; the server
# serves only clients that present one.
openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=test-ca -keyout "$tmp/ca.key" \
  -out "$tmp/ca.pem" > /dev/null 2>&1 || fail "openssl could not make a CA"
sign() {  # sign NAME SUBJECT [EXTENSIONS]
  openssl req -newkey rsa:2048 -nodes -subj "$2" -keyout "$tmp/$1.key" -out "$tmp/$1.csr" > /dev/null 2>&1
  printf '%s\n' "${3:-basicConstraints=CA:FALSE}" > "$tmp/$1.ext"
  openssl x509 -req -in "$tmp/$1.csr" -CA "$tmp/ca.pem" -CAkey "$tmp/ca.key" -CAcreateserial -days 1 \
    -extfile "$tmp/$1.ext" -out "$tmp/$1.pem" > /dev/null 2>&1 || fail "openssl could not sign $1"
}
sign server /CN=localhost "subjectAltName=IP:127.0.0.1,DNS:localhost"
sign client /CN=sfcsampler-test-client
"$server" --address 127.0.0.1:0 --health-address "" --metrics-address "" \
  --tls-cert "$tmp/server.pem" --tls-key "$tmp/server.key" --tls-client-ca "$tmp/ca.pem" > "$tmp/mtls.log" 2>&1 &
pid=$!
for _ in $(seq 100); do grep -q "listening" "$tmp/mtls.log" && break; sleep 0.05; done
grep -q "mutual_tls=true" "$tmp/mtls.log" || fail "the server did not report mutual TLS"
mtls_port=$(sed -n 's/.* port=\([0-9]*\) health_port=.*/\1/p' "$tmp/mtls.log")
"$cli" sample --surface torus --count 1000 -q -o "$tmp/mtls.csv" --server "127.0.0.1:$mtls_port" \
  --tls-roots "$tmp/ca.pem" --tls-cert "$tmp/client.pem" --tls-key "$tmp/client.key" \
  || fail "mutual TLS with a client certificate"
cmp -s "$tmp/mtls.csv" "$tmp/plain.csv" || fail "mutual-TLS samples differ"
"$cli" sample --surface torus --count 10 -q -o /dev/null --server "127.0.0.1:$mtls_port" \
  --tls-roots "$tmp/ca.pem" 2> /dev/null && fail "a client without a certificate was served"
kill -TERM "$pid"; wait "$pid" || true; pid=""

echo "cli_server_test: all checks passed"
