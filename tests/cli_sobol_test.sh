#!/usr/bin/env bash
# Issue 36 through the CLI, as a user types it: `--sequence sobol` on a CAD
# model and a mesh gives exactly N samples, each index once; 4 shards and an
# index range are positions of the whole set (they concatenate to its bytes,
# and the CLI says what a part costs); a sphere set of 1024 is the samples
# with index < 1024 of a set of 4096 on the same tree.
#   tests/cli_sobol_test.sh SFCSAMPLER MAKE_CAD_FIXTURES
set -euo pipefail
cli=$1 make_fixtures=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*"; cat "$dir/err.txt" 2>/dev/null; exit 1; }
"$make_fixtures" "$dir" > /dev/null
cp "$(dirname "$0")/pulled_octahedron.obj" "$dir/mesh.obj"  # the pinned bytes' mesh
for model in "step:$dir/box_with_hole.step" "obj:$dir/mesh.obj"; do
  args=(--surface "$model" --count 5000 --seed 3 --sequence sobol)
  "$cli" sample -q "${args[@]}" -o "$dir/whole.csv"
  [ "$(tail -n +2 "$dir/whole.csv" | wc -l)" -eq 5000 ] || fail "$model: not 5000 samples"
  [ "$(tail -n +2 "$dir/whole.csv" | cut -d, -f1 | sort -u | wc -l)" -eq 5000 ] ||
    fail "$model: an index twice"
  : > "$dir/parts.csv"
  for i in 0 1 2 3; do
    "$cli" sample "${args[@]}" --shard "$i/4" -o "$dir/part.csv" 2> "$dir/err.txt"
    grep -q "all 5000 samples were placed and sorted" "$dir/err.txt" ||
      fail "$model: the CLI does not say what a shard costs"
    tail -n +2 "$dir/part.csv" >> "$dir/parts.csv"
  done
  tail -n +2 "$dir/whole.csv" | cmp -s - "$dir/parts.csv" ||
    fail "$model: 4 shards are not the whole set"
  "$cli" sample -q "${args[@]}" --begin 1000 --end 2000 -o "$dir/range.csv"
  sed -n 1002,2001p "$dir/whole.csv" | cmp -s - <(tail -n +2 "$dir/range.csv") ||
    fail "$model: [1000, 2000) is not positions 1000..1999 of the whole set"
  echo "$model: 5000 samples, shards and a range are slices of the whole set"
done
"$cli" sample -q --surface sphere --count 1024 --tree-count 4096 --sequence sobol -o "$dir/a.csv"
"$cli" sample -q --surface sphere --count 4096 --tree-count 4096 --sequence sobol -o "$dir/b.csv"
awk -F, 'NR > 1 && $1 < 1024' "$dir/b.csv" | cmp -s - <(tail -n +2 "$dir/a.csv") ||
  fail "the set of 1024 is not the prefix of the set of 4096"
echo "sphere: the set of 1024 is the samples with index < 1024 of the set of 4096"
