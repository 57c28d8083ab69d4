#!/usr/bin/env bash
# Checks .clang-format's column limit on every C++, proto and Python file of
# the tree: prints each longer line as file:line
# and exits 1 if there is any. (Fix a C++ one with clang-format --lines=N:N -i
# FILE.) Needs no build.
#   tools/check_format.sh [SOURCE_DIR]
set -euo pipefail
root="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
cd "$root"
limit=$(sed -n 's/^ColumnLimit: *\([0-9]*\)/\1/p' .clang-format)
[ -n "$limit" ] || { echo "check_format: no ColumnLimit in .clang-format" >&2; exit 1; }
# The sources as found (a container build has no .git), without build trees.
long=$(find . \( -path './build*' -o -path './.*' \) -prune -o -type f \
         \( -name '*.h' -o -name '*.cc' -o -name '*.proto' -o -name '*.py' \) -print |
       sed 's|^\./||' | sort |
       xargs -r awk -v limit="$limit" \
         'length > limit { printf "%s:%d: %d columns\n", FILENAME, FNR, length }')
if [ -n "$long" ]; then
  echo "$long"
  echo "check_format: $(echo "$long" | wc -l) lines over $limit columns" >&2
  exit 1
fi
echo "check_format: every C++, proto and Python line within $limit columns"
