# Sourced by cli_test.sh and cli_server_test.sh (with $cli, $tmp and fail
# defined): float32 columns that cannot hold a request's values are refused
# before a file is written, with exit 2, INVALID_ARGUMENT and the column
# named (engine/float32_range.h), in every output format; float64 serves the
# same request. Extra arguments (--server ADDR) go to every sample command.
f32_refused() {  # surface density column-flag names-this [more sample flags]
  local surface=$1 density=$2 flag=$3 names=$4; shift 4
  for format in csv ply npy; do
    set +e
    "$cli" sample --surface "$surface" --density "$density" $flag --count 500 --precision float32 \
      --format "$format" -q "$@" -o "$tmp/f32.$format" 2> "$tmp/err"; code=$?
    set -e
    [ "$code" -eq 2 ] && grep -q "INVALID_ARGUMENT" "$tmp/err" && grep -q "$names" "$tmp/err" &&
      grep -q "float64" "$tmp/err" && [ ! -e "$tmp/f32.$format" ] ||
      fail "float32 $surface $density ($format): exit $code, $(cat "$tmp/err")"
  done
  "$cli" sample --surface "$surface" --density "$density" $flag --count 500 -q "$@" \
    -o "$tmp/f64.csv" || fail "float64 $surface $density"
}
f32_refusals() {
  f32_refused 'sphere:r=1e70' uniform "" "the x, y, z columns reach" "$@"
  f32_refused 'sphere:r=1e-50' uniform "" "the x, y, z columns span" "$@"
  f32_refused 'expr:x=u;y=v;z=0' 'expr:1e300*u' --density-column "the density column reaches" "$@"
  # A mesh's box is its triangles' corners: an octahedron of radius 1e39.
  printf 'v 1e39 0 0\nv -1e39 0 0\nv 0 1e39 0\nv 0 -1e39 0\nv 0 0 1e39\nv 0 0 -1e39\n' > "$tmp/big.obj"
  printf 'f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n' >> "$tmp/big.obj"
  f32_refused "obj:$tmp/big.obj" uniform "" "the x, y, z columns reach 1e+39" "$@"
}
