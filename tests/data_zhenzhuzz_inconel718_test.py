#!/usr/bin/python3
"""The Inconel 718 cutting data (data/zhenzhuzz_inconel718_carbide) against independent answers:
  1. the committed CSVs against the sentences and tables of the source's own text (the repository's report
     docx of January 2023, its slides of June 2023, its README of 2025, and the Klocke et al. 2013 paper it
     holds), written from the authors' own numbers;
  2. the vector-figure reader on a content stream built here from known values with the same constructs as
     the paper's figures (grey axis and tick rectangles, labels placed by Tm/TD, black bars drawn top-down in
     translated groups, white bars absolute, all on a 0.2208 pt device grid): recovery to one grid step, and a
     refusal of a bar off the grid;
  3. values of the paper's Figs. 7 and 3 against the values read by eye from their rendering;
  4. where a copy of the source repository is given (MUFRIC_INCONEL718_REPO, a clone or bare git directory),
     the extraction re-run from it gives the committed files byte for byte.
Usage: data_zhenzhuzz_inconel718_test.py SOURCE_DIR"""
import csv
import io
import os
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

SOURCE_DIR = Path(sys.argv.pop(1) if len(sys.argv) > 1 else Path(__file__).resolve().parents[1])
DATA = SOURCE_DIR / "data" / "zhenzhuzz_inconel718_carbide"
sys.path.insert(0, str(DATA))
import extract  # noqa: E402

FILES = ("cutting_tests.csv", "chip_thickness.csv", "johnson_cook.csv", "material_properties.csv",
         "klocke2013_cutting_tests.csv", "klocke2013_fig3_friction_as_plotted.csv")


def read_csv(name):
    lines = [l for l in (DATA / name).read_text().splitlines() if not l.startswith("#")]
    return list(csv.DictReader(io.StringIO("\n".join(lines))))


def f(row, key):
    return float(row[key]) if row[key] else None


class BedzraForcesAgainstTheText(unittest.TestCase):
    rows = read_csv("cutting_tests.csv")

    def force(self, radius, speed, key):
        for r in self.rows:
            if (f(r, "cutting_edge_radius[um]"), f(r, "cutting_speed[m/min]")) == (radius, speed):
                return f(r, key)
        self.fail(f"no row r_beta {radius} um, {speed} m/min")

    def test_nine_parameter_sets_of_the_plan_once(self):
        # Report Table 2-1 and "A total of nine sets of cutting operations": r_beta 10/20/30 um x 20/40/80 m/min,
        # every one at f = 0.05 mm.
        keys = sorted((f(r, "cutting_edge_radius[um]"), f(r, "cutting_speed[m/min]")) for r in self.rows)
        self.assertEqual(keys, sorted((r, v) for r in (10, 20, 30) for v in (20, 40, 80)))
        self.assertEqual({f(r, "uncut_chip_thickness[mm]") for r in self.rows}, {0.05})

    def test_the_report_tables_4_1_and_4_2(self):
        # Project_report docx, Tables 4-1 and 4-2 (r_beta = 10 um, its "Set 1, 2, 3").
        expected = {20: (269, 285.42, 235, 128.09), 40: (234, 259.83, 192, 113.06), 80: (232, 254.90, 181, 104.74)}
        for speed, (fc, fc_sim, ff, ff_sim) in expected.items():
            self.assertEqual(self.force(10, speed, "Fc_exp[N]"), fc)
            self.assertEqual(self.force(10, speed, "Fc_sim_bedzra[N]"), fc_sim)
            self.assertEqual(self.force(10, speed, "Ff_exp[N]"), ff)
            self.assertEqual(self.force(10, speed, "Ff_sim_bedzra[N]"), ff_sim)

    def test_largest_cutting_force_difference_is_11_percent_at_40_m_per_min(self):
        # "the simulated and experimental cutting forces are quite close, with the highest difference 11%
        # occurring at a cutting speed of 40 m/min" (r_beta = 10 um).
        gaps = {v: abs(self.force(10, v, "Fc_sim_bedzra[N]") - self.force(10, v, "Fc_exp[N]")) / self.force(10, v, "Fc_exp[N]")
                for v in (20, 40, 80)}
        self.assertEqual(max(gaps, key=gaps.get), 40)
        self.assertEqual(round(100 * gaps[40]), 11)

    def test_simulated_feed_forces_are_underestimated(self):
        # "The obtained simulation feed forces are underestimated compared by their corresponding experimental
        # results" (r_beta = 10 um); it holds at all nine conditions of the README's table 4.12 as well.
        for r in self.rows:
            self.assertLess(f(r, "Ff_sim_bedzra[N]"), f(r, "Ff_exp[N]"))

    def test_forces_fall_with_speed_at_10_um(self):
        # "by increasing cutting velocity, both cutting forces and feed forces in simulations and experiments
        # decrease" (r_beta = 10 um).
        for key in ("Fc_exp[N]", "Ff_exp[N]", "Fc_sim_bedzra[N]", "Ff_sim_bedzra[N]"):
            series = [self.force(10, v, key) for v in (20, 40, 80)]
            self.assertEqual(series, sorted(series, reverse=True), key)

    def test_cutting_force_falls_overall_and_feed_force_mostly_with_speed(self):
        # README: "三种刀具圆角下，切削速度升高 → 切削力总体下降" (cutting force falls overall with speed for
        # all three radii) and "多数情况下进给力随速度上升而降低" (the feed force falls with speed in most cases):
        # 80 m/min below 20 m/min at each radius; 5 of the 6 speed steps lower the feed force (not 20 um, 40 -> 80).
        for radius in (10, 20, 30):
            self.assertLess(self.force(radius, 80, "Fc_exp[N]"), self.force(radius, 20, "Fc_exp[N]"))
        falls = sum(self.force(r, b, "Ff_exp[N]") < self.force(r, a, "Ff_exp[N]")
                    for r in (10, 20, 30) for a, b in ((20, 40), (40, 80)))
        self.assertEqual(falls, 5)

    def test_feed_force_rises_with_the_edge_radius_at_every_speed(self):
        # Slides of 2023-06-21, p. 10: "三种切削速度下，随着刀具圆角增加，进给力反而增大" (at all three cutting
        # speeds the feed force rises with the edge radius).
        for speed in (20, 40, 80):
            series = [self.force(r, speed, "Ff_exp[N]") for r in (10, 20, 30)]
            self.assertEqual(series, sorted(series), speed)
            self.assertEqual(len(set(series)), 3)


