#!/bin/bash
# The CLI, started by name from the PATH in a folder that holds a file named
# like it and a bogus libsfcsampler-cad.so, never loads that module: the CAD
# kind's module is looked for beside the real executable
# (kinds/module_kind.h), never in the working directory.
# usage: module_search_test.sh SFCSAMPLER_CLI
set -euo pipefail
cli=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
printf 'sfcsampler-nurbs 1\ndegree 1 1\ncount 2 2\nknots_u 0 0 1 1\nknots_v 0 0 1 1\npole 0 0 0\npole 0 1 0\npole 1 0 0\npole 1 1 0.5\n' > "$work/sheet.nurbs"
mkdir "$work/bin"
ln -s "$cli" "$work/bin/sfcsampler"
cd "$work"
touch sfcsampler
echo "not a module" > libsfcsampler-cad.so
PATH="$work/bin:$PATH" sfcsampler sample --surface "nurbs:$work/sheet.nurbs" -n 100 -q -o "$work/out.csv"
lines=$(wc -l < "$work/out.csv")
[ "$lines" -eq 101 ] || { echo "FAIL: expected 100 samples and a header, got $lines lines"; exit 1; }
echo "ok: the module came from beside the executable"
