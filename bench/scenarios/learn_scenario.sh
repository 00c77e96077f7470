#!/usr/bin/env bash
# Issue 62's scenario: a meso code walks out of a small starting model's box (contact pressures of
# 150-400 MPa at first contact, below the box's 400 MPa) while `mufric learn` runs beside the server.
# A 16-point campaign on the coarse scene (deploy/coarse_scene.sh) makes the starting model; then, per
# round, the meso trace (bench/scenarios/learn_trace.py) asks the server and the learner runs one round. Writes
# OUT/rounds.csv (per pass: the share of the region's answers uncertain or outside, the median
# half-width over mu there, core-hours spent, the gate's decision before it), OUT/rounds.png, and
# prints the table. The budget is fixed beforehand: ROUNDS rounds of ROUND_SAMPLES runs and
# BUDGET core-hours.
#   bash bench/scenarios/learn_scenario.sh [--mufric build/app/mufric] [--out /tmp/learn-scenario] [--rounds 6]
#        [--round-samples 8] [--budget 0.5] [--jobs 1] [--start-samples 16] [--uncertain-width 0.05]
#        [--slurm-tasks N] [--damage-round K]
# (--uncertain-width: the server's, and the trace's definition of an uncertain answer: a 95 % interval
# wider than this; the learner rests once the log no longer sees such answers. --slurm-tasks: the
# learner's rounds run as a Slurm array of N tasks on the cluster SLURM_CONF names, instead of the
# local pool; bench/scenarios/learn_scenario_slurm.sh brings one up and compares the two. --damage-round K, with
# --slurm-tasks: round K's runs go through bench/scenarios/faulty_site/submit-dataset.sh, whose workers run
# another scene and record the campaign's; bench/scenarios/learn_damaged_round.sh checks what the gate makes of it.)
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
mufric=$here/build/app/mufric out=/tmp/learn-scenario rounds=6 round_samples=8 budget=0.5 jobs=1 start=16 width=0.05
engine=() damage_round=0
# shellcheck source=bench/tools/learn_common.sh
source "$here/bench/tools/learn_common.sh"
while (($#)); do
  learn_common_option "$@" && { shift 2; continue; }
  case $1 in
    --budget) budget=$2; shift 2 ;;
    --start-samples) start=$2; shift 2 ;;
    --uncertain-width) width=$2; shift 2 ;;
    --slurm-tasks) engine=(--slurm-tasks "$2" --slurm-poll 1); shift 2 ;;
    --damage-round) damage_round=$2; shift 2 ;;
    -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
    *) echo "unknown argument $1 (--help)"; exit 2 ;;
  esac
done
if ((damage_round > 0 && ${#engine[@]} == 0)); then echo "--damage-round needs --slurm-tasks (the faulty site is a Slurm site)"; exit 2; fi
source "$here/deploy/coarse_scene.sh"
prepare_learn_dir
started=$SECONDS

echo "== starting campaign: $start Sobol' points over p 400-1300 MPa (the coarse scene)"
"$mufric" dataset plan --out "$out/plan.h5" --samples "$start" --p 400MPa:1300MPa "${coarse_scene[@]}" >/dev/null
"$mufric" dataset run --plan "$out/plan.h5" --db "$out/db.h5" --jobs "$jobs" | tail -1
"$mufric" train --data "$out/db.h5" --out "$out/served/gp.h5" | tail -1

start_learning_server --models "$out/served" --poll 0.5 --log-uncertain "$out/logs" --uncertain-width "$width"

"$mufric" learn init "$out/learner" --db "$out/db.h5" --model "$out/served/gp.h5" --log "$out/logs/gp.csv" \
  --round-samples "$round_samples" --budget-core-hours "$budget"
trace() { "$py" "$here/bench/scenarios/learn_trace.py" "$address" gp --uncertain-width "$width" --pass-number "$1" "${@:2}"; }
trace 0 --header > "$out/passes.csv"
for r in $(seq 1 "$rounds"); do
  echo "== round $r ($((SECONDS - started)) s)"
  site=()
  ((r == damage_round)) && site=(--slurm-submit "$here/bench/scenarios/faulty_site/submit-dataset.sh") && echo "   (round $r through the faulty site)"
  "$mufric" learn run "$out/learner" --jobs "$jobs" "${engine[@]}" "${site[@]}" | grep -E "submitted|planned|published|kept aside|quarantined|resting|budget" || true
  sleep 2  # the server's poll (0.5 s) reloads a published version
  trace "$r" >> "$out/passes.csv"
done
wall=$((SECONDS - started))
"$py" - "$out" "$wall" <<'EOF'
import csv, json, sys
out, wall = sys.argv[1], int(sys.argv[2])
state = json.load(open(f"{out}/learner/learn.json"))
passes = list(csv.DictReader(open(f"{out}/passes.csv")))
rows, spent = [], 0.0
for p in passes:
    k = int(p["pass"])
    decision = ""
    if k >= 1 and k <= len(state["rounds"]):
        r = state["rounds"][k - 1]
        spent += r["run_core_seconds"] / 3600
        decision = "published" if r["gate"]["publish"] else ("kept aside: " + r["gate"]["reason"] if r["step"] == "done" else r["step"])
    rows.append([k, p["version"], p["region_points"], p["uncertain_or_outside_share"], p["median_half_width_over_mu"], f"{spent:.3f}", decision])
with open(f"{out}/rounds.csv", "w") as f:
    w = csv.writer(f)
    w.writerow(["pass", "version", "region_points", "uncertain_or_outside_share", "median_half_width_over_mu", "core_hours", "gate_before"])
    w.writerows(rows)
print("| pass | version | share uncertain or outside (p < 400 MPa) | median half-width / mu there | core-hours | gate (the round before) |")
print("|---|---|---|---|---|---|")
for r in rows:
    print(f"| {r[0]} | {r[1]} | {float(r[3]):.3f} | {float(r[4]):.3f} | {r[5]} | {r[6].split(':')[0]} |")
first, last = float(rows[0][3]), float(rows[-1][3])
points = int(rows[-1][2])
fall = f"{first / last:.1f}x lower" if last > 0 else f"none of the last pass's {points} region answers uncertain"
print(f"share {first:.3f} -> {last:.3f} ({fall}); wall {wall} s")
try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(9, 3.5))
    k = [r[0] for r in rows]
    ax[0].plot(k, [float(r[3]) for r in rows], "o-")
    ax[0].set_xlabel("pass (after round)"); ax[0].set_ylabel("share uncertain or outside, p < 400 MPa"); ax[0].set_ylim(-0.03, 1.03)
    ax[1].plot(k, [float(r[4]) for r in rows], "o-"); ax[1].axhline(0.05, color="grey", ls="--")
    ax[1].set_xlabel("pass (after round)"); ax[1].set_ylabel("median half-width / mu, p < 400 MPa")
    fig.tight_layout(); fig.savefig(f"{out}/rounds.png", dpi=110)
    print(f"wrote {out}/rounds.png")
except ImportError:
    pass
EOF