class ChipThicknessAgainstTheText(unittest.TestCase):
    def test_table_4_3_and_its_trend(self):
        # Report Table 4-3 "Measured chip thickness": Exp 0.13 mm (40 m/min), 0.11 mm (80 m/min); slides p. 12:
        # "随着切削速度增加，切屑厚度减小" (the chip thins as the speed rises); the simulation's chips are thinner.
        rows = {f(r, "cutting_speed[m/min]"): r for r in read_csv("chip_thickness.csv")}
        self.assertEqual(sorted(rows), [40, 80])
        self.assertEqual((f(rows[40], "h_chip_exp[mm]"), f(rows[80], "h_chip_exp[mm]")), (0.13, 0.11))
        for r in rows.values():
            self.assertLess(f(r, "h_chip_sim_bedzra[mm]"), f(r, "h_chip_exp[mm]"))
            self.assertAlmostEqual(f(r, "chip_ratio_exp_derived[1]"), f(r, "h_chip_exp[mm]") / 0.05, places=9)


class JohnsonCookAgainstThePaper(unittest.TestCase):
    def test_the_set_klocke_et_al_identified(self):
        # Klocke, Lung, Buchkremer 2013: "A = 1485 MPa, B = 904, n = 0,777" and "m = 1,689; C = 0,015;
        # Dcrit = 97,8; p = 43,13 %"; README and report: reference strain rate 1e-3 1/s, T0 20 C, Tm 1297 C.
        rows = {r["parameter"]: r for r in read_csv("johnson_cook.csv")}
        expected = {"A": 1485, "B": 904, "n": 0.777, "C": 0.015, "m": 1.689, "reference_strain_rate": 1e-3,
                    "T0": 20, "Tm": 1297, "cockcroft_latham_D_crit": 97.8, "cockcroft_latham_p": 43.13,
                    "jc_damage_d2": 2.031, "jc_damage_d4": 0.014}
        self.assertEqual({k: f(rows[k], "value") for k in expected}, expected)
        for k in ("A", "B", "n", "C", "m"):
            self.assertEqual(float(rows[k]["klocke2013_text"]), expected[k], k)


