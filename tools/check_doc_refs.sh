#!/usr/bin/env bash
# Checks that what the code cites exists, so a reader can open it:
#  - every document a source file names (docs/ALGORITHM.md, python/README.md,
#    ...: a name in capitals ending in .md), looked up from the repository
#    root, the citing file's folder and docs/;
#  - every source path it names from a top-level folder of ours
#    (core/curve_tree.h, tools/fuzz.sh, ...), from the root or the citing
#    file's folder; generated files (*.pb.*) and paths inside another
#    project's tree (absl/base/..., CGAL/...) are not ours to check.
# Prints each dangling citation as file:line: name and exits 1 if any.
#   tools/check_doc_refs.sh [SOURCE_DIR]
set -euo pipefail
root="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
cd "$root"
bad=0
sources() {
  find . -mindepth 2 \( -path './build*' -o -path './.*' \) -prune -o -type f \
    \( -name '*.h' -o -name '*.cc' -o -name '*.py' -o -name '*.sh' -o -name '*.proto' \
       -o -name 'CMakeLists.txt' -o -name 'Dockerfile' -o -name '*.yaml' -o -name '*.in' \
       -o -name '*.template' -o -name '*.conf' \) -print | sed 's|^\./||' | sort
}
while IFS=: read -r file line name; do
  name="${name#/}"
  if [[ ! -e "$name" && ! -e "$(dirname "$file")/$name" && ! -e "docs/$name" ]]; then
    echo "$file:$line: cites $name, which is not in the repository"
    bad=1
  fi
done < <(sources | xargs -r grep -noE '[A-Za-z0-9_./-]*[A-Z][A-Z0-9_]+\.md\b' || true)
folders='base|core|request|cad|mesh|catalog|engine|kinds|proto|server|evaluation|render|client|python|tools|tests|bench|docker|fuzz|examples'
while IFS=: read -r file line name; do
  name="${name#[^A-Za-z]}"
  [[ "$name" == *.pb.* ]] && continue
  if [[ ! -e "$name" && ! -e "$(dirname "$file")/$name" ]]; then
    echo "$file:$line: cites $name, which is not in the repository"
    bad=1
  fi
done < <(sources | xargs -r grep -noE "(^|[^A-Za-z0-9_./-])($folders)/[A-Za-z0-9_./-]*[A-Za-z0-9_]\.(h|cc|py|sh|proto|md|txt|yaml|conf|template|map)\b" || true)
[[ $bad -eq 0 ]] || { echo "check_doc_refs: dangling citations above" >&2; exit 1; }
echo "check_doc_refs: every cited document and source path is in the repository"
