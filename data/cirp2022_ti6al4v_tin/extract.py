#!/usr/bin/python3
"""Reads the measured (and the paper's simulated) cutting forces and chip thickness ratios of
Ducobu, Pantale & Lauwers (repository pantale/CIRP-2022-paper) out of the vector figures'
drawing operators, and writes cutting_tests.csv; reads the friction coefficients the paper's FE model
used (its Table tab:fricHeat, attributed there to Rech et al. 2013) out of Article.tex, and writes
tribometer_rech2013_as_tabulated.csv.

Method (no pixels): each figure is a one-page matplotlib PDF. Its content stream (FlateDecode) draws
  - every measured mean as a filled-and-stroked rectangle ('B') standing on the axis,
  - every simulated value as a narrower rectangle filled with a hatch pattern ('/Pattern cs ... f'),
  - every error bar as a vertical stroked segment centred on its bar (the text: "The average and
    standard deviation (2 sigma) are calculated from the 3 experimental values"),
  - every y tick as a 3.5 pt mark left of the axis followed by its label,
  - every bar's cutting-speed label as a rotated text below it, every group's uncut chip thickness
    as an upright text below the group.
The y axis is the least-squares line through the (tick position, tick label) pairs; its largest
residual is checked (the axis is linear to the stream's 6 decimals). A bar is assigned to the
nearest speed label and the nearest thickness label. A bar's error bar must be centred on the
bar's top (checked), so mean and half-width both come from the stream.

Usage:
  extract.py --repo /path/to/CIRP-2022-paper[.git] [--commit SHA] [--out-dir DIR]
  extract.py --figures DIR        (a folder holding Fx_0.pdf ... h6.pdf and Article.tex; no commit check)
"""
import argparse
import math
import re
import subprocess
import sys
import zlib
from pathlib import Path

REPOSITORY = "pantale/CIRP-2022-paper"
COMMIT = "0d1f9017d5089b734567cf86066429b633951d95"

# (figure stem, quantity column, inclination angle lambda_s in degrees)
FIGURES = [
    ("Fx_0", "Fc", 0), ("Fy_0", "Ff", 0), ("h0", "chip_ratio", 0),
    ("Fx_6", "Fc", 6), ("Fy_6", "Ff", 6), ("Fz_6", "Fp", 6), ("h6", "chip_ratio", 6),
]
# What each figure's y-axis label must say (a check that the file is the figure we think it is).
AXIS_LABELS = {"Fc": "Cutting force (N)", "Ff": "Feed force (N)", "Fp": "Passive force (N)",
               "chip_ratio": "Chip thickness ratio"}
SPEEDS_M_PER_MIN = [5.0, 7.5, 10.0, 20.0, 30.0, 40.0]
THICKNESSES_UM = [40.0, 60.0, 80.0]

# Tolerances in PDF points (1/72 in); the stream prints 6 decimals.
AXIS_LINEARITY_TOLERANCE_PT = 1e-4
ERROR_BAR_CENTRE_TOLERANCE_PT = 1e-4
BASELINE_TOLERANCE_PT = 1e-4
# A tick label's baseline sits about 3.4 pt below its tick (10 pt font); labels are >= 15 pt apart.
LABEL_MATCH_TOLERANCE_PT = 3.0


class ExtractionError(RuntimeError):
    pass


def page_content(pdf_bytes, name):
    """The decompressed content stream of the PDF's single page."""
    page = re.search(rb"/Contents (\d+) 0 R", pdf_bytes)
    if not page:
        raise ExtractionError(f"{name}: no page /Contents")
    obj = re.search(rb"\n" + page.group(1) + rb" 0 obj\n<<([^>]*)>>\nstream\r?\n", pdf_bytes)
    if not obj or b"/FlateDecode" not in obj.group(1):
        raise ExtractionError(f"{name}: the page content is not a FlateDecode stream")
    end = pdf_bytes.find(b"endstream", obj.end())
    return zlib.decompress(pdf_bytes[obj.end():end]).decode("latin-1")


