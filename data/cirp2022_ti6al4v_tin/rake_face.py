#!/usr/bin/python3
"""From the measured forces of cutting_tests.csv to the rake face: per cutting speed, the rake-face
friction coefficient, the mean normal stress, the chip's sliding velocity and the interface
temperature, each with its uncertainty; written to rake_face_analysis.csv (both inclinations, every
intermediate) and, for the orthogonal cuts only, to rake_face_mu_0deg.csv (what `mufric calibrate`
reads: the conditions with their SDs, mu and mu_sd). The oblique cuts' rows of the analysis treat them
as orthogonal (normal rake 14.93 deg against 15: tan gamma_n = tan gamma cos lambda_s) and are for
comparison only.

Method, per cutting speed V and inclination (the chip-forming forces of a 1 mm wide cut):
  1. Edge forces apart: at each speed each force is a straight line in the uncut chip thickness h,
     F(h) = F_edge + k h (the linear edge-force model of mechanistic cutting models, Altintas,
     Manufacturing Automation, 2nd ed. 2012, sec. 2.6; F_edge is the ploughing force of the edge,
     Albrecht 1960, J. Eng. Ind. 82:348), fitted by least squares to the three thicknesses. The slopes
     k_c, k_f carry the chip-forming forces F_c = k_c h b, F_f = k_f h b.
  2. Rake-face friction (Merchant 1945, J. Appl. Phys. 16:267, the force circle), for rake gamma:
     mu = (k_f + k_c tan gamma) / (k_c - k_f tan gamma).
  3. Shear angle from the measured chip ratio lambda_h (the mean over the three thicknesses):
     tan phi = cos gamma / (lambda_h - sin gamma); chip velocity V_c = V / lambda_h (the sliding
     velocity on the rake face).
  4. Contact length from Oxley's chip-equilibrium relation (Oxley, The Mechanics of Machining, 1989,
     ch. 4; the form of pantale/OxleyPython): with the friction angle lambda = atan mu and
     theta = lambda + phi - gamma, C n_eq = 1 + pi/2 - 2 phi - tan theta (Oxley's angle relation
     solved for the measured theta; taken as 0 where negative) and
     l_c = h sin theta / (cos lambda sin phi) [1 + C n_eq / (3 tan theta)]; l_c is proportional to h,
     so the mean normal stress p = (k_c cos gamma - k_f sin gamma) h / l_c does not depend on h.
  5. Interface temperature, Oxley's (1989) mean tool-chip interface temperature at each h:
     the shear zone's rise dT_sz = (1 - beta) F_s V_s / (m_dot c_p) with Boothroyd's partition
     beta = 0.5 - 0.35 log10(R_T tan phi) (R_T tan phi <= 10), 0.3 - 0.15 log10(R_T tan phi) (above),
     R_T = rho c_p V h / K; the chip's mean rise from friction dT_c = F V_c / (m_dot c_p); the
     interface's maximum rise dT_M = dT_c 10^(0.06 - 0.195 delta sqrt(R_T t2 / l_c)) sqrt(R_T t2 / l_c)
     with t2 = lambda_h h and the secondary zone's relative thickness delta; and
     T_int = T_w + dT_sz + psi dT_M, psi = 0.9. The temperature at the speed is the mean over the three
     thicknesses; their spread is part of its SD.
Uncertainty, by Monte Carlo (fixed seed): each measured mean drawn from a normal of its standard error
(the error bar's 2 sigma / 2 / sqrt(3), three repeats; forces and chip ratio independent), the
standard errors of a force at a speed scaled by the Birge ratio sqrt(chi^2 / dof) of its line's
weighted fit where that exceeds 1 (Birge 1932, Phys. Rev. 40:207; the Particle Data Group's scale
factor): where three means do not lie on a line within their errors (the feed force at 20 m/min,
lambda_s = 0: chi^2 = 8.6 on 1 degree of freedom), the line's slope is that much less certain; delta
log-uniform on [0.005, 0.2] (the range OxleyPython optimises it over), and the chip's conductivity
and specific heat uniform on [6.3, 15] W/(m K) and [531, 700] J/(kg K): the source gives their
293 K values and says they depend on temperature; the ranges are our assumption for Ti6Al4V between
room temperature and the interface's. The calibrate file reports each quantity's Monte Carlo mean
and SD; mu and the conditions are correlated through the same draws, which calibrate does not use.
Usage: rake_face.py [--draws N] [--seed S]"""
import argparse
import csv
import io
import math
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
RAKE_ANGLE_DEG = 15.0            # Table tab:CutCond
CUT_WIDTH_M = 1e-3                # the rib's width
DENSITY = 4430.0                 # kg/m^3, Table tab:prop
ROOM_TEMPERATURE_K = 293.0       # Table tab:prop, T_room; the cuts start at room temperature
OXLEY_PSI = 0.9                  # mean interface rise over the maximum (Oxley 1989)
CONDUCTIVITY_RANGE = (6.3, 15.0)     # W/(m K), assumption above
SPECIFIC_HEAT_RANGE = (531.0, 700.0)  # J/(kg K), assumption above
DELTA_RANGE = (0.005, 0.2)
THICKNESSES_UM = (40.0, 60.0, 80.0)


