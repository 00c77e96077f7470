#!/usr/bin/env bash
# The lubricant's protocol study: the same scene run dry and lubricated under several film models,
# two runs at a time on one core each, with a table of what each run finds over its mu window —
# mu, the real contact area, how the normal load splits between contact and lubricant, where the
# film cavitated, and the work (cut-backs, coupling exchanges, seconds). Every run's result.json is
# kept in OUT_DIR/<label>/.
# Usage: bash bench/studies/lubricant/lubricant_study.sh BUILD OUT_DIR [coarse|default] label="--set k=v ..." ...
#   a variant's overrides are added to `--set physics=lubricated` (label dry: a dry run, no lubricant);
#   coarse (the default) is the 32 x 6 scene of the dataset benchmark with one tool.
# Example: bash bench/studies/lubricant/lubricant_study.sh build /tmp/lub coarse dry= \
#   none="--set lubricant.fill=after-pressing --set lubricant.cavitation=none"
set -uo pipefail
if [[ $# -lt 3 || $1 == -h || $1 == --help ]]; then
  sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
build=$1
out=$2
shift 2
scene=()
if [[ $1 == coarse || $1 == default ]]; then
  [[ $1 == coarse ]] && scene=(--set protocol.realisations=1 --set discretisation.elements_x=32 --set discretisation.elements_y=6
    --set geometry.chip_surface.fit.control_points=32 --set geometry.tool_surface.fit.control_points=32)
  shift
fi
mkdir -p "$out"
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'); machine: $(lscpu | sed -n 's/Model name: *//p'), $(nproc --all) cores; one core per run; load before: $(cut -d' ' -f1-3 /proc/loadavg)"
labels=()
run() {  # label overrides
  local label=$1 dir=$out/$1
  local -a extra
  read -r -a extra <<< "$2"
  [[ $label == dry ]] || extra=(--set physics=lubricated "${extra[@]}")
  mkdir -p "$dir"
  local start=$SECONDS
  OMP_NUM_THREADS=1 "$build/app/mufric" micro run --quiet --out "$dir" "${scene[@]}" "${extra[@]}" > "$dir/summary.txt" 2>&1
  echo $((SECONDS - start)) > "$dir/seconds"
}
running=0
for variant in "$@"; do
  label=${variant%%=*}
  labels+=("$label")
  run "$label" "${variant#*=}" &
  running=$((running + 1))
  if ((running == 2)); then wait -n; running=$((running - 1)); fi
done
wait
/usr/bin/python3 - "$out" "${labels[@]}" <<'PY'
import json, sys, pathlib
out = pathlib.Path(sys.argv[1])
print("| run | mu | contact area | window load [N/m]: contact y / lubricant y (x) | film cavitated | steps | cut-backs | coupling exchanges (max) | seconds |")
print("|---|---|---|---|---|---|---|---|---|")
for label in sys.argv[2:]:
    d = out / label
    seconds = (d / "seconds").read_text().strip()
    try:
        r = json.load(open(d / "result.json"))
    except (OSError, ValueError):
        print(f"| {label} | error: {(d / 'summary.txt').read_text().strip()[-160:]} | | | | | | | {seconds} |")
        continue
    draw = r["draws"][0]
    lo, hi = draw.get("mu_window_sliding_distance_m", [0.0, float("inf")])
    window = [s for s in draw["history"] if lo <= s["sliding_distance_m"] <= hi] if r["completed"] else draw["history"][-20:]
    n = max(len(window), 1)
    mean = lambda key: sum(s.get(key, 0.0) for s in window) / n
    fy, ly, lx = mean("force_y_n_per_m"), mean("fluid_force_y_n_per_m"), mean("fluid_force_x_n_per_m")
    mu = f'{r["mu"]:.4f}' if r["completed"] else "not completed: " + draw.get("reason", r.get("reason", ""))[:80]
    lub = draw.get("lubricant", {})
    g = r["diagnostics"]
    exchanges = f'{lub["coupling_iterations"]} ({lub["max_coupling_iterations_per_step"]})' if lub else "—"
    cavitated = f'{100 * mean("cavitated_fraction"):.1f} %' if lub else "—"
    print(f'| {label} | {mu} | {100 * mean("contact_area_fraction"):.1f} % | {fy - ly:.0f} / {ly:.0f} ({lx:.0f}) | {cavitated} | '
          f'{len(draw["history"])} | {g["cutbacks"]} | {exchanges} | {seconds} |')
PY