TOKEN = re.compile(r"\((?:\\.|[^\\)])*\)|/[^\s/\[\]()<>]+|\[|\]|[^\s()\[\]/]+")


def unescape(pdf_string):
    body = pdf_string[1:-1]
    return re.sub(r"\\(.)", r"\1", body)


def multiply(m, n):
    """The PDF product m x n of two affine matrices [a b c d e f] (m applied first)."""
    a, b, c, d, e, f = m
    A, B, C, D, E, F = n
    return [a * A + b * C, a * B + b * D, c * A + d * C, c * B + d * D, e * A + f * C + E, e * B + f * D + F]


IDENTITY = [1.0, 0.0, 0.0, 1.0, 0.0, 0.0]


def parse(content):
    """Walks the operators and returns the painted paths and the placed texts.

    A path is (points, painting operator, filled with a pattern?, stroke width), in the page's
    coordinates (matplotlib draws paths untransformed); a text is (string, x, y, rotated by 90 deg?),
    its origin through the text matrix and the current transformation (matplotlib versions place and
    rotate a label with either)."""
    paths, texts = [], []
    operands, points = [], []
    pattern_fill, line_width, ctm = False, 1.0, IDENTITY
    state_stack = []
    text_matrix, line_matrix = IDENTITY, IDENTITY
    for token in TOKEN.findall(content):
        if token[0] in "(/[]" or re.fullmatch(r"[-+]?[0-9.]+", token):
            operands.append(token)
            continue
        op = token
        numbers = lambda k: [float(o) for o in operands[-k:]]  # noqa: E731
        if op == "q":
            state_stack.append((pattern_fill, line_width, ctm))
        elif op == "Q":
            pattern_fill, line_width, ctm = state_stack.pop()
        elif op == "cm":
            ctm = multiply(numbers(6), ctm)
        elif op == "w":
            line_width = float(operands[-1])
        elif op in ("rg", "g"):
            pattern_fill = False
        elif op == "scn" and any(o.startswith("/H") for o in operands):
            pattern_fill = True
        elif op == "m":
            points = [tuple(numbers(2))]
        elif op == "l":
            points.append(tuple(numbers(2)))
        elif op == "c":
            points.append(None)  # a curve: never a bar, tick or error bar
        elif op in ("S", "f", "B") and points:
            paths.append((points, op, pattern_fill, line_width))
            points = []
        elif op == "n":
            points = []
        elif op == "BT":
            text_matrix = line_matrix = IDENTITY
        elif op == "Td":
            line_matrix = multiply([1.0, 0.0, 0.0, 1.0] + numbers(2), line_matrix)
            text_matrix = line_matrix
        elif op == "Tm":
            text_matrix = line_matrix = numbers(6)
        elif op in ("Tj", "TJ"):
            strings = [o for o in operands if o.startswith("(")]
            placed = multiply(text_matrix, ctm)
            rotated = abs(placed[0]) < 1e-9 and placed[1] > 0
            texts.append(("".join(unescape(t) for t in strings), placed[4], placed[5], rotated))
        operands = []
    return paths, texts


def rectangle(points):
    """(x0, x1, y0, y1) of an axis-aligned closed 4-point path, else None."""
    if len(points) != 4 or None in points:
        return None
    xs = sorted({round(p[0], 6) for p in points})
    ys = sorted({round(p[1], 6) for p in points})
    if len(xs) != 2 or len(ys) != 2:
        return None
    return xs[0], xs[1], ys[0], ys[1]


