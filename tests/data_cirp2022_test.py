#!/usr/bin/python3
"""The Ti6Al4V cutting data (data/cirp2022_ti6al4v_tin) against independent answers:
  1. the committed CSV against the sentences and the table of differences of the source's text
     (Article.tex at the cited commit), which were written from the authors' own numbers;
  2. the extraction method on a figure drawn here by matplotlib from known values (the same kind of
     figure: grouped bars with error bars, hatched narrower bars, rotated labels): exact recovery;
  3. one value of the source's figure against the value read by eye from its rendering;
  4. the shipped model's measurement file (rake_face_mu_calibration.csv) against the validation's rows;
  5. where a copy of the source repository is given (MUFRIC_CIRP_REPO), the extraction re-run from it
     gives the committed files byte for byte.
The rake-face analysis (forces to the rake face) is the library's, tested in tests/test_reduction.cpp.
Usage: data_cirp2022_test.py SOURCE_DIR"""
import csv
import io
import os
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

SOURCE_DIR = Path(sys.argv.pop(1) if len(sys.argv) > 1 else Path(__file__).resolve().parents[1])
DATA = SOURCE_DIR / "data" / "cirp2022_ti6al4v_tin"
sys.path.insert(0, str(DATA))
import extract  # noqa: E402


def read_csv(path):
    lines = [l for l in path.read_text().splitlines() if not l.startswith("#")]
    return list(csv.DictReader(io.StringIO("\n".join(lines))))


def number(row, key):
    return float(row[key]) if row[key] else None


# The figures' bars are drawn to 6 decimals of a point, so a difference computed from them may sit a
# hair's breadth on the other side of a printed rounding boundary (3.4999 printed as 4).
ROUNDING_SLACK_PERCENT = 0.01


def relative_difference_percent(rows, quantity, unit, inclination=None):
    values = []
    for r in rows:
        if inclination is not None and number(r, "inclination_angle[deg]") != inclination:
            continue
        sim, exp = number(r, f"{quantity}_sim[{unit}]"), number(r, f"{quantity}_exp_mean[{unit}]")
        if sim is not None:
            values.append(abs(sim - exp) / exp * 100)
    return values


