#!/usr/bin/env bash
# The micro-model's speed goal: one well-defined mu of the default dry scene (every tool draw of the
# press-slide protocol) at its converged 96 x 18 mesh on one core, run by two builds at the same
# time, one core each, so that their ratio is meaningful on a shared machine. With one build, the
# peer is the same build with seed 000's protocol (one draw, 250 ns) on the same mesh. Prints a
# markdown table; every run's result.json is kept in the output directory.
# Usage: bash bench/benchmarks/micro_speed.sh BUILD [PEER_BUILD] [OUT_DIR] [extra --set overrides...]
set -uo pipefail
if [[ $# -lt 1 || $1 == -h || $1 == --help ]]; then
  sed -n '2,7p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
build=$1
peer=${2:-}
out=${3:-micro-speed}
shift $(( $# < 3 ? $# : 3 ))
mkdir -p "$out"
converged=(--set discretisation.elements_x=96 --set discretisation.elements_y=18)  # press-slide: converged at 96 x 18
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'); machine: $(lscpu | sed -n 's/Model name: *//p'), $(nproc --all) cores; one core per run"
run() {  # label build dir overrides...
  local label=$1 bin=$2/app/mufric dir=$out/$3
  shift 3
  mkdir -p "$dir"
  OMP_NUM_THREADS=1 "$bin" micro run --quiet --out "$dir" "$@" > "$dir/summary.txt" 2>&1
  echo "$label" > "$dir/label"
}
if [[ -n $peer ]]; then
  run "$build, 96 x 18" "$build" a "${converged[@]}" "$@" &
  run "$peer, 96 x 18" "$peer" b "${converged[@]}" "$@" &
else
  run "$build, 96 x 18, press-slide" "$build" a "${converged[@]}" "$@" &
  run "$build, 96 x 18, seed 000's protocol" "$build" b "${converged[@]}" --set protocol.name=seed-000 "$@" &
fi
wait
printf '| run | dofs | draws | Newton | cut-backs | mu | wall [s] |\n|---|---|---|---|---|---|---|\n'
/usr/bin/python3 - "$out" <<'PY'
import json, sys, pathlib
out = pathlib.Path(sys.argv[1])
rows = []
for name in ("a", "b"):
    d = out / name
    try:
        r = json.load(open(d / "result.json"))
    except (OSError, ValueError):
        print(f"| {(d / 'label').read_text().strip()} | error: {(d / 'summary.txt').read_text().strip()[-120:]} |")
        continue
    g = r["diagnostics"]
    rows.append(g["wall_seconds"])
    mu = f'{r["mu"]:.5f}' if r["completed"] else "not completed"
    if r["completed"] and r.get("mu_std_error"):
        mu += f' ± {r["mu_std_error"]:.5f}'
    print(f'| {(d / "label").read_text().strip()} | {g["dofs"]} | {len(r["draws"])} | {g["newton_iterations"]} | '
          f'{g["cutbacks"]} | {mu} | {g["wall_seconds"]:.1f} |')
if len(rows) == 2:
    print(f"ratio first / second: {rows[0] / rows[1]:.2f}")
PY
