#!/bin/bash
# One small press-slide run per interface law (the small scene of tests/test_micro_run.cpp's
# small_press_slide, one phase), printing each run's mu with all its digits: the check that a
# refactor leaves every law's result unchanged to the bit
# (bench/studies/point_kernel_refactor/README.md, issue 50).
# Usage: bash bench/tools/law_runs.sh MUFRIC_BINARY OUT_DIR > mu.txt; then diff two binaries' mu.txt.
set -euo pipefail
bin=${1:?usage: law_runs.sh MUFRIC_BINARY OUT_DIR}
out=${2:?usage: law_runs.sh MUFRIC_BINARY OUT_DIR}
mkdir -p "$out"
cat > "$out/table.csv" <<'CSV'
contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu_a
0,100,20,0.1
2000,100,20,0.5
CSV
small=(--set discretisation.elements_x=32 --set discretisation.elements_y=4
       --set geometry.chip_surface.fit.control_points=32 --set geometry.tool_surface.fit.control_points=32
       --set protocol.run_in=0.25um --set protocol.window=0.5um --set protocol.step_distance=50nm
       --set protocol.phases=1 --set protocol.realisations=1 --set protocol.press_hold=10ns
       --set load.pressure=400MPa)
run() {
  local name=$1
  shift
  OMP_NUM_THREADS=1 "$bin" micro run --quiet --out "$out/$name" "${small[@]}" "$@" > "$out/$name.log" 2>&1 || true
  echo "$name $(/usr/bin/python3 -c "import json,sys; print(repr(json.load(open(sys.argv[1]))['mu']))" "$out/$name/result.json")"
}
run coulomb --set contact.law=coulomb --set contact.adhesive_coefficient=0.1
run shear --set contact.law=shear-factor --set contact.shear_factor=0.5
run zorev --set contact.law=zorev --set contact.adhesive_coefficient=0.3 --set contact.shear_factor=0.2
run table --set contact.law=table --set "contact.table=$out/table.csv"
run lubricated_zorev --set physics=lubricated --set contact.law=zorev --set contact.adhesive_coefficient=0.3 \
  --set contact.shear_factor=0.5
run adiabatic_coulomb --set contact.law=coulomb --set contact.adhesive_coefficient=0.2 --set thermal.model=adiabatic
