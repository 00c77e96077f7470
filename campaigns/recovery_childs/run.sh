#!/usr/bin/env bash
# The calibration's recovery study on the micro-model itself (issue 51): a campaign whose inputs are
# seed 000's box and the shear factor m of Childs' law (contact.law=childs, mu_a 0.5, n 1: the
# smooth law a calibration fits; bench/studies/point_kernel_refactor/README.md, "The interface law
# as a point kernel" has it
# completing at the default point), so that "measurements" made by `mufric micro run` at an m* kept
# out of the plan can be calibrated back through the campaign's GP. The default dry scene, four
# independent draws per sample. Resumable: run it again after a stop. Never part of CI.
#   nohup bash campaigns/recovery_childs/run.sh > recovery.log 2>&1 &     # one core, one free for builds
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
exec bash "$here/../run_plan.sh" "$here/plan.h5" "$here/db.h5" 1800 -- \
  --samples 64 --design sobol --seed 1 \
  --p 300MPa:1300MPa --v 22.5m/min:200m/min --T 25C:900C --shear-factor 0.2:0.9 \
  --set contact.law=childs --set contact.adhesive_coefficient=0.5 --set contact.shear_factor=0.5 \
  --set contact.childs_exponent=1