class CommittedDataAgainstTheText(unittest.TestCase):
    rows = read_csv(DATA / "cutting_tests.csv")

    def row(self, inclination, speed, thickness):
        for r in self.rows:
            if (number(r, "inclination_angle[deg]"), number(r, "cutting_speed[m/min]"),
                    number(r, "uncut_chip_thickness[um]")) == (inclination, speed, thickness):
                return r
        self.fail(f"no row {inclination} deg, {speed} m/min, {thickness} um")

    def test_every_condition_of_the_design_once(self):
        keys = sorted((number(r, "inclination_angle[deg]"), number(r, "cutting_speed[m/min]"),
                       number(r, "uncut_chip_thickness[um]")) for r in self.rows)
        self.assertEqual(keys, sorted((i, v, h) for i in (0.0, 6.0) for v in extract.SPEEDS_M_PER_MIN
                                      for h in extract.THICKNESSES_UM))

    def test_feed_force_is_46_percent_of_the_cutting_force_at_6_deg_10_m_per_min_40_um(self):
        # "the average value of the feed force is 46 % of the average value of the cutting force"
        r = self.row(6, 10, 40)
        self.assertEqual(round(100 * number(r, "Ff_exp_mean[N]") / number(r, "Fc_exp_mean[N]")), 46)

    def test_simulated_feed_force_is_low_but_within_the_95_percent_interval_there(self):
        # "The numerical feed force is underestimated by the model, but is within the 95 % experimental
        # confidence interval."
        r = self.row(6, 10, 40)
        exp, half, sim = number(r, "Ff_exp_mean[N]"), number(r, "Ff_exp_2sd[N]"), number(r, "Ff_sim[N]")
        self.assertLess(sim, exp)
        self.assertLessEqual(exp - sim, half)

    def test_all_simulated_cutting_forces_within_95_and_35_of_36_within_68_percent(self):
        # "All numerical values are within 95 % confidence of the experiments (35 of the 36 conditions
        # are within 68 % confidence)": 2 sigma and 1 sigma of the error bars' 2 sigma.
        gaps = [(abs(number(r, "Fc_sim[N]") - number(r, "Fc_exp_mean[N]")), number(r, "Fc_exp_2sd[N]"))
                for r in self.rows]
        self.assertEqual(sum(g <= two_sigma for g, two_sigma in gaps), 36)
        self.assertEqual(sum(g <= two_sigma / 2 for g, two_sigma in gaps), 35)

    def test_the_table_of_differences_for_cutting_force_passive_force_and_chip_ratio(self):
        # Table tab:Synth, rounded to whole per cent as printed. (Its feed-force column, 38/40/39 %,
        # max 60, min 10, and its cutting-force max 10 and min 1 are not reproduced by the figures of
        # the cited commit: README.md says so.)
        mean = lambda xs: sum(xs) / len(xs)  # noqa: E731

        def assert_printed_as(value, printed):
            self.assertLessEqual(abs(value - printed), 0.5 + ROUNDING_SLACK_PERCENT, f"{value} printed as {printed}")

        assert_printed_as(mean(relative_difference_percent(self.rows, "Fc", "N", 0)), 3)
        assert_printed_as(mean(relative_difference_percent(self.rows, "Fc", "N", 6)), 4)
        assert_printed_as(mean(relative_difference_percent(self.rows, "Fc", "N")), 4)
        passive = relative_difference_percent(self.rows, "Fp", "N", 6)
        assert_printed_as(mean(passive), 26)
        assert_printed_as(max(passive), 29)
        ratio = relative_difference_percent(self.rows, "chip_ratio", "1")
        assert_printed_as(mean(relative_difference_percent(self.rows, "chip_ratio", "1", 0)), 14)
        assert_printed_as(mean(relative_difference_percent(self.rows, "chip_ratio", "1", 6)), 21)
        assert_printed_as(mean(ratio), 17)
        assert_printed_as(max(ratio), 38)
        assert_printed_as(min(ratio), 2)

    def test_passive_force_differences_are_about_5_newton_at_most(self):
        # "the average difference is 26 %, but it is small in absolute terms -- less than 5 N", a rounded
        # figure: the largest is 5.02 N (5 m/min, 80 um).
        gaps = [abs(number(r, "Fp_sim[N]") - number(r, "Fp_exp_mean[N]")) for r in self.rows if r["Fp_sim[N]"]]
        self.assertEqual(len(gaps), 18)
        self.assertEqual(round(max(gaps)), 5)

    def test_cutting_force_rises_with_thickness_and_the_6_deg_inclination_lowers_it(self):
        # "The increase in cutting force with uncut chip thickness is clearly observed ... Increasing the
        # inclination angle from 0 to 6 deg slightly reduces the cutting force"
        for inclination in (0.0, 6.0):
            for v in extract.SPEEDS_M_PER_MIN:
                forces = [number(self.row(inclination, v, h), "Fc_exp_mean[N]") for h in extract.THICKNESSES_UM]
                self.assertEqual(forces, sorted(forces))
        lowered = sum(number(self.row(6, v, h), "Fc_exp_mean[N]") < number(self.row(0, v, h), "Fc_exp_mean[N]")
                      for v in extract.SPEEDS_M_PER_MIN for h in extract.THICKNESSES_UM)
        self.assertGreaterEqual(lowered, 15)

    def test_the_tabulated_friction_coefficients(self):
        rows = read_csv(DATA / "tribometer_rech2013_as_tabulated.csv")
        self.assertEqual([(number(r, "cutting_speed[m/min]"), number(r, "mu")) for r in rows],
                         [(5, 0.24), (7.5, 0.22), (10, 0.21), (20, 0.19), (30, 0.18), (40, 0.17)])