def y_axis(paths, texts):
    """Least-squares value = a + b*y through the y ticks; returns (a, b, axis x, baseline y)."""
    ticks = []
    for points, op, _, _ in paths:
        if len(points) == 2 and None not in points and points[0][1] == points[1][1]:
            x_axis, x_out = points[0][0], points[1][0]
            if 3.0 < x_axis - x_out < 4.0:  # matplotlib's 3.5 pt outward tick mark
                ticks.append((x_axis, points[0][1]))
    labels = [(t, x, y) for t, x, y, rot in texts if not rot and re.fullmatch(r"-?[0-9.]+", t)]
    pairs = []
    for x_axis, y_tick in ticks:
        # matplotlib places a tick label left of its tick, its baseline 3.4 pt below the tick.
        near = [(abs(y - (y_tick - 3.4)), t) for t, x, y in labels if x < x_axis]
        if not near:
            raise ExtractionError(f"y tick at {y_tick} pt has no label")
        distance, label = min(near)
        if distance > LABEL_MATCH_TOLERANCE_PT:
            raise ExtractionError(f"y tick at {y_tick} pt has no label")
        pairs.append((y_tick, float(label)))
    if len(pairs) < 3:
        raise ExtractionError("fewer than 3 labelled y ticks")
    n = len(pairs)
    mean_y = sum(p[0] for p in pairs) / n
    mean_v = sum(p[1] for p in pairs) / n
    slope = sum((p[0] - mean_y) * (p[1] - mean_v) for p in pairs) / sum((p[0] - mean_y) ** 2 for p in pairs)
    intercept = mean_v - slope * mean_y
    worst_pt = max(abs((p[1] - intercept) / slope - p[0]) for p in pairs)
    if worst_pt > AXIS_LINEARITY_TOLERANCE_PT:
        raise ExtractionError(f"y ticks are not on one line (worst {worst_pt:.2e} pt)")
    baseline = (0.0 - intercept) / slope
    return intercept, slope, ticks[0][0], baseline, pairs


def read_figure(pdf_bytes, name):
    """Returns {(speed, thickness): {"mean", "half_width", "sim"}} and the axis label."""
    paths, texts = parse(page_content(pdf_bytes, name))
    intercept, slope, axis_x, baseline, ticks = y_axis(paths, texts)
    value = lambda y: intercept + slope * y  # noqa: E731

    axis_label = next((t for t, x, y, rot in texts if rot and x < axis_x - 10 and not t.endswith("m/min")), None)
    speed_labels = []
    for t, x, y, rot in texts:
        if rot and t.endswith(" m/min"):
            speed_labels.append((x, float(t.split()[0])))
    thickness_labels = [(x + 5.0, float(t)) for t, x, y, rot in texts  # "40": two 5 pt digits
                        if not rot and re.fullmatch(r"[0-9]+", t) and x > axis_x and y < baseline]

    def nearest(labels, x):
        return min(labels, key=lambda l: abs(l[0] - x))[1]

    measured, simulated, error_bars = {}, {}, {}
    for points, op, pattern, width in paths:
        box = rectangle(points)
        if box and op in ("B", "f") and abs(box[2] - baseline) < BASELINE_TOLERANCE_PT and box[0] > axis_x:
            centre = 0.5 * (box[0] + box[1])
            # A rotated label's anchor sits 2.68 pt right of the bar centre it is centred on.
            key = (nearest(speed_labels, centre + 2.68), nearest(thickness_labels, centre))
            if op == "B" and not pattern:
                measured.setdefault(key, []).append((centre, value(box[3])))
            elif op == "f" and pattern:
                simulated.setdefault(key, []).append((centre, value(box[3])))
        elif (op == "S" and len(points) == 2 and None not in points and points[0][0] == points[1][0]
              and points[0][0] > axis_x and abs(width - 0.75) < 1e-9):
            x = points[0][0]
            lo, hi = sorted((points[0][1], points[1][1]))
            error_bars.setdefault(round(x, 4), []).append((lo, hi))

    table = {}
    for key, bars in measured.items():
        if len(bars) != 1:
            raise ExtractionError(f"{name}: {len(bars)} measured bars at {key}")
        centre, mean = bars[0]
        bar_list = error_bars.get(round(centre, 4))
        if not bar_list or len(bar_list) != 1:
            raise ExtractionError(f"{name}: no single error bar on the measured bar at {key}")
        lo, hi = bar_list[0]
        mid = value(0.5 * (lo + hi))
        if abs(0.5 * (lo + hi) - (mean - intercept) / slope) > ERROR_BAR_CENTRE_TOLERANCE_PT:
            raise ExtractionError(f"{name}: the error bar at {key} is not centred on its bar ({mid} vs {mean})")
        sim = simulated.get(key)
        if not sim or len(sim) != 1:
            raise ExtractionError(f"{name}: no single simulated bar at {key}")
        table[key] = {"mean": mean, "half_width": 0.5 * slope * (hi - lo), "sim": sim[0][1]}
    expected = {(v, h) for v in SPEEDS_M_PER_MIN for h in THICKNESSES_UM}
    if set(table) != expected:
        raise ExtractionError(f"{name}: conditions found {sorted(table)} differ from the 18 expected")
    return table, axis_label, ticks


