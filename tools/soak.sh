#!/usr/bin/env bash
# Load and soak run (not in ctest): starts a real sfcsampler-server on
# loopback with modest limits, runs bench/load_generator against it (STREAMS
# concurrent streams for SECONDS: complete streams of mixed surfaces,
# densities, counts, ranges, shards and regions spot-checked against an
# in-process run; cancels; slow readers; client deadlines; bad requests) and,
# on a quarter of the workers, the model phase (good STEP, IGES, NURBS, OBJ
# and PLY models uploaded and sampled, spot-checked in process; meshes of
# tens of MB; hostile uploads that must be refused), and prints its table:
# outcomes by status code, unexpected outcomes (target 0), samples/s, and the
# server's peak RSS against the sum of its memory budgets: trees, streams'
# working memory, uploaded models (stored and being received), parsed models
# and parses' working memory (target: within the sum + 20%). Exits 1 on any
# unexpected outcome.
#   bash tools/soak.sh [SECONDS] [STREAMS]      (defaults 60 and 64)
# SFC_SOAK_CACHE_BYTES (default 256 MiB) sets the server's cache budget and
# SFC_SOAK_STREAM_BYTES (default 64 MiB) its streams' working memory;
# SFC_SOAK_MODEL_BYTES and SFC_SOAK_PARSED_MODEL_BYTES (default 128 MiB each)
# its uploaded and parsed models; SFC_SOAK_PARSE_MEMORY_BYTES (default 256
# MiB) its parses' working memory; SFC_SOAK_MODEL_SHARE (default 25, 0 = none)
# the percent of workers in the model phase; SFC_SOAK_SERVER_FLAGS adds
# server flags.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
streams="${2:-64}"
cache_bytes="${SFC_SOAK_CACHE_BYTES:-268435456}"
stream_bytes="${SFC_SOAK_STREAM_BYTES:-67108864}"
model_bytes="${SFC_SOAK_MODEL_BYTES:-134217728}"
parsed_model_bytes="${SFC_SOAK_PARSED_MODEL_BYTES:-134217728}"
parse_memory_bytes="${SFC_SOAK_PARSE_MEMORY_BYTES:-268435456}"
model_share="${SFC_SOAK_MODEL_SHARE:-25}"
bash tools/build.sh
server=build/server/sfcsampler-server
dir=$(mktemp -d)
pid=""
cleanup() { [ -n "$pid" ] && kill "$pid" 2>/dev/null; wait 2>/dev/null || true; rm -rf "$dir"; }
trap cleanup EXIT

# Stream slots: one per client stream plus an eighth, for the moment between
# a client's cancel (which it sees at once) and the server noticing it. A
# server that keeps slots for departed clients still runs out.
slots=$((streams + (streams + 7) / 8))
flags=(--address 127.0.0.1:0 --health-address "" --metrics-address ""
       --cache-bytes "$cache_bytes" --max-tree-leaves 4194304 --max-count 2000000
       --max-concurrent-streams "$slots" --request-deadline 120 --shutdown-grace 5)
# A budget for streams' working memory, where this server has one.
# The server's flags, read once (grep -q on a pipe would end the writer with
# SIGPIPE, which pipefail reports as a failure).
server_help=$("$server" --help 2>&1)
if grep -q -- --stream-memory-bytes <<< "$server_help"; then flags+=(--stream-memory-bytes "$stream_bytes"); fi
# A write timeout for stalled readers, where this server has one.
if grep -q -- --write-timeout <<< "$server_help"; then flags+=(--write-timeout 5); fi
# Budgets for uploaded and parsed models, and a parse CPU budget of 5 s (the
# hostile uploads' quadratic shell is stopped there; the largest good mesh
# parses in well under it).
if grep -q -- --parsed-model-bytes <<< "$server_help"; then
  flags+=(--model-bytes "$model_bytes" --parsed-model-bytes "$parsed_model_bytes" --model-parse-seconds 5)
  # Parses' working memory: the largest good mesh (a 48 MB PLY) reserves
  # 5 bytes a byte.
  if grep -q -- --parse-memory-bytes <<< "$server_help"; then
    flags+=(--parse-memory-bytes "$parse_memory_bytes")
  fi
else
  model_share=0
fi
# shellcheck disable=SC2206
flags+=(${SFC_SOAK_SERVER_FLAGS:-})
"$server" "${flags[@]}" > "$dir/server.log" 2>&1 &
pid=$!
for _ in $(seq 200); do grep -q listening "$dir/server.log" && break; sleep 0.05; done
port=$(sed -n 's/.* port=\([0-9]*\) .*/\1/p' "$dir/server.log")
[ -n "$port" ] || { cat "$dir/server.log"; echo "soak: the server did not start" >&2; exit 1; }
echo "soak: server pid $pid on 127.0.0.1:$port: ${flags[*]}"
echo "soak: $streams streams for $seconds s"

status=0
mkdir -p "$dir/models"
build/bench/load_generator --server "127.0.0.1:$port" --server-pid "$pid" --streams "$streams" \
  --seconds "$seconds" --model-share "$model_share" --model-dir "$dir/models" || status=$?
# Every client has gone: a second later no stream should hold a slot.
sleep 1
build/client/sfcsampler cache --server "127.0.0.1:$port" > "$dir/cache.txt" || status=1
sed 's/^/soak: cache: /' "$dir/cache.txt"
active=$(awk '$1 == "active_streams:" {print $2}' "$dir/cache.txt")
echo "soak: streams still active 1 s after every client left: ${active:-0} (target 0)"
[ "${active:-0}" -eq 0 ] || status=1
stop_start=$(date +%s.%N)
kill -TERM "$pid"
wait "$pid" || { echo "soak: the server did not exit cleanly" >&2; status=1; }
pid=""
echo "soak: SIGTERM to exit: $(awk -v a="$stop_start" -v b="$(date +%s.%N)" 'BEGIN {printf "%.1f", b - a}') s (grace 5 s)"
errors=$(grep -c '\[error\]\|\[critical\]' "$dir/server.log" || true)
echo "soak: server log lines at error level: $errors"
exit "$status"