class MaterialPropertiesAgainstTheReadme(unittest.TestCase):
    def test_the_readme_sentences(self):
        # README: cp 440 J/(kg C) rising to about 710 at 1200 C; conductivity 10 rising to about 31; expansion about
        # 13e-6 at 20 C and 15.8e-6 at 700 C; E 217 GPa at 20 C and 155.9 GPa at 871 C; tool conductivity 100
        # falling to 65, tool cp 200 rising to 260; densities 8.22e3 and 15.8e3 kg/m3.
        table = {(r["body"], r["property"], r["temperature[degC]"]): f(r, "value") for r in read_csv("material_properties.csv")}
        self.assertEqual(table[("workpiece", "specific_heat", "0")], 440)
        self.assertEqual(table[("workpiece", "specific_heat", "1200")], 710)
        self.assertEqual(table[("workpiece", "thermal_conductivity", "0")], 10)
        self.assertEqual(table[("workpiece", "thermal_conductivity", "1200")], 31)
        self.assertEqual(table[("workpiece", "thermal_expansion", "700")], 15.8)
        self.assertEqual(table[("workpiece", "youngs_modulus", "871")], 155.9)
        self.assertEqual(table[("tool", "thermal_conductivity", "0")], 100)
        self.assertEqual(table[("tool", "thermal_conductivity", "1200")], 65)
        self.assertEqual(table[("tool", "specific_heat", "1200")], 260)
        self.assertEqual(table[("workpiece", "density", "")], 8220)
        self.assertEqual(table[("tool", "density", "")], 15800)
        for body, prop, n in (("workpiece", "specific_heat", 13), ("workpiece", "thermal_conductivity", 13),
                              ("workpiece", "thermal_expansion", 15), ("tool", "specific_heat", 13)):
            self.assertEqual(sum(1 for k in table if k[:2] == (body, prop)), n)


class SceneMaterialPartAgainstTheData(unittest.TestCase):
    # scene_material.json (the micro-model's material for this pair, `mufric micro scene --with`) is
    # typed from johnson_cook.csv and material_properties.csv: the Johnson-Cook set, E and nu at 20 C,
    # the density, and the specific heat and conductivity at 600 C (README: the contact zone's).
    def test_every_value_is_the_datas(self):
        import json
        part = json.loads((DATA / "scene_material.json").read_text())
        material, thermal = part["material"], part["thermal"]
        jc = {r["parameter"]: f(r, "value") for r in read_csv("johnson_cook.csv")}
        table = {(r["body"], r["property"], r["temperature[degC]"]): f(r, "value") for r in read_csv("material_properties.csv")}
        self.assertEqual(material["a"], f"{jc['A']:g}MPa")
        self.assertEqual(material["b"], f"{jc['B']:g}MPa")
        self.assertEqual((material["n"], material["c"], material["m"]), (jc["n"], jc["C"], jc["m"]))
        self.assertEqual(material["reference_strain_rate"], jc["reference_strain_rate"])
        self.assertEqual(material["transition_temperature"], f"{jc['T0']:g}C")
        self.assertEqual(material["melting_temperature"], f"{jc['Tm']:g}C")
        self.assertEqual(material["youngs_modulus"], f"{table[('workpiece', 'youngs_modulus', '20')]:g}GPa")
        self.assertEqual(material["poisson_ratio"], table[("workpiece", "poissons_ratio", "20")])
        self.assertEqual(material["density"], table[("workpiece", "density", "")])
        self.assertEqual(material["specific_heat"], table[("workpiece", "specific_heat", "600")])
        self.assertEqual(thermal["conductivity"], table[("workpiece", "thermal_conductivity", "600")])


