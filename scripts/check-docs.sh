#!/usr/bin/env bash
# Keeps the documentation in step (run by the tests: tests/test_docs.cpp):
#   - README.md starts with the two quick-start commands, `make demo` and `make test`;
#   - docs/README.md lists every docs/*.md;
#   - every relative Markdown link in README.md and docs/*.md points at a file that exists;
#   - README.md copies no list of run configurations (it points at `wheelins run --help`).
set -uo pipefail
root=${1:-$(cd "$(dirname "$0")/.." && pwd)}
cd "$root" || exit 2
fail=0
bad() { echo "docs check: $*" >&2; fail=1; }

first_block=$(awk '/^```/{n++; next} n==1' README.md | grep -v '^\s*$' | sed 's/ *#.*//')
[ "$first_block" = $'make demo\nmake test' ] ||
  bad "README.md must open with a code block of exactly 'make demo' and 'make test', got: $first_block"

for f in docs/*.md; do
  b=$(basename "$f")
  [ "$b" = README.md ] && continue
  grep -q "](${b})" docs/README.md || bad "docs/README.md does not list $b"
done

for f in README.md docs/*.md; do
  dir=$(dirname "$f")
  # [text](target) with a relative target (no scheme, no pure #anchor)
  while IFS= read -r target; do
    t=${target%%#*}
    [ -z "$t" ] && continue
    case "$t" in http://*|https://*|mailto:*) continue ;; esac
    [ -e "$dir/$t" ] || bad "$f links to '$target', which does not exist"
  done < <(grep -o '\]([^)]*)' "$f" | sed 's/^](//; s/)$//')
done

if grep -Eq 'single-right|`single`, `dual-wheel`' README.md; then
  bad "README.md lists run configurations; point at 'wheelins run --help' instead"
fi
exit $fail