class ExtractionRecoversAFigureOfKnownValues(unittest.TestCase):
    def test_a_matplotlib_figure_of_the_same_kind(self):
        import matplotlib
        matplotlib.use("pdf")
        import matplotlib.pyplot as plt
        speeds, thicknesses = extract.SPEEDS_M_PER_MIN, extract.THICKNESSES_UM
        truth = {}
        fig, ax = plt.subplots(figsize=(5.5, 3.6))
        width = 0.15
        for i, h in enumerate(thicknesses):
            for j, v in enumerate(speeds):
                x = i + (j - 2.5) * width
                mean = 60.0 + 1.37 * h - 0.91 * v + 0.123 * i * j
                half = 3.0 + 0.21 * v
                sim = mean * (0.9 + 0.01 * j)
                truth[(v, h)] = (mean, half, sim)
                ax.bar(x, mean, width, color=f"C{j}", edgecolor="k", zorder=2)
                ax.bar(x, sim, width * 0.4, color=f"C{j}", hatch="..", zorder=3)
                ax.errorbar(x, mean, yerr=half, color="k", capsize=5, elinewidth=0.75, zorder=4)
        ax.set_xticks([i + (j - 2.5) * width for i in range(3) for j in range(6)])
        ax.set_xticklabels([f"{v:g} m/min" for _ in thicknesses for v in speeds], rotation=90)
        for i, h in enumerate(thicknesses):
            ax.text(i, -70, f"{h:g}", ha="center", va="top")
        ax.set_ylabel("Cutting force (N)")
        ax.grid(axis="y", lw=0.3)
        with tempfile.TemporaryDirectory() as folder:
            path = Path(folder) / "figure.pdf"
            fig.savefig(path)
            table, label, ticks = extract.read_figure(path.read_bytes(), "synthetic")
        self.assertEqual(label, "Cutting force (N)")
        for key, (mean, half, sim) in truth.items():
            self.assertAlmostEqual(table[key]["mean"], mean, delta=1e-4 * mean)
            self.assertAlmostEqual(table[key]["half_width"], half, delta=1e-4 * mean)
            self.assertAlmostEqual(table[key]["sim"], sim, delta=1e-4 * mean)


class OneValueReadByEye(unittest.TestCase):
    def test_fx_0_at_5_m_per_min_and_80_um(self):
        # Figures/Fx_0.pdf rendered at 200 dpi (pdftoppm) and read by eye, 2026-12-01: the solid bar
        # tops just above the 175 N gridline (about 176 N); its error bar runs from about 163 N (just
        # above the 150-175 midpoint) to about 189 N.
        rows = CommittedDataAgainstTheText.rows
        r = next(r for r in rows if (number(r, "inclination_angle[deg]"), number(r, "cutting_speed[m/min]"),
                                     number(r, "uncut_chip_thickness[um]")) == (0, 5, 80))
        mean, half = number(r, "Fc_exp_mean[N]"), number(r, "Fc_exp_2sd[N]")
        self.assertAlmostEqual(mean, 176.0, delta=2.0)
        self.assertAlmostEqual(mean - half, 163.0, delta=2.0)
        self.assertAlmostEqual(mean + half, 189.0, delta=2.0)


class CalibrationMeasurements(unittest.TestCase):
    def test_the_shipped_models_measurement_file_is_what_the_validation_calibrates_on(self):
        # campaigns/ti6al4v_tin/train.sh calibrates on the committed file, which its model records by
        # path and hash; bench/studies/ti6al4v/ti6al4v_validation.py writes the rows it validates: the
        # two must agree.
        validation = SOURCE_DIR / "bench" / "studies" / "ti6al4v" / "ti6al4v_validation.py"
        with tempfile.TemporaryDirectory() as folder:
            written = Path(folder) / "rows.csv"
            subprocess.run([sys.executable, str(validation), "--write-measurements", str(written)], check=True,
                           capture_output=True)
            self.assertEqual(written.read_text(), (DATA / "rake_face_mu_calibration.csv").read_text())


class ReExtraction(unittest.TestCase):
    @unittest.skipUnless(os.environ.get("MUFRIC_CIRP_REPO"), "no copy of pantale/CIRP-2022-paper (MUFRIC_CIRP_REPO)")
    def test_the_committed_files_come_out_of_the_source_byte_for_byte(self):
        with tempfile.TemporaryDirectory() as folder:
            subprocess.run([sys.executable, str(DATA / "extract.py"), "--repo", os.environ["MUFRIC_CIRP_REPO"],
                            "--out-dir", folder], check=True, capture_output=True)
            for name in ("cutting_tests.csv", "tribometer_rech2013_as_tabulated.csv"):
                self.assertEqual((Path(folder) / name).read_text(), (DATA / name).read_text(), name)


if __name__ == "__main__":
    unittest.main(verbosity=2)