class KlockeFiguresAgainstTheText(unittest.TestCase):
    rows = read_csv("klocke2013_cutting_tests.csv")

    def test_the_conditions_of_table_1_and_fig_7(self):
        # Table 1 for Inconel 718: f 0.02 (20 m/min), 0.05 (5-40), 0.075 (10, 20, 40), 0.1 (20).
        keys = [(f(r, "cutting_speed[m/min]"), f(r, "uncut_chip_thickness[mm]")) for r in self.rows]
        self.assertEqual(keys, [(20, 0.02), (5, 0.05), (10, 0.05), (20, 0.05), (30, 0.05), (40, 0.05),
                                (10, 0.075), (20, 0.075), (40, 0.075), (20, 0.1)])
        self.assertEqual(sum(1 for r in self.rows if r["hmax_exp[mm]"]), 7)

    def test_average_error_of_the_forces_is_about_10_percent(self):
        # "The average error between the experimental and numerical data is ca. 10 %": over the 20 force bars of
        # Fig. 7 it is 12.7 % (cutting force 8.5 %, feed force 17.0 %), "ca. 10" to the nearest ten.
        errors = [abs(f(r, f"{q}_sim_klocke[N]") - f(r, f"{q}_exp[N]")) / f(r, f"{q}_exp[N]")
                  for r in self.rows for q in ("Fc", "Ff")]
        self.assertEqual(round(100 * sum(errors) / len(errors) / 10) * 10, 10)

    def test_cutting_force_rises_with_feed_at_20_m_per_min(self):
        series = [f(r, "Fc_exp[N]") for r in self.rows if f(r, "cutting_speed[m/min]") == 20]
        self.assertEqual(series, sorted(series))

    def test_fig_7_by_eye(self):
        # Page 5 rendered at 200 dpi (pdftoppm) and read by eye: at 10 m/min, f = 0.075 mm the black cutting-force
        # bar ends a little below the midpoint of the 1000 and 1500 gridlines, about 1150 N, its white bar about
        # 870 N; at 40 m/min, 0.075 mm the black feed-force bar is about 640 N, the white one about 870 N.
        r = next(r for r in self.rows if (f(r, "cutting_speed[m/min]"), f(r, "uncut_chip_thickness[mm]")) == (10, 0.075))
        self.assertAlmostEqual(f(r, "Fc_exp[N]"), 1150, delta=25)
        self.assertAlmostEqual(f(r, "Fc_sim_klocke[N]"), 870, delta=25)
        r = next(r for r in self.rows if (f(r, "cutting_speed[m/min]"), f(r, "uncut_chip_thickness[mm]")) == (40, 0.075))
        self.assertAlmostEqual(f(r, "Ff_exp[N]"), 640, delta=25)
        self.assertAlmostEqual(f(r, "Ff_sim_klocke[N]"), 870, delta=25)


class KlockeFrictionCurve(unittest.TestCase):
    rows = read_csv("klocke2013_fig3_friction_as_plotted.csv")

    def test_five_points_at_20_to_100_m_per_min_falling(self):
        # Fig. 3: the Inconel 718 series has five markers, at the category positions 20, 40, ... 100 m/min of an
        # axis labelled 0 ... 100; the curve falls with the relative velocity.
        speeds = [f(r, "relative_velocity[m/min]") for r in self.rows]
        for speed, expected in zip(speeds, (20, 40, 60, 80, 100)):
            self.assertAlmostEqual(speed, expected, delta=0.5)
        self.assertEqual(len(speeds), 5)
        mu = [f(r, "mu_coulomb") for r in self.rows]
        self.assertEqual(mu, sorted(mu, reverse=True))
        self.assertEqual(len(set(mu)), 5)

    def test_fig_3_by_eye(self):
        # Page 3 rendered at 200 dpi and read by eye: the square at 100 m/min sits about halfway between the 0.1
        # and 0.2 gridlines (about 0.15); the first one, at 20 m/min, a little above the 0.3 line.
        self.assertAlmostEqual(f(self.rows[-1], "mu_coulomb"), 0.15, delta=0.01)
        self.assertAlmostEqual(f(self.rows[0], "mu_coulomb"), 0.32, delta=0.015)


Q = extract.DEVICE_QUANTUM_PT


def grid(x):
    return round(x / Q) * Q