def source_bytes(args, path):
    """A file of the repository at the commit (or of the --figures folder)."""
    if args.figures:
        return (Path(args.figures) / Path(path).name).read_bytes()
    return subprocess.run(["git", "-C", args.repo, "show", f"{args.commit}:{path}"],
                          check=True, capture_output=True).stdout


def read_friction_table(tex):
    """Rows (cutting speed m/min, mu, beta) of the LaTeX table labelled tab:fricHeat."""
    start = tex.find(r"\label{tab:fricHeat}")
    if start < 0:
        raise ExtractionError("Article.tex: no table labelled tab:fricHeat")
    body = tex[start:tex.find(r"\end{tabular}", start)]
    rows = []
    for line in body.splitlines():
        cells = [c.strip() for c in line.rstrip("\\ ").split("&")]
        if len(cells) == 3 and all(re.fullmatch(r"[0-9.]+", c) for c in cells):
            rows.append(tuple(float(c) for c in cells))
    if [r[0] for r in rows] != SPEEDS_M_PER_MIN:
        raise ExtractionError(f"Article.tex: tab:fricHeat rows {rows} are not the 6 cutting speeds")
    return rows


def write_friction_table(rows, commit, out):
    lines = [
        "# Friction coefficient mu and heat partition beta against cutting speed, as tabulated in the FE model of",
        "# F. Ducobu, O. Pantale, B. Lauwers (Article.tex, Table tab:fricHeat 'Friction and heat transfer coefficients').",
        "# The text attributes mu and beta to the open-tribometer results of Rech, Arrazola, Claudin, Courbon, Pusavec &",
        "# Kopac 2013, 'Characterisation of friction and heat partition coefficients at the tool-work material interface",
        "# in cutting', CIRP Annals 62(1):79-82, doi:10.1016/j.cirp.2013.03.099 (the table also cites GRANTA 2020 and",
        "# Stampfer et al. 2021 for its heat-transfer rows). Rech et al. 2013 itself could not be read here: whether it",
        "# lists these values, for which pair and at which contact pressure, is not checked. These are values TABULATED",
        "# BY THAT SOURCE, not measurements read from Rech et al. The key is the cutting speed of the cut the FE model",
        "# simulated; the tribometer's sliding velocity behind each value is not stated. No uncertainty is given.",
        "# Used in the paper as Coulomb friction with a limiting shear stress of 576 MPa (A/sqrt(3)).",
        f"# Repository: https://github.com/{REPOSITORY} commit {commit}, file Article.tex",
        "# How read: table (LaTeX source), by data/cirp2022_ti6al4v_tin/extract.py.",
        "cutting_speed[m/min],mu,heat_partition_beta",
    ]
    lines += [f"{significant(v)},{significant(mu)},{significant(beta)}" for v, mu, beta in rows]
    Path(out).write_text("\n".join(lines) + "\n")


