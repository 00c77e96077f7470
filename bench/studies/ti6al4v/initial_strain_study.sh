#!/usr/bin/env bash
# Does the chip's hardening as it arrives at the tool matter to mu? (issue 60; bench/studies/ti6al4v/README.md, "The chip's
# initial plastic strain"). The Ti6Al4V scene at the rake-face states of the slowest and fastest measured cuts
# (data/cirp2022_ti6al4v_tin/rake_face_mu_0deg.csv: 5 and 40 m/min) with Childs' law at the campaign box's
# largest coefficients and at its centre, for a virgin chip (seed 000's) and for one that has passed the
# primary shear zone (load.initial_plastic_strain, Merchant's gamma/sqrt(3) of the measured shear angles).
# Paired: the same surfaces (seeds) in every run. One core; about 2-4 min a run.
#   bash bench/studies/ti6al4v/initial_strain_study.sh [STRAINS] > study.csv      (STRAINS default "0 1")
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
mufric=${MUFRIC:-$here/../../../build/app/mufric}
scene=$here/../../../micro/scene/ti6al4v_tin.json
strains=${1:-0 1}
realisations=${REALISATIONS:-2}
out=$(mktemp -d)
echo "speed_case,contact_pressure[MPa],sliding_velocity[m/min],temperature[C],adhesive_coefficient,shear_factor,initial_plastic_strain,mu,mu_se,seconds"
# the 5 and 40 m/min rake-face states (rounded)
for state in "5:916:2.64:420" "40:1289:31.2:845"; do
  IFS=: read -r speed p v T <<< "$state"
  for coefficients in "1:1" "0.525:0.55"; do
    IFS=: read -r mua m <<< "$coefficients"
    for e in $strains; do
      start=$(date +%s)
      OMP_NUM_THREADS=1 "$mufric" micro run "$scene" --quiet --out "$out/run" \
        --set load.pressure=${p}MPa --set load.velocity=${v}m/min --set load.temperature=${T}C \
        --set contact.adhesive_coefficient=$mua --set contact.shear_factor=$m \
        --set load.initial_plastic_strain=$e --set protocol.realisations=$realisations > /dev/null
      mu=$(/usr/bin/python3 -c "import json; r=json.load(open('$out/run/result.json')); print(r['mu'], r['mu_std_error'] if r['mu_std_error'] is not None else '', sep=',')")
      echo "$speed,$p,$v,$T,$mua,$m,$e,$mu,$(( $(date +%s) - start ))"
    done
  done
done
rm -rf "$out"
