#!/usr/bin/env bash
# The Ti6Al4V recovery study's "measurements" (issue 60): the micro-model on the Ti6Al4V scene with
# Childs' coefficients mu_a* = 0.45 and m* = 0.7, which the campaign (run.sh) never ran, at 8
# conditions of the box the rake-face states need (a Sobol' plan of another seed), four draws each on
# surfaces of their own. bench/studies/calibration/recovery_calibration.sh --campaign campaigns/ti6al4v_tin --truth
# adhesive_coefficient=0.45 --truth shear_factor=0.7 [--condition-sd temperature=60] calibrates mu_a and m
# back from them, with the temperatures given exactly or with an SD. Resumable; never part of CI.
#   nohup bash campaigns/ti6al4v_tin/measure.sh > measure.log 2>&1 &      # one core
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
exec bash "$here/../run_plan.sh" "$here/measure-plan.h5" "$here/measure-db.h5" 1800 -- \
  --samples 8 --design sobol --seed 23 --scene "$here/../../micro/scene/ti6al4v_tin.json" \
  --p 600MPa:1600MPa --v 2m/min:40m/min --T 350C:950C \
  --set contact.adhesive_coefficient=0.45 --set contact.shear_factor=0.7
