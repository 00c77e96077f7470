#!/usr/bin/env bash
# The shipped default model (models/dry_default.h5) from this campaign's database, with train's
# defaults. Rerun and commit both files together whenever db.h5 is committed: the CLI test
# Cli.TheShippedModelIsTheCampaignsFit retrains it and requires the same answers. Stored without its
# fast evaluator (the build tabulates it: CMakeLists.txt, shipped_models), so that the file in git
# stays under 1 MB.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
mufric=${MUFRIC:-$here/../../build/app/mufric}
"$mufric" train --data "$here/db.h5" --out "$here/../../models/dry_default.h5" --no-fast-evaluator