def read_tests():
    lines = [l for l in (HERE / "cutting_tests.csv").read_text().splitlines() if not l.startswith("#")]
    return list(csv.DictReader(io.StringIO("\n".join(lines))))


def standard_error(row, quantity, unit):
    """The standard error of a mean of three repeats, from the error bar's 2 sigma."""
    return float(row[f"{quantity}_exp_2sd[{unit}]"]) / 2.0 / math.sqrt(3.0)


def birge_ratio(h_m, means, errors):
    """sqrt(chi^2 / dof) of the weighted least-squares line through (h, mean) with these errors."""
    weights = 1.0 / errors**2
    design = np.column_stack([np.ones_like(h_m), h_m])
    coefficients = np.linalg.solve(design.T @ (weights[:, None] * design), design.T @ (weights * means))
    chi2 = float(np.sum(weights * (means - design @ coefficients) ** 2))
    return math.sqrt(chi2 / (len(h_m) - 2))


def line_fits(h_m, forces):
    """Slopes and intercepts of least-squares lines through (h, F) for every draw (rows of forces)."""
    h_centred = h_m - h_m.mean()
    slope = (forces - forces.mean(axis=1, keepdims=True)) @ h_centred / (h_centred @ h_centred)
    intercept = forces.mean(axis=1) - slope * h_m.mean()
    return slope, intercept


def oxley_interface_temperature(speed, h, k_c, k_f, chip_ratio, phi, lc, delta, conductivity, specific_heat):
    """Oxley's mean tool-chip interface temperature (K) of the chip-forming forces at thickness h."""
    gamma = math.radians(RAKE_ANGLE_DEG)
    force_c, force_f = k_c * h * CUT_WIDTH_M, k_f * h * CUT_WIDTH_M
    shear_force = force_c * np.cos(phi) - force_f * np.sin(phi)
    shear_velocity = speed * math.cos(gamma) / np.cos(phi - gamma)
    friction_force = force_c * math.sin(gamma) + force_f * math.cos(gamma)
    chip_velocity = speed / chip_ratio
    mass_rate = DENSITY * speed * h * CUT_WIDTH_M
    thermal_number = DENSITY * specific_heat * speed * h / conductivity
    r_tan_phi = thermal_number * np.tan(phi)
    beta = np.where(r_tan_phi > 10.0, 0.3 - 0.15 * np.log10(r_tan_phi), 0.5 - 0.35 * np.log10(r_tan_phi))
    rise_shear_zone = (1.0 - beta) * shear_force * shear_velocity / (mass_rate * specific_heat)
    rise_chip = friction_force * chip_velocity / (mass_rate * specific_heat)
    ratio = thermal_number * chip_ratio * h / lc
    rise_max = rise_chip * 10.0 ** (0.06 - 0.195 * delta * np.sqrt(ratio)) * np.sqrt(ratio)
    return ROOM_TEMPERATURE_K + rise_shear_zone + OXLEY_PSI * rise_max


