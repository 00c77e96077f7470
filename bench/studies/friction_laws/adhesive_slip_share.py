#!/usr/bin/env python3
"""Why μ's adhesive part changes over a study: the interface's shear force against its work.

For each point of a friction-laws study (bench/studies/friction_laws/friction_laws_study.sh) run with a Coulomb law of
coefficient MU_A, from the first draw (contact.csv holds its last step; result.json its work split
over μ's window):
  shear force / load  Σ|τ| w / (p L): the interface's tangential force per unit normal load
  stick share         the share of the contact's normal force at points below the slip limit
                      |τ| < MU_A p (to 0.1 %)
  slip / slide        the interface's frictional work per unit slide and load (μ's adhesive part)
                      over that force: the share of the imposed slide the contact points actually
                      slip; the rest the chip's surface layer takes as shear (in the plastic work).
The slip share is an estimate: the force is the last step's, the work the window's mean.

  /usr/bin/python3 bench/studies/friction_laws/adhesive_slip_share.py STUDY/coulomb MU_A
"""
import csv
import json
import os
import sys

from plot_friction_laws import point_of  # the study's point directory name: (p MPa, v m/min, T °C)

INTERVAL_M = 10e-6  # the default scenes' period (geometry.interval)
SLIP_LIMIT_FRACTION = 0.999  # |τ| below this share of μ_a p counts as stick


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    study, mu_a = sys.argv[1], float(sys.argv[2])
    print("| point | contact | shear force / load | stick share | adhesive part (draw 1) | slip / slide | plastic part (draw 1) |")
    print("|---|---|---|---|---|---|---|")
    for name in sorted(os.listdir(study)):
        result_path, contact_path = os.path.join(study, name, "result.json"), os.path.join(study, name, "contact.csv")
        point = point_of(name)
        if point is None or not (os.path.exists(result_path) and os.path.exists(contact_path)):
            continue
        result = json.load(open(result_path))
        if not result.get("completed"):
            continue
        pressure = point[0] * 1e6
        shear = normal = stick = 0.0
        for row in csv.DictReader(open(contact_path)):
            p, w, tau = float(row["pressure_pa"]), float(row["weight_m"]), abs(float(row["shear_pa"]))
            shear += tau * w
            if p > 0.0:
                normal += p * w
                if tau < SLIP_LIMIT_FRACTION * mu_a * p:
                    stick += p * w
        shear_per_load = shear / (pressure * INTERVAL_M)
        first = result["draws"][0]
        interface = first["work_split"]["mu_interface"]
        print(f"| {name} | {first['diagnostics']['contact_area_fraction']:.2f} | {shear_per_load:.3f} | "
              f"{stick / normal if normal > 0 else 0.0:.3f} | {interface:.4f} | {interface / shear_per_load:.2f} | "
              f"{first['work_split']['mu_bulk_plastic']:.3f} |")


if __name__ == "__main__":
    main()
