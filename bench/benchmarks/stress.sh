#!/usr/bin/env bash
# Numerical stress of the micro-model and the GP trainer, nothing hidden: every case either converges
# or fails with a named reason, and the table says which; a NaN, a hang (killed after a time limit)
# or a crash is counted as such. Cases:
#   1. 100 random rough tools (seeds 1..100, the default's statistics) at the default state;
#   2. contact penalty 1e14 ... 1e20 Pa/m;   3. time step over three decades (0.1, 1, 10 ns, fixed);
#   4. degenerate inputs: flat tool, flat tool and chip, a gap at t = 0, zero velocity, huge pressure;
#   5. GP training on duplicated, clustered and noisy data and on n = 1 ... 5 points.
# Micro runs use the default 64 x 12 scene over 100 ns (average from 50 ns), two runs at a time with
# one thread each. Prints markdown tables; every result.json is kept in OUT_DIR.
# Usage: bash bench/benchmarks/stress.sh [BUILD] [OUT_DIR]
set -uo pipefail
if [[ ${1:-} == -h || ${1:-} == --help ]]; then sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'; exit 0; fi
build=${1:-build}
out=${2:-stress-out}
mufric=$(realpath "$build/app/mufric")
mkdir -p "$out"
out=$(realpath "$out")
limit_seconds=900
# The stress table was measured with seed 000's protocol on a 50 ns window
# (bench/studies/hardening/README.md).
short=(--set protocol.name=seed-000 --set time.duration=100ns --set time.average_from=50ns)
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'); machine: $(lscpu | sed -n 's/Model name: *//p'), $(nproc) cores; load: $(cut -d' ' -f1 /proc/loadavg)"

# One micro run: NAME OVERRIDES... -> OUT/NAME/{result.json,stdout,exit}
micro() {
  local name=$1; shift
  local dir=$out/$name
  mkdir -p "$dir"
  local start end code
  start=$(date +%s.%N)
  OMP_NUM_THREADS=1 timeout "$limit_seconds" "$mufric" micro run --quiet --out "$dir" "$@" > "$dir/stdout" 2>&1
  code=$?
  end=$(date +%s.%N)
  echo "$code" > "$dir/exit"
  awk -v s="$start" -v e="$end" 'BEGIN { printf "%.1f", e - s }' > "$dir/seconds"
}
export -f micro
export mufric out limit_seconds

# The outcome of a run as a table cell: converged (mu), failed (reason), hang, crash or NaN.
outcome() {  # DIR
  local dir=$1 code
  code=$(cat "$dir/exit")
  if [[ $code == 124 ]]; then echo "HANG (killed after ${limit_seconds} s)"; return; fi
  if ((code > 128)); then echo "CRASH (signal $((code - 128)))"; return; fi
  if [[ ! -s $dir/result.json ]]; then echo "error, exit $code: $(head -c 200 "$dir/stdout" | tr '\n|' ' /')"; return; fi
  /usr/bin/python3 - "$dir/result.json" <<'PY'
import json, math, sys
r = json.load(open(sys.argv[1]))
d = r.get("diagnostics", {})
warn = " ⚠ " + "; ".join(w[:60] for w in r["warnings"]) if r.get("warnings") else ""
if r["completed"]:
    mu = r["mu"]
    if mu is None or not math.isfinite(mu): print("NaN mu"); sys.exit()
    print(f"converged, mu {mu:.4f}, {d.get('cutbacks', 0)} cut-backs{warn}")
else:
    print("failed: " + r.get("reason", "?")[:160].replace("|", "/") + warn)
PY
}

echo
echo "### 1. 100 random rough tools at the default state (800 MPa, 100 m/min, 500 C)"
seq 1 100 | xargs -P 2 -I{} bash -c 'micro seed-{} "$@" --set geometry.tool_surface.synthetic.seed={}' _ "${short[@]}"
/usr/bin/python3 - "$out" <<'PY'
import json, math, os, statistics, sys
out = sys.argv[1]
mus, failed, other = [], [], []
for s in range(1, 101):
    d = os.path.join(out, f"seed-{s}")
    code = int(open(os.path.join(d, "exit")).read())
    try:
        r = json.load(open(os.path.join(d, "result.json")))
    except Exception:
        other.append((s, code)); continue
    if r["completed"] and r["mu"] is not None and math.isfinite(r["mu"]): mus.append(r["mu"])
    else: failed.append((s, r.get("reason", "NaN mu")))
secs = [float(open(os.path.join(out, f"seed-{s}", "seconds")).read()) for s in range(1, 101)]
print(f"\nconverged {len(mus)} of 100; failed with a reason {len(failed)}; crash/hang/no result {len(other)}")
if mus:
    print(f"mu over the converged tools: mean {statistics.mean(mus):.4f}, std {statistics.stdev(mus):.4f} "
          f"({100*statistics.stdev(mus)/statistics.mean(mus):.1f} %), min {min(mus):.4f}, max {max(mus):.4f}; "
          f"wall time per run {statistics.mean(secs):.1f} s (max {max(secs):.1f} s)")
