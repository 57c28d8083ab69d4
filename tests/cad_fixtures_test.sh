#!/usr/bin/env bash
# Writes the CAD fixtures into a temporary directory with make_cad_fixtures
# and describes each with describe_model: every file loads, and each
# description lists the faces it should.
set -euo pipefail
make_fixtures=$1 describe=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$make_fixtures" "$dir" > "$dir/written.txt"
[ "$(wc -l < "$dir/written.txt")" -eq 7 ] || { echo "expected 7 fixtures"; cat "$dir/written.txt"; exit 1; }
expect_faces() {  # FILE COUNT
  out=$("$describe" "$1")
  echo "$out"
  # No pipe into grep -q here: with pipefail, its early exit could fail the echo.
  [[ "${out%%$'\n'*}" == *": $2 faces,"* ]] || { echo "FAIL: $1 should have $2 faces"; exit 1; }
}
for f in step iges; do
  expect_faces "$dir/sphere.$f" 1
  expect_faces "$dir/cylinder.$f" 3
  expect_faces "$dir/box_with_hole.$f" 8
done
expect_faces "$dir/quarter_cylinder.nurbs" 1
head -c 2000 "$dir/box_with_hole.step" > "$dir/cut.step"
if "$describe" "$dir/cut.step" 2> "$dir/err.txt"; then echo "FAIL: a truncated STEP loaded"; exit 1; fi
grep -q "cut.step" "$dir/err.txt" && grep -q "truncated" "$dir/err.txt" || { cat "$dir/err.txt"; exit 1; }
echo OK
