#!/usr/bin/env python3
"""campaigns/meso_ti6al4v_sph/analyse.py on a made-up run whose steady state is known: Fc a mean of
100 N with a sine of three whole periods in the window, Ff 20 N, the chip 90 um thick for h = 60 um.
Its table must give those means, the measured values of Ducobu's 40 m/min, 60 um cut, the errors
and whether each lies inside the measured 2 sigma; the plots must be written.

  /usr/bin/python3 tests/meso_analyse_test.py SOURCE_DIR
"""
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

source = sys.argv[1]
script = os.path.join(source, "campaigns", "meso_ti6al4v_sph", "analyse.py")
failures = []


def check(condition, what):
    if not condition:
        failures.append(what)
        print("FAILED:", what)


with tempfile.TemporaryDirectory() as campaign:
    run = os.path.join(campaign, "runs", "v40_h60_made_up")
    os.makedirs(run)
    with open(os.path.join(campaign, "runs.csv"), "w") as f:
        f.write("# a comment\nname,options\nv40_h60_made_up,--speed 40m/min --feed 60um\nnot_run_yet,--feed 40um\n")
    summary = {"friction": "constant:0.43", "cutting_speed_m_per_min": 40, "uncut_thickness_um": 60,
               "mufric": {"points": 0, "extrapolated": 0, "share_of_wall": 0}}
    with open(os.path.join(run, "summary.json"), "w") as f:
        json.dump(summary, f)
    with open(os.path.join(run, "forces.csv"), "w") as f:
        f.write("travel[m],time[s],Fc[N/mm],Ff[N/mm],friction_over_normal[1],mu_weighted[1],chip_thickness[m],"
                "contact_points[1],mufric_seconds[s],wall_seconds[s]\n")
        for i in range(1, 601):
            travel = i * 1e-6
            # before the window: a transient that must not count
            fc = 100 + 10 * math.sin(2 * math.pi * travel / 100e-6) if travel >= 0.3e-3 else 10.0
            ff = 20.0 if travel >= 0.3e-3 else 500.0
            f.write(f"{travel},{travel / 0.667},{fc},{ff},0.3,0.43,{90e-6 if travel >= 0.3e-3 else 0},12,0,{i}\n")
    out = os.path.join(campaign, "analysis")
    os.makedirs(out)
    done = subprocess.run([sys.executable, script, "--campaign", campaign, "--out", out, "--window-from", "0.3mm"],
                          capture_output=True, text=True, env=dict(os.environ, MPLBACKEND="Agg"))
    check(done.returncode == 0, f"analyse.py exits 0 ({done.returncode}: {done.stderr[-500:]})")
    with open(os.path.join(out, "comparison.csv")) as f:
        rows = list(csv.DictReader(f))
    check(len(rows) == 1, f"one finished run, one row ({len(rows)})")
    r = rows[0]
    # 301 rows from 0.300 to 0.600 mm: the sine's three periods and one end point, sin(2 pi 3) = 0
    check(abs(float(r["Fc[N]"]) - 100.0) < 1e-9, f"Fc is the window's mean, 100 ({r['Fc[N]']})")
    check(float(r["Ff[N]"]) == 20.0, f"Ff 20 ({r['Ff[N]']})")
    check(abs(float(r["chip_ratio"]) - 1.5) < 1e-12, f"chip ratio 90/60 ({r['chip_ratio']})")
    check(abs(float(r["Fc_measured[N]"]) - 117.9563) < 1e-3, f"the measured Fc at 40 m/min, 60 um ({r['Fc_measured[N]']})")
    check(abs(float(r["Fc_error[%]"]) - 100 * (100 - 117.9563) / 117.9563) < 1e-3, f"Fc error ({r['Fc_error[%]']})")
    check(r["Fc_inside_2sd"] == "True", "Fc 100 lies inside 117.96 +- 26.68")
    check(r["Ff_inside_2sd"] == "False", "Ff 20 lies outside 50.40 +- 13.86")
    check(float(r["Fc_block_se[N]"]) > 0, "a sine's block means scatter")
    check(os.path.getsize(os.path.join(out, "forces.png")) > 10000, "forces.png written")
    bad = subprocess.run([sys.executable, script, "--campaign", campaign, "--window-from", "0.3"],
                         capture_output=True, text=True)
    check(bad.returncode != 0 and "needs a unit" in bad.stderr + bad.stdout, "a window without its unit is refused")

print("meso_analyse_test:", "FAILED" if failures else "passed")
sys.exit(1 if failures else 0)
