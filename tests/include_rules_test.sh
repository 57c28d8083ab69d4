#!/bin/bash
# The include check can fail where it matters for the thin client: in a small
# tree judged by the real tools/include_rules.txt, the client library and
# proto/ may include core/'s value types but nothing else of the sampler, and
# only the server (and tests, bench) proto/service/; the CLI's in-process
# code may include the sampler.
#   include_rules_test.sh SOURCE_DIR
set -u
src="$1"
tmp=$(mktemp -d) out=$(mktemp)
trap 'rm -rf "$tmp" "$out"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# put FILE HEADER: $tmp/FILE.cc includes HEADER.
put() { mkdir -p "$tmp/$(dirname "$1")"; printf '#include "%s"\n' "$2" > "$tmp/$1.cc"; }
check() { bash "$src/tools/check_includes.sh" "$tmp" "$src/tools/include_rules.txt" 2>&1; }

# Allowed: each must pass alone.
for pair in "client/a core/types/sample_batch.h" "client/a proto/convert.h" \
            "proto/a core/types/region.h" "proto/service/a engine/model_source.h" \
            "server/a proto/service/service_convert.h" "client/cli/a core/curve_tree.h" \
            "client/cli/a engine/sampling_engine.h"; do
  rm -rf "${tmp:?}"/*; put $pair
  check > "$out" || fail "$pair refused: $(cat "$out")"
done
# Refused: each must fail alone, naming the file.
for pair in "client/a core/curve_tree.h" "client/a engine/sampling_engine.h" \
            "client/a proto/service/service_convert.h" "client/a catalog/catalog.h" \
            "proto/a core/curve_tree.h" "proto/a engine/model_source.h" \
            "proto/a catalog/catalog.h" "proto/a proto/service/service_convert.h" \
            "core/types/a core/curve.h" "request/a core/surface.h"; do
  rm -rf "${tmp:?}"/*; put $pair
  set -- $pair
  if check > "$out"; then fail "$pair passed the check"; fi
  grep -q "^$1.cc:1: " "$out" || fail "$pair: $(cat "$out")"
done
echo "include rules: the thin-client lines hold and can fail"
