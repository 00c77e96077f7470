#!/usr/bin/env bash
# The production campaign behind the shipped default model (issue 33): the default dry scene
# (micro/scene/dry_default.json, 64 x 12, 4 draws of tool and chip surfaces per sample) over the box
# real meso codes ask for, each plan row its own surfaces (independent draws). The box: seed 000's
# grown to p 300 MPa-3.1 GPa, v 1-2000 m/min, T 25-900 C, where every corner converges at this mesh
# (bench/studies/served_interval/README.md, "The production campaign"). Resumable: run it again
# after a stop; the database
# is rewritten after every sample. Never part of CI.
#   nohup bash campaigns/dry_default/run.sh > campaign.log 2>&1 &       # one core, one free for builds
#   JOBS=2 bash campaigns/dry_default/run.sh                              # both cores
# After a prefix of the plan (128 rows), refine.sh spends the rest of the budget where the interval is
# widest. Then: bash campaigns/dry_default/train.sh (the shipped model, committed with db.h5).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
exec bash "$here/../run_plan.sh" "$here/plan.h5" "$here/db.h5" 900 -- \
  --samples 256 --design sobol --seed 1 --p 300MPa:3100MPa --v 1m/min:2000m/min --T 25C:900C
