#!/usr/bin/env bash
# The production campaign's second part: after a prefix of the Sobol' plan (run.sh), the rest of the
# budget goes where the served interval is widest, by `dataset refine` (stochastic kriging, picks by
# the integrated variance of the mean they remove: a new point, or four more draws at one already
# run). The interval over the box after the Sobol' prefix is widest at its edges
# (bench/studies/served_interval/README.md,
# "The served interval over the whole box"), which a uniform plan samples least.
# Resumable: run it again after a stop. --drop-pending leaves out the plan rows not yet run (the
# unrun Sobol' tail the first time, an interrupted round's picks after a stop), and the budget is
# what is left of TOTAL samples. Never part of CI.
#   TOTAL=192 nohup bash campaigns/dry_default/refine.sh > refine.log 2>&1 &    # one core
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
mufric=${MUFRIC:-$here/../../build/app/mufric}
total=${TOTAL:-192}     # 8 core-hours at the campaign's 2.5 min of one core per sample
db=$here/db.h5
samples=$("$mufric" dataset status "$db" | sed -n 's/^  samples: \([0-9]*\) .*/\1/p')
if [[ -z $samples ]]; then echo "refine.sh: cannot read the sample count of $db" >&2; exit 2; fi
budget=$((total - samples))
if ((budget <= 0)); then echo "refine.sh: $db already holds $samples samples of $total"; exit 0; fi
echo "refine.sh: $samples samples in $db; $budget more, in rounds of 8"
OMP_NUM_THREADS=1 exec "$mufric" dataset refine --db "$db" --budget "$budget" --batch 8 --drop-pending \
  --jobs "${JOBS:-1}" --threads 1 --sample-timeout 900
