#!/usr/bin/env bash
# The Ti6Al4V-on-TiN-coated-carbide calibration campaign (issue 60): micro/scene/ti6al4v_tin.json
# (Seo et al. 2005's Johnson-Cook set and the thermal properties of Ducobu et al.'s Table tab:prop;
# the default rough surfaces; Childs' law, n = 1) over the box the measured cuts' rake-face states
# need (data/cirp2022_ti6al4v_tin: mean normal stress about 0.9-1.3 GPa, chip sliding velocity 2.5-31
# m/min, interface temperature estimated 400-900 C), with Childs' two coefficients as inputs:
# mu_a (the sliding part) and m (the sticking part). One law family with its limits inside the box:
# m -> 1 with small mu_a is Coulomb-like, large mu_a is shear-factor-like, either -> 0 frictionless,
# so `calibrate --fix` compares the laws on the same runs. 192 Sobol' samples x 4 draws, about
# 200 s a sample on one core (11 core-hours; the issue's budget is 16). Resumable; never part of CI.
#   nohup bash campaigns/ti6al4v_tin/run.sh > ti6al4v.log 2>&1 &      # one core, one free for builds
#   JOBS=2 bash campaigns/ti6al4v_tin/run.sh                           # both cores
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
exec bash "$here/../run_plan.sh" "$here/plan.h5" "$here/db.h5" 1800 -- \
  --samples 192 --design sobol --seed 11 --scene "$here/../../micro/scene/ti6al4v_tin.json" \
  --p 300MPa:2000MPa --v 1m/min:60m/min --T 100C:1100C --adhesive-coefficient 0.05:1 --shear-factor 0.1:1
