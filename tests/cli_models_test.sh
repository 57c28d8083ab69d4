#!/usr/bin/env bash
# Issue 37 through the CLI, as a user types it: a CAD read bounded by
# --model-parse-seconds ends with a clear error (in the check process, where
# the kernel cannot hold the CLI), a model of faces without area is refused
# naming them, and seeds or rho that would be silently changed are refused
# quoting what was typed.
#   tests/cli_models_test.sh SFCSAMPLER MAKE_CAD_FIXTURES
set -euo pipefail
cli=$1 make_fixtures=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*"; cat "$dir/err.txt" 2>/dev/null; exit 1; }

"$make_fixtures" "$dir" --polygon 8000 > /dev/null   # minutes of the kernel's CPU
"$make_fixtures" "$dir" --collinear 10 > /dev/null
for command in sample inspect; do
  start=$(date +%s)
  if [ "$command" = sample ]; then
    "$cli" sample -q --surface "step:$dir/polygon_8000.step" -n 100 --model-parse-seconds 1 \
      -o /dev/null 2> "$dir/err.txt" && fail "a read past its CPU budget sampled"
  else
    "$cli" inspect "step:$dir/polygon_8000.step" --model-parse-seconds 1 > /dev/null \
      2> "$dir/err.txt" && fail "a read past its CPU budget was described"
  fi
  seconds=$(( $(date +%s) - start ))
  # The 1 s of CPU, or, when other jobs starve the check process of CPU, the
  # wall-clock watchdog's 10 s without progress: both stop the read clearly.
  grep -q -E "RESOURCE_EXHAUSTED: reading the model took more than (1 s of CPU|10 s and was stopped)" \
    "$dir/err.txt" ||
    fail "$command: no clear error for a read past --model-parse-seconds"
  [ "$seconds" -lt 30 ] || fail "$command: the bounded read took $seconds s"
  echo "$command --model-parse-seconds 1: refused after ${seconds} s"
done

"$cli" inspect "step:$dir/collinear_10.step" > /dev/null 2> "$dir/err.txt" &&
  fail "a model of faces without area was described"
grep -q "has no face with area: its 10 faces (0, 1, 2" "$dir/err.txt" || fail "faces without area"
"$cli" sample -q --surface "step:$dir/collinear_10.step" -n 100 -o /dev/null 2> "$dir/err.txt" &&
  fail "a model of faces without area was sampled"
grep -q "has no face with area" "$dir/err.txt" || fail "faces without area (sample)"

for seed in -1 18446744073709551616; do
  "$cli" sample -q --surface sphere -n 10 --seed "$seed" -o /dev/null 2> "$dir/err.txt" &&
    fail "--seed $seed was accepted"
  grep -q "got '$seed'" "$dir/err.txt" || fail "--seed $seed: the message does not quote it"
done
"$cli" sample -q --surface sphere -n 10 --rho 0 -o /dev/null 2> "$dir/err.txt" && fail "--rho 0 was accepted"
grep -q -- "--rho must be a positive number" "$dir/err.txt" || fail "--rho 0: no clear error"
echo OK
