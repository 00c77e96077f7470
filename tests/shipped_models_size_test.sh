#!/usr/bin/env bash
# The shipped models are kept in git without their fast evaluator: every file in models/ at most 1 MB
# (a grid is ~10 MB, and each retrain would add it to the history). The build tabulates the grid.
# Usage: tests/shipped_models_size_test.sh SOURCE_DIR
set -euo pipefail
big=$(find "$1/models" -name '*.h5' -size +1024k)
if [[ -n $big ]]; then
  echo "over 1 MB in git (store it without its fast evaluator: mufric upgrade FILE --rebuild --no-fast-evaluator):"
  ls -la $big
  exit 1
fi
echo "every shipped model in git is at most 1 MB: $(du -ch "$1"/models/*.h5 | tail -1 | cut -f1) in all"
