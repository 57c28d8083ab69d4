#!/usr/bin/env bash
# Checks that every #include "..." of our C++ follows tools/include_rules.txt
# (which folder may include which), and that OpenCASCADE's <*.hxx> headers
# appear only where the rules allow. Prints each violation as
# file:line: message and exits 1 if there is any, 0 otherwise (2: no rules).
#
#   tools/check_includes.sh [SOURCE_DIR [RULES_FILE]]
#
# SOURCE_DIR defaults to the repository root; build trees (build*/) and hidden
# folders are not read. Works without git (the container build has none).
set -euo pipefail
root="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
rules="${2:-$root/tools/include_rules.txt}"
[[ -f "$rules" ]] || { echo "check_includes: no rules file $rules" >&2; exit 2; }
cd "$root"

find . -mindepth 2 \( -path './build*' -o -path './.*' \) -prune -o \
     -type f \( -name '*.h' -o -name '*.hpp' -o -name '*.cc' -o -name '*.cpp' -o -name '*.c' \) \
     -print | sed 's|^\./||' | sort |
  xargs -r awk -v rules="$rules" '
    BEGIN {
      while ((getline line < rules) > 0) {
        sub(/#.*/, "", line)
        if (line !~ /:/) continue
        split(line, side, ":")
        head = side[1]; gsub(/^[ \t]+|[ \t]+$/, "", head)
        n = split(side[2], allowed, /[ \t]+/)
        if (head ~ /^@generated /) {
          sub(/^@generated +/, "", head)
          for (i = 1; i <= n; i++) if (allowed[i] != "") generated[head] = allowed[i]
        } else if (head == "@hxx") {
          for (i = 1; i <= n; i++) if (allowed[i] != "") hxx_ok[allowed[i]] = 1
        } else {
          ruled[head] = 1
          for (i = 1; i <= n; i++) if (allowed[i] != "") may[head, allowed[i]] = 1
        }
      }
      bad = 0
    }
    # The most specific ruled folder holding `path` ("client/cli" before
    # "client"), or "" if none does.
    function ruled_folder(path,    f, best) {
      best = ""
      for (f in ruled) if (index(path, f "/") == 1 && length(f) > length(best)) best = f
      return best
    }
    FNR == 1 {
      folder = ruled_folder(FILENAME)
      if (folder == "") {
        folder = FILENAME; sub(/\/.*/, "", folder)
        if (!(folder in unruled)) {
          unruled[folder] = 1
          printf "%s: the folder %s/ has C++ but no line in %s\n", FILENAME, folder, rules
          bad = 1
        }
      }
    }
    /^[ \t]*#[ \t]*include[ \t]*"/ {
      target = $0
      sub(/^[^"]*"/, "", target); sub(/".*/, "", target)
      if (target !~ /\//) next
      top = target; sub(/\/.*/, "", top)
      if (top in generated) top = generated[top]
      else top = ruled_folder(target)
      if (top == "" || top == folder) next
      if (!((folder, top) in may)) {
        printf "%s:%d: %s/ may not include %s (%s)\n", FILENAME, FNR, folder, target, rules
        bad = 1
      }
      next
    }
    /^[ \t]*#[ \t]*include[ \t]*<[^>]*\.hxx>/ {
      if (!(folder in hxx_ok)) {
        printf "%s:%d: OpenCASCADE headers stay in the @hxx folders of %s\n", FILENAME, FNR, rules
        bad = 1
      }
    }
    END { exit bad }
  ' || { echo "check_includes: includes break $rules" >&2; exit 1; }
echo "check_includes: every include follows $rules"