def significant(x, digits=7):
    return f"{x:.{digits}g}"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--repo", help="a clone (or bare git directory) of " + REPOSITORY)
    source.add_argument("--figures", help="a folder with the seven figure PDFs (no commit check)")
    parser.add_argument("--commit", default=COMMIT)
    parser.add_argument("--out-dir", default=str(Path(__file__).parent))
    args = parser.parse_args()

    rows = {}
    for stem, quantity, inclination in FIGURES:
        try:
            table, axis_label, _ = read_figure(source_bytes(args, f"Figures/{stem}.pdf"), stem)
        except (ExtractionError, subprocess.CalledProcessError, OSError) as error:
            sys.exit(f"extract: {stem}.pdf: {error}")
        if axis_label != AXIS_LABELS[quantity]:
            sys.exit(f"extract: {stem}.pdf: y axis says '{axis_label}', expected '{AXIS_LABELS[quantity]}'")
        for (speed, thickness), v in table.items():
            row = rows.setdefault((inclination, speed, thickness), {})
            row[quantity] = v
            row.setdefault("files", []).append(f"Figures/{stem}.pdf")

    quantities = [("Fc", "N"), ("Ff", "N"), ("Fp", "N"), ("chip_ratio", "1")]
    header = ["inclination_angle[deg]", "cutting_speed[m/min]", "uncut_chip_thickness[um]"]
    for q, unit in quantities:
        header += [f"{q}_exp_mean[{unit}]", f"{q}_exp_2sd[{unit}]"]
    for q, unit in quantities:
        header += [f"{q}_sim[{unit}]"]
    header += ["figures"]
    commit = args.commit if args.repo else "unknown (read from --figures)"
    lines = [
        "# Dry orthogonal (lambda_s = 0 deg) and oblique (lambda_s = 6 deg) cutting of Ti6Al4V (grade 5, annealed 750 C 1 h,",
        "# air cooled) with a TiN-coated carbide tool (SECO CP500, modified LCGN160602-0600-FG): rake 15 deg, clearance",
        "# 2 deg, edge radius 20 um, rib (cut) width 1 mm; forces from a Kistler 9257B, means of the steady state over",
        "# 3 repeats; chip thickness measured 3 times along each chip (Dino Lite microscope).",
        "# Source: F. Ducobu, O. Pantale, B. Lauwers, 'Predictive 3D modelling of free oblique cutting introducing an",
        "# ANN-based material flow law with experimental validation over a wide range of conditions' (LaTeX source",
        "# Article.tex). Publication status and journal: not known (the repository's README says 'to be submitted in",
        "# CIRP Journal of Manufacturing Science and Technology'; its history records a submission to EAAI, a",
        "# rejection and a revision for reviewers in December 2023). See README.md.",
        f"# Repository: https://github.com/{REPOSITORY} commit {commit}",
        "# Files: Figures/Fx_0.pdf Fy_0.pdf h0.pdf Fx_6.pdf Fy_6.pdf Fz_6.pdf h6.pdf",
        "# How read: vector figure - every value from the page's drawing operators (bar tops, error-bar ends, the axis",
        "# from its tick marks and labels), by data/cirp2022_ti6al4v_tin/extract.py; no pixel was read.",
        "# *_exp_mean: the measured mean (solid bar); *_exp_2sd: the error bar's half-width, which the text calls the",
        "# standard deviation (2 sigma) of the 3 repeats; *_sim: the paper's own 3D CEL FE model (hatched bar), NOT a",
        "# measurement. Fp is not drawn for lambda_s = 0 (zero by symmetry): empty cells. Values to 7 significant digits.",
        ",".join(header),
    ]
    for key in sorted(rows):
        row = rows[key]
        cells = [significant(key[0]), significant(key[1]), significant(key[2])]
        for q, _ in quantities:
            cells += [significant(row[q]["mean"]), significant(row[q]["half_width"])] if q in row else ["", ""]
        for q, _ in quantities:
            cells += [significant(row[q]["sim"])] if q in row else [""]
        cells.append(" ".join(row["files"]))
        lines.append(",".join(cells))
    out_dir = Path(args.out_dir)
    (out_dir / "cutting_tests.csv").write_text("\n".join(lines) + "\n")
    try:
        friction = read_friction_table(source_bytes(args, "Article.tex").decode("utf-8"))
    except (ExtractionError, subprocess.CalledProcessError, OSError) as error:
        sys.exit(f"extract: Article.tex: {error}")
    write_friction_table(friction, commit, out_dir / "tribometer_rech2013_as_tabulated.csv")
    print(f"extract: {len(rows)} cutting conditions and {len(friction)} tabulated friction rows written to {out_dir}")


if __name__ == "__main__":
    main()
