#!/usr/bin/env bash
# Fails, listing the files, where a C++ or GLSL source differs from what clang-format makes of it
# (.clang-format). CI runs it as the test Format.SourcesAreClangFormatted; fix with
#   git ls-files '*.cpp' '*.h' | xargs clang-format -i
#   scripts/check-format.sh [CLANG_FORMAT]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
clang_format="${1:-clang-format}"
cd "$root"
mapfile -t files < <(git ls-files -co --exclude-standard '*.cpp' '*.h' 2>/dev/null ||
                     find host tests shaders -name '*.cpp' -o -name '*.h')
bad=()
for f in "${files[@]}"; do
    [ -f "$f" ] || continue
    "$clang_format" --dry-run -Werror "$f" >/dev/null 2>&1 || bad+=("$f")
done
if ((${#bad[@]})); then
    echo "not clang-formatted (run: clang-format -i FILE):" >&2
    printf '  %s\n' "${bad[@]}" >&2
    exit 1
fi
echo "${#files[@]} files clang-formatted"
