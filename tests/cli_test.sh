#!/usr/bin/env bash
# End-to-end checks of the embedded CLI: header, exact counts, byte-identical
# reruns, ranges and shards that concatenate to the full file, PLY headers,
# and clear errors with a non-zero exit for bad input.
set -euo pipefail
cli="$1"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

"$cli" sample --surface torus --density gaussian:floor=0.1 --count 5000 --seed 4 -q -o "$tmp/a.csv"
"$cli" sample --surface torus --density gaussian:floor=0.1 --count 5000 --seed 4 -q --batch-size 333 -o "$tmp/b.csv"
[ "$(head -1 "$tmp/a.csv")" = "index,u,v,x,y,z" ] || fail "CSV header"
[ "$(wc -l < "$tmp/a.csv")" -eq 5001 ] || fail "row count"
cmp -s "$tmp/a.csv" "$tmp/b.csv" || fail "reruns differ"

for i in 0 1 2; do
  "$cli" sample --surface torus --density gaussian:floor=0.1 --count 5000 --seed 4 -q --shard "$i/3" -o "$tmp/s$i.csv"
done
{ head -1 "$tmp/s0.csv"; for i in 0 1 2; do tail -n +2 "$tmp/s$i.csv"; done; } > "$tmp/joined.csv"
cmp -s "$tmp/a.csv" "$tmp/joined.csv" || fail "shards do not join to the full set"

"$cli" sample --surface torus --density gaussian:floor=0.1 --count 5000 --seed 4 -q --begin 100 --end 200 -o "$tmp/r.csv"
diff <(tail -n +2 "$tmp/r.csv") <(sed -n '102,201p' "$tmp/a.csv") > /dev/null || fail "range is not the slice"

"$cli" sample --surface sphere --count 1000 -q --format ply -o "$tmp/p.ply"
grep -aq "format binary_little_endian 1.0" "$tmp/p.ply" || fail "binary PLY header"
grep -aq "element vertex 1000" "$tmp/p.ply" || fail "PLY vertex count"
"$cli" sample --surface sphere --count 1000 -q --format ply --ascii --region uv:0,0.5,0,0.5 -o "$tmp/q.ply"
n=$(grep -a "element vertex" "$tmp/q.ply" | awk '{print $3}')
body=$(($(wc -l < "$tmp/q.ply") - $(grep -an end_header "$tmp/q.ply" | cut -d: -f1)))
[ "$n" -eq "$body" ] && [ "$n" -gt 0 ] || fail "ASCII PLY with a region: header says $n, body has $body"

set +e
"$cli" sample --surface klein -q -o "$tmp/x.csv" 2> "$tmp/err"; code=$?
set -e
[ "$code" -ne 0 ] && grep -q "unknown surface" "$tmp/err" || fail "unknown surface error"
"$cli" surfaces | grep -q "monkey_saddle" || fail "surfaces listing"
# Evidence commands: a tiny protocol run writes its table, CSV and plots; a
# render writes a PNG.
"$cli" eval --l-max 4 --out-dir "$tmp/eval" > "$tmp/eval.txt" 2> /dev/null
grep -q "hilbert-jittered" "$tmp/eval.txt" || fail "eval slope table"
for f in discrepancy.csv slopes.md plane-rectangular.svg plane-triangular.png sphere-spherical.png; do
  [ -s "$tmp/eval/$f" ] || fail "eval did not write $f"
done
"$cli" render --surface torus --count 2000 --what samples -o "$tmp/t.png" 2> /dev/null
[ "$(head -c 4 "$tmp/t.png" | tail -c 3)" = "PNG" ] || fail "render PNG"

# eval's output folder is made by the program, not a shell: any name works.
odd="$tmp/it's a \$(folder) with spaces"
"$cli" eval --setting fast --out-dir "$odd" > /dev/null 2>&1 || fail "eval into a folder with quotes and spaces"
[ -s "$odd/discrepancy.csv" ] || fail "eval wrote no discrepancy.csv into the odd folder"
[ ! -e "$tmp/it" ] || fail "the folder name was split by a shell"

# Commands that ask a server are refused by the parser without --server.
for command in cache health "upload ply:$tmp/none.ply"; do
  set +e
  "$cli" $command > /dev/null 2> "$tmp/err"; code=$?
  set -e
  [ "$code" -ne 0 ] && grep -q -- "--server is required" "$tmp/err" ||
    fail "$command without --server: exit $code, $(cat "$tmp/err")"
done
# upload refuses a spec that names no file before it sends anything.
set +e
"$cli" upload --server 127.0.0.1:1 sphere > /dev/null 2> "$tmp/err"; code=$?
set -e
[ "$code" -eq 2 ] && grep -q "names no model file" "$tmp/err" || fail "upload of a non-model"
# render draws the curve tree in process, and refuses it from a server.
"$cli" render --surface torus --count 500 --what param-curve -o "$tmp/c.png" 2> /dev/null
[ "$(head -c 4 "$tmp/c.png" | tail -c 3)" = "PNG" ] || fail "render of the curve tree"
set +e
"$cli" render --surface torus --what curve --server 127.0.0.1:1 -o "$tmp/c.png" 2> "$tmp/err"
code=$?
set -e
[ "$code" -eq 1 ] && grep -q "stays on the server" "$tmp/err" || fail "render curve with --server"
# float32 columns that cannot hold the values, in process.
. "$(dirname "$0")/cli_float32_checks.sh"
f32_refusals
echo "cli_test: all checks passed"
