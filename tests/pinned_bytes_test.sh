#!/usr/bin/env bash
# The bytes of algorithm version sfcsampler-4, pinned. Version 4 is in
# development: only its own issues (33 to 36) re-pin these, until they have
# landed; after that the bytes are frozen. Each line of
# tests/pinned_bytes.txt is "SHA256 NAME ARGS...": the SHA-256 of the NPY file
# `sfcsampler sample -q --format npy ARGS` writes, over every curve, sequence,
# density kind and region kind, ranges and shards, float32, singular
# surfaces, a CAD model and a mesh. Lines may repeat a hash with other
# arguments that must not change the bytes (batch sizes), and every line of
# kVectorPaths runs again under each narrower vector path the CPU has
# (SFCSAMPLER_VECTOR_PATH: scalar, sse2, avx, avx2; one the CPU lacks runs
# the widest) and must give the same hash.
# Every line also runs with glibc's CPU dispatch narrowed to a CPU without
# AVX, AVX2, FMA or AVX-512 (GLIBC_TUNABLES; our own dispatch reads the CPU
# itself and keeps its path): libm's FMA variants of sin, exp, pow and the
# like round differently, so a hash that moves here reads the C library
# somewhere the sampler promises machine-independent bytes.
#
# A changed hash means the same request now gives other samples: that needs
# a new algorithm version (request/sample_request.h), not a new pin.
#   tests/pinned_bytes_test.sh CLI MAKE_CAD_FIXTURES PINS [--print]
# --print writes the current hashes in the PINS format instead of checking.
set -euo pipefail
cli=$1 make_fixtures=$2 pins=$3 mode=${4:-check}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$make_fixtures" "$tmp" > /dev/null
# A small closed mesh (an octahedron with one vertex pulled out), as OBJ.
cp "$(dirname "$0")/pulled_octahedron.obj" "$tmp/mesh.obj"
hash_of() {  # ARGS...: the SHA-256 of the NPY the CLI writes
  "$cli" sample -q --format npy "$@" -o "$tmp/out.npy" 2> "$tmp/stderr" ||
    { cat "$tmp/stderr" >&2; echo "FAIL: sample $*" >&2; exit 1; }
  sha256sum < "$tmp/out.npy" | cut -c1-64
}
failures=0 checked=0
narrow_glibc=glibc.cpu.hwcaps=-AVX512F,-AVX2,-FMA,-FMA4,-AVX
while read -r expected name rest; do
  [[ -z "$expected" || "$expected" == \#* ]] && continue
  eval "args=($rest)"  # the file's own quoting; MODELS is the fixtures' folder
  args=("${args[@]//MODELS/$tmp}")
  got=$(hash_of "${args[@]}")
  if [[ "$mode" == --print ]]; then
    echo "$got $name $rest"
    continue
  fi
  checked=$((checked + 1))
  if [[ "$got" != "$expected" ]]; then
    echo "FAIL: $name ($rest): $got, pinned $expected" >&2
    failures=$((failures + 1))
  fi
  got=$(GLIBC_TUNABLES=$narrow_glibc hash_of "${args[@]}")
  checked=$((checked + 1))
  [[ "$got" == "$expected" ]] || { echo "FAIL: $name under $narrow_glibc: $got" >&2; failures=$((failures + 1)); }
  if [[ "$name" == *@paths ]]; then
    for path in scalar sse2 avx avx2; do
      got=$(SFCSAMPLER_VECTOR_PATH=$path hash_of "${args[@]}")
      checked=$((checked + 1))
      [[ "$got" == "$expected" ]] || { echo "FAIL: $name on the $path path: $got" >&2; failures=$((failures + 1)); }
    done
  fi
done < "$pins"
[[ "$mode" == --print ]] && exit 0
echo "$checked hashes checked, $failures differ"
[[ $failures -eq 0 ]]
