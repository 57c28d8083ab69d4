#!/usr/bin/env bash
# Starts N sfcsampler replicas and nginx (consistent hash on x-surface-key) on
# loopback, without containers. Prints the proxy address; stops everything on
# exit or Ctrl-C.
#   bash docker/scaleout.sh [replicas] [proxy_port]
# Then: ./build/client/sfcsampler sample --server 127.0.0.1:PORT --surface torus ...
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
replicas="${1:-3}"
proxy_port="${2:-50080}"
server="$root/build/server/sfcsampler-server"
[ -x "$server" ] || { echo "scaleout: $server is missing: build first (bash tools/build.sh)" >&2; exit 1; }
# SFC_SCALEOUT_DIR, if set, receives the logs and a state file for scripts:
# "replicas" (one "pid port" line each), "proxy" (the port) and "ready".
dir="${SFC_SCALEOUT_DIR:-$(mktemp -d)}"
: > "$dir/replicas"
pids=()
stop() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done; wait 2>/dev/null || true; }
trap stop EXIT INT TERM

servers=""
for i in $(seq 1 "$replicas"); do
  "$server" --address 127.0.0.1:0 --health-address "" --metrics-address "" > "$dir/replica$i.log" 2>&1 &
  pids+=($!)
  for _ in $(seq 100); do grep -q listening "$dir/replica$i.log" && break; sleep 0.05; done
  port=$(sed -n 's/.* port=\([0-9]*\) .*/\1/p' "$dir/replica$i.log")
  if [ -z "$port" ]; then
    echo "scaleout: replica $i did not start (log $dir/replica$i.log):" >&2
    tail -5 "$dir/replica$i.log" >&2
    exit 1
  fi
  servers+="    server 127.0.0.1:$port max_fails=1 fail_timeout=10s;"$'\n'
  echo "${pids[-1]} $port" >> "$dir/replicas"
  echo "replica $i on 127.0.0.1:$port (log $dir/replica$i.log)"
done
mkdir -p "$dir/tmp"
user_line=""
[ "$(id -u)" -eq 0 ] && user_line="user root;"
awk -v servers="$servers" -v prefix="$dir" -v listen="127.0.0.1:$proxy_port" -v user="$user_line" \
  '{gsub("@SERVERS@", servers); gsub("@PREFIX@", prefix); gsub("@LISTEN@", listen); gsub("@USER@", user); print}' \
  "$root/docker/nginx.conf.template" > "$dir/nginx.conf"
nginx -p "$dir" -c "$dir/nginx.conf" -g 'daemon off;' &
pids+=($!)
for _ in $(seq 100); do (exec 3<>"/dev/tcp/127.0.0.1/$proxy_port") 2>/dev/null && break; sleep 0.05; done
echo "$proxy_port" > "$dir/proxy"
touch "$dir/ready"
echo "proxy on 127.0.0.1:$proxy_port (access log $dir/access.log)"
wait
