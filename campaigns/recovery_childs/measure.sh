#!/usr/bin/env bash
# The recovery study's "measurements" (issue 51): the micro-model itself at a shear factor m* = 0.55
# that the campaign (run.sh) never ran, at 8 conditions of seed 000's box that it never ran either
# (a Sobol' plan with another shift), on surfaces of their own. Each measurement is a sample's mean
# over its four draws, its standard error the measurement's SD: what a tribometer paper reports as a
# mean and its scatter. bench/studies/calibration/recovery_calibration.sh calibrates m back from them. Resumable; never
# part of CI.
#   nohup bash campaigns/recovery_childs/measure.sh > measure.log 2>&1 &      # one core
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
exec bash "$here/../run_plan.sh" "$here/measure-plan.h5" "$here/measure-db.h5" 1800 -- \
  --samples 8 --design sobol --seed 7 \
  --p 300MPa:1300MPa --v 22.5m/min:200m/min --T 25C:900C \
  --set contact.law=childs --set contact.adhesive_coefficient=0.5 --set contact.shear_factor=0.55 \
  --set contact.childs_exponent=1
