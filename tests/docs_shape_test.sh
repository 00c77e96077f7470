#!/usr/bin/env bash
# The README a newcomer reads in five minutes (issue 50): at most 300 lines, its first section
# heading within the first 40; bench/RESULTS.md's table of contents lists its sections as they are;
# no file points at a document outside the repository (issue 71: a clone does not have it).
# Usage: tests/docs_shape_test.sh SOURCE_DIR
set -euo pipefail
readme=$1/README.md
lines=$(wc -l <"$readme")
first_heading=$(grep -n -m1 '^## ' "$readme" | cut -d: -f1)
status=0
if ((lines > 300)); then
  echo "README.md has $lines lines, more than 300: move detail to docs/usage.md or docs/status.md"
  status=1
fi
if [[ -z $first_heading ]] || ((first_heading > 40)); then
  echo "README.md's first section heading is at line ${first_heading:-none}, after line 40"
  status=1
fi
/usr/bin/python3 "$1/bench/tools/results_toc.py" --check "$1/bench/RESULTS.md" || status=1
if [[ -d $1/.git ]]; then
  outside=$(git -C "$1" grep -n -I -E 'ARCHITECTURE\.md|\.\./shared/|shared/(notes|seeds)/' -- . ':!tests/docs_shape_test.sh' || true)
  if [[ -n $outside ]]; then
    echo "files point at documents outside the repository (say it in docs/formats.md or docs/design.md instead):"
    echo "$outside"
    status=1
  fi
fi
((status == 0)) && echo "README.md: $lines lines, first section at line $first_heading; RESULTS.md's contents current"
exit $status