def synthetic_panel(values, ticks, title, axis_x=100.0, zero_y=400.0, height_pt=46.0):
    """A content stream drawing one bar panel of (exp, sim) pairs as the paper's Excel/Distiller figures do."""
    top = ticks[-1]
    scale = grid(height_pt) / top  # pt per unit
    out = [".52549 .52549 .52549 rg", f"{axis_x:.3f} {zero_y:.3f} .6624 {grid(height_pt):.3f} re", "f",
           f"q 1 0 0 1 {axis_x - 1.766:.3f} {zero_y + Q:.3f} cm 0 0 m"]
    for t in ticks:
        y = grid(t * scale)
        out.append(f"0 {y:.3f} m 0 {y:.3f} 1.9872 -.4416 re")
    out += ["f", "Q", f"{axis_x + 0.441:.3f} {zero_y - Q:.3f} {max(176.4, len(values) * 17.664):.3f} .4416 re", "f"]
    out += ["/GS2 gs", "BT", f"6.5832 0 0 6.5825 {axis_x - 9:.4f} {zero_y - 2.0:.4f} Tm", f"({ticks[0]:g})Tj"]
    for previous, t in zip(ticks, ticks[1:]):
        step = (grid(t * scale) - grid(previous * scale)) / 6.5825
        out += [f"0 {step:.4f} TD", "[(" + f"{t:g}".replace(".", ",") + ")]TJ"]
    out += [f"0 6.5825 -6.5832 0 {axis_x - 22:.3f} {zero_y - 5:.3f} Tm", f"[({title})]TJ", "ET"]
    first_top = grid(values[0][0] * scale)
    out += ["0 0 0 rg", f"q 1 0 0 1 {axis_x + 4:.3f} {zero_y + first_top:.3f} cm 0 0 m"]
    for k, (exp, _) in enumerate(values):
        h = grid(exp * scale)
        dy = h - first_top
        out.append(f"{17.664 * k:.3f} {dy:.3f} m {17.664 * k:.3f} {dy:.3f} 5.0784 {-h:.3f} re")
    out += ["f", "Q"]
    for k, (_, sim) in enumerate(values):
        out += ["1 1 1 rg", f"{axis_x + 9.08 + 17.664 * k:.3f} {zero_y:.3f} 4.8576 {grid(sim * scale):.3f} re", "f"]
    return "\n".join(out) + "\n", scale


class FigureReaderOnKnownValues(unittest.TestCase):
    ticks = [0.0, 400.0, 800.0, 1200.0]
    values = [(494.5, 614.2), (620.2, 584.3), (787.7, 602.2), (1100.0, 30.0)]

    def read(self, content):
        rects, texts = extract.parse_content(content)
        panels = extract.find_panels(rects, texts, [self.ticks])
        self.assertEqual(len(panels), 1)
        self.assertIn("FeedForce", panels[0]["title"].replace(" ", ""))
        return extract.read_panel(panels[0], list(range(len(self.values))), "synthetic")

    def test_bars_come_back_to_one_grid_step(self):
        content, scale = synthetic_panel(self.values, self.ticks, "Feed Force F")
        for (condition, exp, sim), (true_exp, true_sim) in zip(self.read(content), self.values):
            self.assertAlmostEqual(exp, true_exp, delta=Q / scale)
            self.assertAlmostEqual(sim, true_sim, delta=Q / scale)

    def test_a_bar_off_the_device_grid_is_refused(self):
        content, _ = synthetic_panel(self.values, self.ticks, "Feed Force F")
        lines = content.splitlines()
        k = next(i for i, l in enumerate(lines) if l.startswith("1 1 1 rg"))
        x, y, w, h = lines[k + 1].split()[:4]
        lines[k + 1] = f"{x} {y} {w} {float(h) + 0.1:.3f} re"
        with self.assertRaisesRegex(extract.ExtractionError, "not on the .* pt grid"):
            self.read("\n".join(lines) + "\n")

    def test_a_missing_simulation_bar_is_refused(self):
        content, _ = synthetic_panel(self.values, self.ticks, "Feed Force F")
        lines = content.splitlines()
        k = max(i for i, l in enumerate(lines) if l.startswith("1 1 1 rg"))
        with self.assertRaisesRegex(extract.ExtractionError, "4 black and 3 white bars"):
            self.read("\n".join(lines[:k] + lines[k + 3:]) + "\n")


class ReExtraction(unittest.TestCase):
    @unittest.skipUnless(os.environ.get("MUFRIC_INCONEL718_REPO"),
                         "no copy of zhenzhuzz/Inconel718-Cutting (MUFRIC_INCONEL718_REPO)")
    def test_the_committed_files_come_out_of_the_source_byte_for_byte(self):
        with tempfile.TemporaryDirectory() as folder:
            subprocess.run([sys.executable, str(DATA / "extract.py"), "--repo", os.environ["MUFRIC_INCONEL718_REPO"],
                            "--out-dir", folder], check=True, capture_output=True)
            for name in FILES:
                self.assertEqual((Path(folder) / name).read_text(), (DATA / name).read_text(), name)


if __name__ == "__main__":
    unittest.main(verbosity=2)
