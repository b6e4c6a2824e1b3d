#!/bin/bash
# Format the C++ sources with the project's .clang-format, or check them.
#   scripts/format.sh            rewrite every tracked .h/.cc in place
#   scripts/format.sh --check    list the files clang-format would change; exit 1 if any
#   scripts/format.sh --check F  the same for the files F (used by the style test)
# The style is pinned to clang-format 14 (Debian 12); another major version may
# format some constructs differently, so the check refuses to run with it.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
check=0
if [ "${1:-}" = "--check" ]; then check=1; shift; fi
cf=""
for c in clang-format-14 clang-format; do
  if command -v "$c" >/dev/null; then cf="$c"; break; fi
done
if [ -z "$cf" ]; then
  echo "format.sh: clang-format (14) is not installed; 'make deps' installs it" >&2; exit 2
fi
major=$("$cf" --version | sed -n 's/.*version \([0-9]*\).*/\1/p')
if [ "$major" != "14" ]; then
  echo "format.sh: $cf is version $major; the project's style is pinned to clang-format 14" >&2; exit 2
fi
if [ $# -gt 0 ]; then
  files=("$@")
else
  cd "$root"
  mapfile -t files < <(git ls-files '*.h' '*.cc')
  if [ ${#files[@]} -eq 0 ]; then  # not a git checkout (an exported tree): take what is there
    mapfile -t files < <(find lib tools tests -name '*.h' -o -name '*.cc' | sort)
  fi
fi
if [ $check -eq 0 ]; then
  "$cf" -i --style=file:"$root/.clang-format" "${files[@]}"
  exit 0
fi
bad=0
for f in "${files[@]}"; do
  if ! "$cf" --style=file:"$root/.clang-format" "$f" | cmp -s - "$f"; then
    echo "not formatted: $f (run scripts/format.sh)"
    bad=1
  fi
done
exit $bad