def analyse(rows, inclination, draws, rng):
    gamma = math.radians(RAKE_ANGLE_DEG)
    speeds = sorted({float(r["cutting_speed[m/min]"]) for r in rows})
    results = []
    for speed_m_per_min in speeds:
        at = {float(r["uncut_chip_thickness[um]"]): r for r in rows
              if float(r["cutting_speed[m/min]"]) == speed_m_per_min and float(r["inclination_angle[deg]"]) == inclination}
        h_m = np.array(THICKNESSES_UM) * 1e-6
        scale = {}

        def draw(quantity, unit, line=True):
            means = np.array([float(at[h][f"{quantity}_exp_mean[{unit}]"]) for h in THICKNESSES_UM])
            errors = np.array([standard_error(at[h], quantity, unit) for h in THICKNESSES_UM])
            scale[quantity] = max(1.0, birge_ratio(h_m, means, errors)) if line else 1.0
            return means + scale[quantity] * errors * rng.standard_normal((draws, len(means)))

        fc, ff, ratio = draw("Fc", "N"), draw("Ff", "N"), draw("chip_ratio", "1", line=False)
        # Slopes in N per metre of h per metre of width: Pa.
        k_c, edge_c = line_fits(h_m, fc)
        k_f, edge_f = line_fits(h_m, ff)
        k_c, k_f = k_c / CUT_WIDTH_M, k_f / CUT_WIDTH_M
        mu = (k_f + k_c * math.tan(gamma)) / (k_c - k_f * math.tan(gamma))
        chip_ratio = ratio.mean(axis=1)
        phi = np.arctan(math.cos(gamma) / (chip_ratio - math.sin(gamma)))
        friction_angle = np.arctan(mu)
        theta = friction_angle + phi - gamma
        c_neq = np.maximum(0.0, 1.0 + math.pi / 2.0 - 2.0 * phi - np.tan(theta))
        contact_per_h = np.sin(theta) / (np.cos(friction_angle) * np.sin(phi)) * (1.0 + c_neq / (3.0 * np.tan(theta)))
        pressure = (k_c * math.cos(gamma) - k_f * math.sin(gamma)) / contact_per_h
        speed = speed_m_per_min / 60.0
        sliding_velocity = speed / chip_ratio
        delta = np.exp(rng.uniform(math.log(DELTA_RANGE[0]), math.log(DELTA_RANGE[1]), draws))
        conductivity = rng.uniform(*CONDUCTIVITY_RANGE, draws)
        specific_heat = rng.uniform(*SPECIFIC_HEAT_RANGE, draws)
        temperatures = np.column_stack([
            oxley_interface_temperature(speed, h, k_c, k_f, chip_ratio, phi, contact_per_h * h, delta, conductivity,
                                        specific_heat) for h in h_m])
        temperature = temperatures.mean(axis=1)
        results.append({
            "inclination": inclination, "speed": speed_m_per_min,
            "k_c": k_c, "k_f": k_f, "edge_c": edge_c, "edge_f": edge_f, "chip_ratio": chip_ratio,
            "phi": np.degrees(phi), "mu": mu, "c_neq": c_neq, "contact_per_h": contact_per_h,
            "pressure": pressure, "sliding_velocity": sliding_velocity, "temperature": temperature,
            "temperature_40": temperatures[:, 0], "temperature_80": temperatures[:, 2],
            "birge_c": np.full(draws, scale["Fc"]), "birge_f": np.full(draws, scale["Ff"]),
        })
    return results


def mean_sd(x):
    return float(np.mean(x)), float(np.std(x, ddof=1))


PROVENANCE = [
    "# Rake-face friction of dry Ti6Al4V cut by a TiN-coated carbide tool (rake 15 deg), per cutting speed, derived by",
    "# data/cirp2022_ti6al4v_tin/rake_face.py from the measured forces and chip ratios in cutting_tests.csv (Ducobu,",
    "# Pantale & Lauwers, https://github.com/pantale/CIRP-2022-paper commit 0d1f9017d5089b734567cf86066429b633951d95,",
    "# vector figures; see README.md). Method: edge forces apart by the forces' lines in h (Altintas 2012; Albrecht 1960),",
    "# Merchant's rake-face friction from the slopes, the shear angle from the chip ratio, Oxley's (1989) contact length",
    "# and mean interface temperature; mean and SD over Monte Carlo draws of the repeats' standard errors and of the",
    "# assumed thermal properties (rake_face.py's docstring). The conditions are estimates, not measurements: give",
    "# them to calibrate with their SDs.",
]


