#!/usr/bin/env bash
# Checks that every document a source file names (docs/ALGORITHM.md,
# python/README.md, ...: a name in capitals ending in .md) is in the
# repository, so a reader of the code can open what it cites. A name is looked
# up from the repository root, the citing file's folder and docs/. Prints each
# dangling citation as file:line: name and exits 1 if there is any.
#   tools/check_doc_refs.sh [SOURCE_DIR]
set -euo pipefail
root="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
cd "$root"
bad=0
while IFS=: read -r file line name; do
  name="${name#/}"
  if [[ ! -e "$name" && ! -e "$(dirname "$file")/$name" && ! -e "docs/$name" ]]; then
    echo "$file:$line: cites $name, which is not in the repository"
    bad=1
  fi
done < <(find . -mindepth 2 \( -path './build*' -o -path './.*' \) -prune -o -type f \
           \( -name '*.h' -o -name '*.cc' -o -name '*.py' -o -name '*.sh' -o -name '*.proto' \
              -o -name 'CMakeLists.txt' -o -name 'Dockerfile' -o -name '*.yaml' -o -name '*.in' \) -print |
         sed 's|^\./||' | sort |
         xargs -r grep -noE '[A-Za-z0-9_./-]*[A-Z][A-Z0-9_]+\.md\b' || true)
[[ $bad -eq 0 ]] || { echo "check_doc_refs: dangling citations above" >&2; exit 1; }
echo "check_doc_refs: every cited document is in the repository"
