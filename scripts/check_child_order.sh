#!/bin/sh
# One definition of the child order: include/amc/red_split.h. Fails when another source restates
# it in one of the forms it has taken before (literal child vertex tuples, the center child by
# number, neighbour children by (eq + 1) % 3, link-word tables, hand-written shuffles).
# Usage: scripts/check_child_order.sh [repository root]
set -eu
root=${1:-$(dirname "$0")/..}
cd "$root"
patterns='
[({]\s*(v|corner|c|i|j|t)\[?_?0\]?\s*,\s*(m|mid|mi|mj)\[?_?0\]?\s*,\s*(m|mid|mi|mj)\[?_?2\]?\s*[)}]
[({]\s*(m|mid|mi|mj)\[?_?0\]?\s*,\s*(v|corner|c|i|j|t)\[?_?1\]?\s*,\s*(m|mid|mi|mj)\[?_?1\]?\s*[)}]
[({]\s*(m|mid|mi|mj)\[?_?2\]?\s*,\s*(m|mid|mi|mj)\[?_?1\]?\s*,\s*(v|corner|c|i|j|t)\[?_?2\]?\s*[)}]
[({]\s*(m|mid|mi|mj)\[?_?1\]?\s*,\s*(m|mid|mi|mj)\[?_?2\]?\s*,\s*(m|mid|mi|mj)\[?_?0\]?\s*[)}]
child\([^;]*,\s*3\)|child_index\([^)]*\) == 3
child\([^;]*\((eq|e|k) \+ 1\) % 3\)
kFirstWord|kSecondWord
_MM_SHUFFLE
'
files=$(git ls-files 'src/*' 'include/*' 'tools/*' 'python/*' 'bench/*' | grep -E '\.(h|cpp|hpp|cc|c)$' |
        grep -v -x -e include/amc/red_split.h)
status=0
echo "$patterns" | while IFS= read -r pattern; do
    [ -n "$pattern" ] || continue
    for f in $(grep -l -E -e "$pattern" $files 2>/dev/null || true); do
        echo "child order restated: $f:"; grep -n -E -e "$pattern" "$f"; echo FAIL >&2; exit 1
    done
done
