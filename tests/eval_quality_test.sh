#!/bin/sh
# `sfcsampler eval --sections quality` in its fast setting: it runs in
# seconds, writes quality.md, finds the superellipsoid's singular lines (and
# none in longitude once reparameterised), and prints every section with a
# verdict column.
set -eu
cli="$1"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

"$cli" eval --sections quality --out-dir "$tmp/q" > "$tmp/out.md" 2> "$tmp/err.txt" || { cat "$tmp/err.txt"; fail "eval quality"; }
[ -s "$tmp/q/quality.md" ] || fail "no quality.md"
cmp -s "$tmp/q/quality.md" "$tmp/out.md" || [ "$(wc -c < "$tmp/q/quality.md")" -gt 1000 ] || fail "quality.md differs from stdout"
for section in "sample-anchored boxes" "strips beside the singular lines" "Stratification beside" "Monte Carlo" "Plane, star" \
               "Sphere, spherical-triangle" "Blue noise" "## Summary"; do
  grep -q "$section" "$tmp/out.md" || fail "missing section: $section"
done
grep -q "^| superellipsoid | uniform | 0 0.5 1 / 0 0.25 0.5 0.75 1 |" "$tmp/out.md" || fail "lines of the default superellipsoid"
grep -q "^| superellipsoid:reparam=1 | uniform | 0 1 /  |" "$tmp/out.md" || fail "lines of the reparameterised superellipsoid"
# Every summary row has a verdict.
rows=$(sed -n '/## Summary/,$p' "$tmp/out.md" | grep -c '^| [a-zA-Z]' || true)
verdicts=$(sed -n '/## Summary/,$p' "$tmp/out.md" | grep -cE '\| (PASS|\*\*FAIL\*\*|INFO) \|$' || true)
[ "$rows" -gt 10 ] && [ "$rows" -eq $((verdicts + 1)) ] || fail "summary rows $rows, verdicts $verdicts"
# Unknown section names are refused.
if "$cli" eval --sections quality --quality-sections boxes,nonsense --out-dir "$tmp/r" > /dev/null 2> "$tmp/err2.txt"; then
  fail "an unknown quality section was accepted"
fi
grep -q "unknown quality section" "$tmp/err2.txt" || fail "error message: $(cat "$tmp/err2.txt")"
echo OK