def write_outputs(results, draws, seed):
    analysis_header = ["inclination_angle[deg]", "cutting_speed[m/min]"]
    names = [("mu", "mu", 1.0), ("contact_pressure[MPa]", "pressure", 1e-6),
             ("sliding_velocity[m/min]", "sliding_velocity", 60.0), ("temperature[C]", "temperature", 1.0),
             ("temperature_at_40um[C]", "temperature_40", 1.0), ("temperature_at_80um[C]", "temperature_80", 1.0),
             ("chip_ratio", "chip_ratio", 1.0), ("shear_angle[deg]", "phi", 1.0),
             ("contact_length_per_h", "contact_per_h", 1.0), ("C_neq", "c_neq", 1.0),
             ("specific_cutting_force[MPa]", "k_c", 1e-6), ("specific_feed_force[MPa]", "k_f", 1e-6),
             ("edge_cutting_force[N]", "edge_c", 1.0), ("edge_feed_force[N]", "edge_f", 1.0),
             ("birge_ratio_cutting_force", "birge_c", 1.0), ("birge_ratio_feed_force", "birge_f", 1.0)]
    for label, _, _ in names:
        unit = label[label.find("["):] if "[" in label else ""
        base = label[:label.find("[")] if "[" in label else label
        analysis_header += [label, f"{base}_sd{unit}"]
    lines = PROVENANCE + [f"# {draws} draws, seed {seed}. Temperatures in C (the mean over h = 40, 60, 80 um and at 40 and 80 um).",
                          ",".join(analysis_header)]
    for r in results:
        cells = [f"{r['inclination']:g}", f"{r['speed']:g}"]
        for _, key, scale in names:
            value = r[key] * scale - (273.15 if key.startswith("temperature") else 0.0)
            m, s = mean_sd(value)
            cells += [f"{m:.6g}", f"{s:.4g}"]
        lines.append(",".join(cells))
    (HERE / "rake_face_analysis.csv").write_text("\n".join(lines) + "\n")

    # Only the orthogonal cuts go to calibrate: the oblique ones (lambda_s = 6 deg) are held out of every
    # calibration, and their conditions must not come from their own feed force (the oblique check of
    # bench/studies/ti6al4v/ti6al4v_validation.py).
    for inclination in (0.0,):
        rows = [r for r in results if r["inclination"] == inclination]
        header = ["contact_pressure[MPa]", "contact_pressure_sd[MPa]", "sliding_velocity[m/min]",
                  "sliding_velocity_sd[m/min]", "temperature[C]", "temperature_sd[C]", "mu", "mu_sd"]
        speeds = ", ".join(f"{r['speed']:g}" for r in rows)
        out = PROVENANCE + [f"# Inclination {inclination:g} deg; one row per cutting speed ({speeds} m/min, in that order). "
                            f"{draws} draws, seed {seed}.",
                            ",".join(header)]
        for r in rows:
            p, ps = mean_sd(r["pressure"] * 1e-6)
            v, vs = mean_sd(r["sliding_velocity"] * 60.0)
            t, ts = mean_sd(r["temperature"] - 273.15)
            m, ms = mean_sd(r["mu"])
            out.append(f"{p:.6g},{ps:.4g},{v:.6g},{vs:.4g},{t:.6g},{ts:.4g},{m:.6g},{ms:.4g}")
        (HERE / f"rake_face_mu_{inclination:g}deg.csv").write_text("\n".join(out) + "\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--draws", type=int, default=20000)
    parser.add_argument("--seed", type=int, default=2026)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    rows = read_tests()
    results = analyse(rows, 0.0, args.draws, rng) + analyse(rows, 6.0, args.draws, rng)
    write_outputs(results, args.draws, args.seed)
    for r in results:
        print(f"lambda_s {r['inclination']:g} deg, {r['speed']:>4g} m/min: mu {np.mean(r['mu']):.3f} +- {np.std(r['mu']):.3f}, "
              f"p {np.mean(r['pressure']) / 1e6:6.0f} +- {np.std(r['pressure']) / 1e6:4.0f} MPa, "
              f"v_chip {np.mean(r['sliding_velocity']) * 60:5.2f} m/min, T {np.mean(r['temperature']) - 273.15:5.0f} +- "
              f"{np.std(r['temperature']):3.0f} C, l_c/h {np.mean(r['contact_per_h']):.2f}, "
              f"edges {np.mean(r['edge_c']):.1f} / {np.mean(r['edge_f']):.1f} N, "
              f"Birge {r['birge_c'][0]:.2f} / {r['birge_f'][0]:.2f}")


if __name__ == "__main__":
    main()
