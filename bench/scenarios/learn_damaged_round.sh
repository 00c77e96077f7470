#!/usr/bin/env bash
# Issue 62: the gate refuses a deliberately damaged round, and the meso trace never sees it. The
# learning scenario (bench/scenarios/learn_scenario.sh: the real micro-model on the coarse scene, a meso trace
# walking below a 16-point model's box) with its rounds as a 2-task Slurm array on a single-node
# cluster of its own (deploy/slurm/single-node-cluster.sh; root, slurm-wlm and munge); round DAMAGE
# goes through a faulty site (bench/scenarios/faulty_site/) whose workers run another scene (Coulomb adhesion
# 0.1 at the contact points) and record the campaign's, so that no provenance check sees it. Checks
# and writes to OUT/verdict.txt: that round kept aside for its values, its runs quarantined in the
# database, the served version unchanged across it, and no pass of the meso trace answered by it.
#   [OUT=/tmp/learn-damaged] [DAMAGE_ROUND=2] bash bench/scenarios/learn_damaged_round.sh [learn_scenario.sh arguments...]
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
out=${OUT:-/tmp/learn-damaged} damage=${DAMAGE_ROUND:-2}
[[ ${1:-} == -h || ${1:-} == --help ]] && { sed -n '2,10p' "$0"; exit 0; }
source "$here/deploy/slurm/single-node-cluster.sh"
single_node_slurm_until_exit
rm -rf "$out" && mkdir -p "$out"

bash "$here/bench/scenarios/learn_scenario.sh" --out "$out/scenario" --slurm-tasks 2 --damage-round "$damage" "$@" | tee "$out/scenario.txt"
mufric=$here/build/app/mufric
args=("$@")
for ((i = 0; i + 1 < ${#args[@]}; ++i)); do [[ ${args[i]} == --mufric ]] && mufric=${args[i + 1]}; done
"$mufric" dataset status "$out/scenario/db.h5" > "$out/db-status.txt"
/usr/bin/python3 - "$out" "$damage" <<'PY' | tee "$out/verdict.txt"
import csv, json, sys
out, damage = sys.argv[1], int(sys.argv[2])
state = json.load(open(f"{out}/scenario/learner/learn.json"))
passes = list(csv.DictReader(open(f"{out}/scenario/passes.csv")))
r = state["rounds"][damage - 1]
runs = r["end_plan_row"] - r["first_plan_row"]
checks = [
    (f"round {damage} kept aside", not r["gate"]["publish"]),
    (f"refused for its values ({r['gate']['reason']})", r["gate"].get("values_refused", False)),
    (f"its {runs} runs quarantined ({r.get('quarantined', 0)} marked)", r.get("quarantined", 0) == runs),
    (f"the served version the same before and after it ({passes[damage - 1]['version']}, {passes[damage]['version']})",
     passes[damage - 1]["version"] == passes[damage]["version"]),
    (f"no pass answered by its candidate {r['version']}", all(p["version"] != r["version"] for p in passes)),
]
db_status = open(f"{out}/db-status.txt").read()
checks.append((f"the database names the quarantine (dataset status)", f"round {damage}'s gate refused its values" in db_status))
for text, ok in checks:
    print(("yes  " if ok else "NO   ") + text)
later = [x for x in state["rounds"][damage:] if x["step"] == "done"]
for x in later:
    print(f"round {x['number']}: {'published' if x['gate']['publish'] else 'kept aside'}: {x['gate']['reason']}")
print("damaged round refused and unseen: " + ("yes" if all(ok for _, ok in checks) else "no"))
PY
grep -q "damaged round refused and unseen: yes" "$out/verdict.txt"