for s, why in failed: print(f"- seed {s}: {why[:200]}")
for s, code in other: print(f"- seed {s}: exit {code}, no result.json")
PY

table() {  # TITLE; then NAME|LABEL lines on stdin
  echo; echo "### $1"; echo; echo "| case | outcome | wall [s] |"; echo "|---|---|---|"
  while IFS='|' read -r name label; do
    printf '| %s | %s | %s |\n' "$label" "$(outcome "$out/$name")" "$(cat "$out/$name/seconds")"
  done
}

for exponent in 14 15 16 17 18 19 20; do echo "penalty-$exponent --set contact.penalty=1e$exponent"; done |
  xargs -P 2 -L 1 bash -c 'micro "$@" '"${short[*]}" _
for exponent in 14 15 16 17 18 19 20; do echo "penalty-$exponent|penalty 1e$exponent Pa/m"; done | table "2. Contact penalty (default 2e18)"

printf '%s\n' "step-0.1ns --set time.step=0.1ns --set time.max_step=0.1ns" "step-1ns --set time.step=1ns --set time.max_step=1ns" \
  "step-10ns --set time.step=10ns --set time.max_step=10ns" | xargs -P 2 -L 1 bash -c 'micro "$@" '"${short[*]}" _
printf '%s\n' "step-0.1ns|fixed step 0.1 ns" "step-1ns|fixed step 1 ns" "step-10ns|fixed step 10 ns (ramp 25 ns)" |
  table "3. Time step over three decades"

micro flat-tool "${short[@]}" --set 'geometry.tool_surface={"flat": true}' &
micro flat-both "${short[@]}" --set 'geometry.tool_surface={"flat": true}' --set 'geometry.chip_surface={"flat": true}'
wait
micro gap-1um "${short[@]}" --set geometry.initial_gap=1um &
micro zero-velocity "${short[@]}" --set load.velocity=0m/min
wait
micro pressure-5GPa "${short[@]}" --set load.pressure=5GPa &
micro pressure-50GPa "${short[@]}" --set load.pressure=50GPa
wait
micro no-ramp "${short[@]}" --set load.ramp=0ns
printf '%s\n' "flat-tool|flat tool (expect mu = 0)" "flat-both|flat tool and flat chip" "gap-1um|1 um gap at t = 0 (default: touching)" \
  "zero-velocity|zero sliding velocity" "pressure-5GPa|pressure 5 GPa" "pressure-50GPa|pressure 50 GPa" "no-ramp|pressure applied at once (no ramp)" |
  table "4. Degenerate inputs"

echo
echo "### 5. GP training on awkward data (mufric train, then predict at the box centre)"
echo
echo "| data | train | predict at the centre |"
echo "|---|---|---|"
/usr/bin/python3 - "$out" <<'PY'
import numpy as np, os, sys
out = sys.argv[1]
rng = np.random.default_rng(7)
def write(name, x, mu):
    with open(os.path.join(out, name + ".csv"), "w") as f:
        f.write("contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu\n")
        for r, m in zip(x, mu): f.write(f"{r[0]!r},{r[1]!r},{r[2]!r},{m!r}\n")
def box(n): return np.column_stack([rng.uniform(300, 1300, n), rng.uniform(22.5, 200, n), rng.uniform(25, 900, n)])
def law(x): return 0.3 - 1e-4 * (x[:, 0] - 300) + 2e-4 * x[:, 1] - 5e-5 * x[:, 2]
x = box(40); write("duplicated-same", np.vstack([x, x]), np.concatenate([law(x), law(x)]))
write("duplicated-conflicting", np.vstack([x, x]), np.concatenate([law(x), law(x) + 0.05]))
c = np.array([800, 100, 500]) + rng.normal(0, 1e-6, (40, 3)); write("clustered-1e-6", np.vstack([c, box(2)]), law(np.vstack([c, box(2)])))
x = box(60); write("noisy-50pct", x, law(x) * (1 + 0.5 * rng.standard_normal(60)))
for n in range(1, 6): x = box(n); write(f"n{n}", x, law(x))
PY
for name in duplicated-same duplicated-conflicting clustered-1e-6 noisy-50pct n1 n2 n3 n4 n5; do
  train=$("$mufric" train --data "$out/$name.csv" --out "$out/$name.h5" 2>&1); code=$?
  if ((code == 0)); then
    train_cell="ok: $(grep -oE 'mean relative error [0-9.e+-]+ %' <<< "$train" | head -1)"
    predict=$("$mufric" predict --model "$out/$name.h5" --p 800MPa --v 100m/min --T 500C 2>&1 | grep -E '^mu' || echo "predict failed")
  else
    train_cell="refused (exit $code): $(grep -m1 'error:' <<< "$train" | cut -c1-170)"; predict="-"
  fi
  printf '| %s | %s | %s |\n' "$name" "${train_cell//|//}" "${predict//|//}"
done
