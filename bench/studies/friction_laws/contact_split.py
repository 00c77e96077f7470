#!/usr/bin/env python3
"""Where the contact force of a micro run sits on a wedge-shaped tool: reads the run's contact.csv
(the first draw's final contact, one row per surface quadrature point) and splits the resultant by
the tool's slope at each point's closest point: the leading face (slope within 20 % of -tan(alpha)),
the trailing face (+tan(alpha)) and the apex between them. Prints each part's share of the normal
load and its own mu, and the share carried by points that are not penetrating (mortar spread).
Used for the Challen & Oxley check (bench/studies/friction_laws/challen_oxley_check.sh,
bench/studies/friction_laws/README.md).

  /usr/bin/python3 bench/studies/friction_laws/contact_split.py RUN_DIR/contact.csv ALPHA_DEG
"""
import csv
import math
import sys


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    tan_alpha = math.tan(math.radians(float(sys.argv[2])))
    parts = {"leading face": [0.0, 0.0], "apex": [0.0, 0.0], "trailing face": [0.0, 0.0]}
    separated_y = total_x = total_y = 0.0
    with open(sys.argv[1]) as f:
        for row in csv.DictReader(f):
            weight, pressure = float(row["weight_m"]), float(row["pressure_pa"])
            if pressure <= 0.0:
                continue
            nx, ny = float(row["normal_x"]), float(row["normal_y"])
            shear = float(row.get("shear_pa") or 0.0)  # along t = (-n_y, n_x)
            fx, fy = weight * (pressure * nx - shear * ny), weight * (pressure * ny + shear * nx)
            slope = -nx / ny  # the tool's dy/dx at the closest point
            # The sign of the leading face's slope: the tool moves toward -x relative to the chip.
            name = "leading face" if slope < -0.8 * tan_alpha else "trailing face" if slope > 0.8 * tan_alpha else "apex"
            parts[name][0] += fx
            parts[name][1] += fy
            total_x += fx
            total_y += fy
            if row["gap_m"] == "" or float(row["gap_m"]) <= 0.0:
                separated_y += fy
    if total_y == 0.0:
        sys.exit("no contact in " + sys.argv[1])
    print(f"mu = {total_x / total_y:.5f}, tan(alpha) = {tan_alpha:.5f}, ratio {total_x / total_y / tan_alpha:.4f}")
    for name, (fx, fy) in parts.items():
        own = f"{fx / fy:+.5f}" if fy != 0.0 else "-"
        print(f"{name:14s} share of the normal load {fy / total_y:6.3f}   its own mu {own}")
    print(f"carried by points that do not penetrate (the mortar spread): {separated_y / total_y:.3f}")


if __name__ == "__main__":
    main()
