#!/usr/bin/python3
"""Reads the Inconel 718 orthogonal-cutting data held in the public repository zhenzhuzz/Inconel718-Cutting
(a student's course project, 2023, README rewritten 2025) at a pinned commit, and writes the CSVs of
data/zhenzhuzz_inconel718_carbide/.

What is read, and how (no pixel is read anywhere):
  README.md (markdown tables and text)
    - "表 4.11" / "表 4.12": measured (Exp) and the thesis's FE-simulated (Sim) cutting and feed forces,
      3 cutting-edge radii x 3 cutting speeds; the source of the measurements is R. Bedzra's thesis
      (RWTH Aachen, WZL, 2013), which is not in the repository snapshot (its Master_thesis.pdf is absent);
    - the Johnson-Cook set (A, B, n, C, m, reference strain rate, T0, Tm) and the workpiece density.
  01_Abaqus_FEM_ThermalMechanical_Cutting/Project_report_*.docx (Word XML: tables and sentences)
    - Table 2-1 (the experimental plan), the sentences on tool, feed, repeats and workpiece;
    - Tables 3-4 ... 3-12 (thermal and elastic properties, Johnson-Cook and damage constants, tool data);
    - Tables 4-1, 4-2 (the same forces as README for r_beta = 10 um: checked equal), 4-3 (chip thickness).
  01_Abaqus_FEM_ThermalMechanical_Cutting/Reference/Inverse identification ... .pdf (Klocke, Lung,
    Buchkremer 2013, Procedia CIRP 8:212, same laboratory and machine)
    - its text (the Johnson-Cook constants it identified: the README's set comes from it);
    - its Fig. 7 (cutting and feed force, 10 conditions) and Fig. 9 (maximum chip thickness and
      serration ratio, 7 conditions) from the page's drawing operators (vector figure);
    - its Fig. 3 (the Coulomb friction coefficient against relative velocity implemented in its FE model
      for uncoated carbide on Inconel 718, attributed to Puls et al. 2012), the same way.

Usage:
  extract.py --repo /path/to/Inconel718-Cutting[.git] [--commit SHA] [--out-dir DIR]
"""
import argparse
import io
import re
import subprocess
import sys
import zipfile
import zlib
from pathlib import Path

REPOSITORY = "zhenzhuzz/Inconel718-Cutting"
COMMIT = "ab957ae251a75e898dacfe2dbb929fe2684f9706"
README = "README.md"
REPORT_DOCX = "01_Abaqus_FEM_ThermalMechanical_Cutting/Project_report_\u6731\u9547_2022214656.docx"
KLOCKE_PDF = ("01_Abaqus_FEM_ThermalMechanical_Cutting/Reference/Inverse identification of the constitutive "
              "equations of in 718 and aisi 1045 from fe machining simulations.pdf")

RADII_UM = [10, 20, 30]
SPEEDS_M_PER_MIN = [20, 40, 80]

# Klocke et al. 2013, the conditions under the bars, left to right, as the figures' tables print them.
FIG7_CONDITIONS = [(20, "0,02"), (5, "0,05"), (10, "0,05"), (20, "0,05"), (30, "0,05"), (40, "0,05"),
                   (10, "0,075"), (20, "0,075"), (40, "0,075"), (20, "0,1")]
FIG9_CONDITIONS = [(20, "0,02"), (5, "0,05"), (10, "0,05"), (20, "0,05"), (30, "0,05"), (40, "0,05"), (20, "0,1")]
# Each panel is recognised by its tick labels, and its axis title must contain the words given.
PANELS = {
    "Fc": ([0, 500, 1000, 1500], "Cutting Force"),
    "Ff": ([0, 400, 800, 1200], "Feed Force"),
    "hmax": ([0, 0.1, 0.2, 0.3], "Thcikness"),  # sic, the figure's own spelling
    "serration": ([0, 0.5, 1.0, 1.5, 2.0, 2.5], "Serration Ratio"),
}
# The figures are drawn on a device grid of about 0.2208 pt (1/326 in): every coordinate is rounded to it.
DEVICE_QUANTUM_PT = 0.2208
TICK_RESIDUAL_TOLERANCE_PT = 0.25  # ticks on one line to about one quantum
BAR_BASE_TOLERANCE_PT = 0.35       # a bar's foot on the axis zero to about 1.5 quanta
LABEL_OFFSET_SPREAD_PT = 0.5       # tick label baselines at one offset from their ticks (+-1 grid step)


class ExtractionError(RuntimeError):
    pass


# ------------------------------------------------------------------------------------------------ git

def git_show(repo, commit, path):
    return subprocess.run(["git", "-C", repo, "show", f"{commit}:{path}"], check=True, capture_output=True).stdout


# ------------------------------------------------------------------------------------------- README.md

def number(text):
    return float(text.replace(",", "."))


def markdown_table_after(text, marker):
    """The first markdown table after the line containing marker, as lists of cell strings."""
    start = text.find(marker)
    if start < 0:
        raise ExtractionError(f"README.md: no '{marker}'")
    rows = []
    for line in text[start:].splitlines()[1:]:
        if line.startswith("|"):
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if not all(re.fullmatch(r":?-+:?", c) for c in cells):
                rows.append(cells)
        elif rows:
            break
    if not rows:
        raise ExtractionError(f"README.md: no table after '{marker}'")
    return rows


def read_force_table(text, marker, symbol):
    """{(radius, speed): (exp, sim)} from README's table 4.11 (symbol 'F_c') or 4.12 ('F_f')."""
    header, *body = markdown_table_after(text, marker)
    columns = []
    for cell in header[1:]:
        m = re.fullmatch(r"\$" + symbol + r"\^\{\\text\{(exp|sim)\}\}\$ @(\d+) \(N\)", cell)
        if not m:
            raise ExtractionError(f"README.md {marker}: unexpected column '{cell}'")
        columns.append((m.group(1), int(m.group(2))))
    if sorted(columns) != sorted((k, v) for k in ("exp", "sim") for v in SPEEDS_M_PER_MIN):
        raise ExtractionError(f"README.md {marker}: columns {columns}")
    if not header[0].startswith("$r_\\beta$ (\u03bcm)"):
        raise ExtractionError(f"README.md {marker}: first column '{header[0]}'")
    table = {}
    for row in body:
        radius = int(row[0])
        for (kind, speed), cell in zip(columns, row[1:]):
            table.setdefault((radius, speed), {})[kind] = (number(cell), cell)
    if sorted(table) != sorted((r, v) for r in RADII_UM for v in SPEEDS_M_PER_MIN):
        raise ExtractionError(f"README.md {marker}: conditions {sorted(table)}")
    return table


def read_readme(text):
    fc = read_force_table(text, "\u8868 4.11", "F_c")
    ff = read_force_table(text, "\u8868 4.12", "F_f")
    # The three-way table (experiment / thesis simulation / student's simulation) repeats r_beta = 10 um.
    three_way = markdown_table_after(text, "\u4e09\u5411\u5bf9\u7167")
    heads = three_way[0][1:]
    for row, table in ((three_way[1], fc), (three_way[2], ff)):
        for head, cell in zip(heads, row[1:]):
            speed, kind = head.split("-")
            if kind in ("Exp", "Sim") and table[(10, int(speed))][kind.lower()][0] != number(cell):
                raise ExtractionError(f"README.md: three-way table {head} = {cell} differs from table 4.11/4.12")
    m = re.search(r"A=([0-9.]+)\\ \\mathrm\{MPa\}, B=([0-9.]+)\\ \\mathrm\{MPa\}, n=([0-9.]+), C=([0-9.]+), m=([0-9.]+)", text)
    if not m:
        raise ExtractionError("README.md: no Johnson-Cook line")
    jc = dict(zip(("A", "B", "n", "C", "m"), m.groups()))
    m = re.search(r"\\dot\{\\varepsilon\}_0 = 10\^\{(-?\d+)\}\\ \\mathrm\{s\^\{-1\}\}, T_0 = (\d+)\\ \\mathrm\{\u00b0C\}, "
                  r"T_m = (\d+)\\ \\mathrm\{\u00b0C\}", text)
    if not m:
        raise ExtractionError("README.md: no reference strain rate / temperatures line")
    jc.update({"reference_strain_rate": f"1e{m.group(1)}", "T0": m.group(2), "Tm": m.group(3)})
    m = re.search(r"\\rho = ([0-9.]+) \\times 10\^(\d)\s*\\ \\mathrm\{kg/m\^3\}", text)
    if not m:
        raise ExtractionError("README.md: no workpiece density")
    density = float(m.group(1)) * 10 ** int(m.group(2))
    if "Rinaldi" not in text or "Bedzra R." not in text:
        raise ExtractionError("README.md: the reference list has changed")
    return fc, ff, jc, density


# ---------------------------------------------------------------------------------------------- docx

def docx_items(docx_bytes):
    """The body's top-level paragraphs (strings) and tables (lists of rows of cell strings), in order."""
    xml = zipfile.ZipFile(io.BytesIO(docx_bytes)).read("word/document.xml").decode("utf-8")
    text_of = lambda fragment: "".join(re.findall(r"<w:t[^>]*>([^<]*)</w:t>", fragment))  # noqa: E731
    items, depth, table_start = [], 0, 0
    for m in re.finditer(r"<w:tbl>|</w:tbl>|<w:p[ >].*?</w:p>", xml, flags=re.S):
        tag = m.group(0)
        if tag == "<w:tbl>":
            depth += 1
            if depth == 1:
                table_start = m.start()
        elif tag == "</w:tbl>":
            depth -= 1
            if depth == 0:
                table = xml[table_start:m.end()]
                rows = [[text_of(c) for c in re.findall(r"<w:tc>.*?</w:tc>", r, flags=re.S)]
                        for r in re.findall(r"<w:tr[ >].*?</w:tr>", table, flags=re.S)]
                items.append(("table", rows))
        elif depth == 0:
            items.append(("paragraph", text_of(tag)))
    return items


def docx_tables(items):
    """{'Table 4-3': rows}: each table keyed by the caption of the last paragraph before it."""
    tables, caption = {}, None
    for kind, value in items:
        if kind == "paragraph" and value.strip():
            m = re.match(r"Table (\d+-\d+)", value.strip())
            caption = f"Table {m.group(1)}" if m else None
        elif kind == "table" and caption:
            tables[caption] = value
            caption = None
    return tables


REPORT_SENTENCES = {
    "tool": r"The cutting tools used in the test were uncoated carbide grade inserts \(H13A\)",
    "geometry": r"All tool rake angles were (\d+)\u00b0, all tool flank angles were (\d+)\u00b0 and the cutting edge "
                r"radii were r\u03b2 = (\d+) \u00b5m, (\d+) \u00b5m and (\d+) \u00b5m",
    "speeds_feed": r"the cutting velocities were Vc = (\d+) m/min, (\d+) m/min and (\d+) m/min and the feed was "
                   r"f = ([0-9.]+) mm",
    "repeats": r"each parameter set\S+ cutting test was repeated three times",
    "dry": r"A coolant was not used during any of the experiments",
    "workpiece": r"Inconel 718 measures 100 mm in length, 50 mm in width, and 3\.5 mm in thickness",
    "lab": r"orthogonal cutting tests were conducted at the Werkzeugmaschinenlabor \(WZL\) at RWTH Aachen University",
    "machine": r"Forst RASX 8x2200x600M/CNC",
    "sets_1_3": r"only three cutting operations \(Set 1, 2, 3\) in Table 2-1 were carried out",
    "forces_11_percent": r"with the highest difference 11% occurring at a cutting speed of 40 m/min",
    "feed_underestimated": r"The obtained simulation feed forces are underestimated",
    "chip_similar": r"The chip thicknesses are similar under different cutting speeds",
    "jc_source": r"the coefficients identified by Klocke et al\.\[3\] are adopted",
}


def row_numbers(row):
    return [number(c) for c in row[1:]]


def read_report(docx_bytes):
    items = docx_items(docx_bytes)
    text = " ".join(v for k, v in items if k == "paragraph")
    found = {}
    for key, pattern in REPORT_SENTENCES.items():
        m = re.search(pattern, text)
        if not m:
            raise ExtractionError(f"report docx: the sentence '{key}' ({pattern}) is not there")
        found[key] = m.groups()
    rake, flank, *radii = (int(g) for g in found["geometry"])
    *speeds, feed = found["speeds_feed"]
    if radii != RADII_UM or [int(s) for s in speeds] != SPEEDS_M_PER_MIN:
        raise ExtractionError(f"report docx: radii {radii} or speeds {speeds} are not the README's")
    tables = docx_tables(items)
    plan = tables["Table 2-1"]
    if plan[0] != ["Parameter set", "r\u03b2(\u00b5m)", "f(mm)", "Vc(m/min)"] or \
            [(int(r[1]), r[2], r[3]) for r in plan[1:]] != [(r, feed, "20, 40, 80") for r in RADII_UM]:
        raise ExtractionError(f"report docx: Table 2-1 is {plan}")

    def exp_sim(caption, label):
        rows = tables[caption]
        if rows[0][2:] != [f"Vc={v} m/min" for v in SPEEDS_M_PER_MIN] or rows[1][2:] != ["Exp", "Sim", "My"] * 3 \
                or not rows[2][1].startswith(label):
            raise ExtractionError(f"report docx: {caption} is {rows}")
        cells = rows[2][2:]
        return {v: (cells[3 * i], cells[3 * i + 1]) for i, v in enumerate(SPEEDS_M_PER_MIN)}

    forces = {"Fc": exp_sim("Table 4-1", "Average"), "Ff": exp_sim("Table 4-2", "Average")}
    if "cutting force" not in tables["Table 4-1"][2][1] or "feed force" not in tables["Table 4-2"][2][1]:
        raise ExtractionError("report docx: Tables 4-1/4-2 are not the cutting/feed force tables")
    chip = tables["Table 4-3"]
    if chip[0][1:] != ["Vc=40 m/min", "Vc=80 m/min"] or chip[1][1:] != ["Exp", "Sim", "My"] * 2 \
            or chip[2][0] != "Chip thickness(mm)":
        raise ExtractionError(f"report docx: Table 4-3 is {chip}")
    chips = {40: (chip[2][1], chip[2][2]), 80: (chip[2][4], chip[2][5])}

    def temperature_table(caption, label):
        rows = tables[caption]
        if rows[0][0] != "T (\u2103)" or not rows[1][0].startswith(label):
            raise ExtractionError(f"report docx: {caption} is {rows}")
        return list(zip(rows[0][1:], rows[1][1:]))

    properties = {
        "workpiece_cp": temperature_table("Table 3-4", "cp"),
        "workpiece_conductivity": temperature_table("Table 3-5", "\u03bb"),
        "workpiece_expansion": temperature_table("Table 3-7", "\u03b1"),
        "tool_cp": temperature_table("Table 3-11", "cp"),
        "tool_conductivity": temperature_table("Table 3-12", "\u03bb"),
    }
    elastic = tables["Table 3-6"]
    if elastic[0] != ["T (\u2103)", "E (GPa)", "\u03bd"]:
        raise ExtractionError(f"report docx: Table 3-6 is {elastic}")
    properties["workpiece_elastic"] = [tuple(r) for r in elastic[1:]]
    jc = tables["Table 3-8"]
    if jc[0] != ["(1/s)", "T0 (\u2103)", "Tm (\u2103)", "A(MPa)", "B(MPa)", "C(MPa)", "n", "m"]:
        raise ExtractionError(f"report docx: Table 3-8 is {jc}")
    jc_values = dict(zip(("reference_strain_rate", "T0", "Tm", "A", "B", "C", "n", "m"), jc[1]))
    if jc_values["reference_strain_rate"] != "10-3":
        raise ExtractionError(f"report docx: Table 3-8 reference strain rate '{jc_values['reference_strain_rate']}'")
    jc_values["reference_strain_rate"] = "1e-3"
    damage = tables["Table 3-9"]
    if damage[0] != ["d2", "d4"]:
        raise ExtractionError(f"report docx: Table 3-9 is {damage}")
    tool = tables["Table 3-10"]
    if tool[0] != ["\u03c1(kg/m3)", "\u03b1(10-6/\u2103)"] or not re.fullmatch(r"15\.8\s*\u00d7\s*103", tool[1][0]):
        raise ExtractionError(f"report docx: Table 3-10 is {tool}")
    return {"rake": rake, "flank": flank, "feed_mm": feed, "forces": forces, "chips": chips,
            "properties": properties, "jc": jc_values, "damage": dict(zip(damage[0], damage[1])),
            "tool_density": 15.8e3, "tool_expansion_as_printed": tool[1][1]}


# ----------------------------------------------------------------------------------------------- PDF

def pdf_objects(pdf):
    return {int(m.group(1)): m.group(2) for m in re.finditer(rb"(?<![0-9])(\d+) 0 obj(.*?)endobj", pdf, flags=re.S)}


def stream_of(body):
    start = body.find(b"stream")
    if start < 0 or b"/FlateDecode" not in body[:start]:
        raise ExtractionError("a page content that is not a FlateDecode stream")
    data = body[start + len(b"stream"):].lstrip(b"\r\n")
    return zlib.decompressobj().decompress(data)


def page_content(pdf, page_number):
    """The decompressed content of page page_number (1-based), its streams joined."""
    objects = pdf_objects(pdf)
    roots = [b for b in objects.values() if re.search(rb"/Type\s*/Pages\b", b) and b"/Parent" not in b]
    if len(roots) != 1:
        raise ExtractionError("not one root /Pages object")
    kids = [int(k) for k in re.findall(rb"(\d+) 0 R", re.search(rb"/Kids\s*\[(.*?)\]", roots[0], flags=re.S).group(1))]
    page = objects[kids[page_number - 1]]
    m = re.search(rb"/Contents\s*(\[(.*?)\]|(\d+) 0 R)", page, flags=re.S)
    refs = re.findall(rb"(\d+) 0 R", m.group(2)) if m.group(2) is not None else [m.group(3)]
    return b"\n".join(stream_of(objects[int(r)]) for r in refs).decode("latin-1")


TOKEN = re.compile(r"\((?:\\.|[^\\)])*\)|/[^\s/\[\]()<>]+|\[|\]|[^\s()\[\]/]+")


def unescape(pdf_string):
    body = pdf_string[1:-1]
    octal = re.sub(r"\\([0-7]{1,3})", lambda m: chr(int(m.group(1), 8)), body)
    return re.sub(r"\\(.)", r"\1", octal)


def multiply(m, n):
    a, b, c, d, e, f = m
    A, B, C, D, E, F = n
    return [a * A + b * C, a * B + b * D, c * A + d * C, c * B + d * D, e * A + f * C + E, e * B + f * D + F]


IDENTITY = [1.0, 0.0, 0.0, 1.0, 0.0, 0.0]


def colour_name(values):
    if values is None:
        return None
    if all(abs(v) < 1e-6 for v in values):
        return "black"
    if all(abs(v - 1) < 1e-6 for v in values):
        return "white"
    if len(set(round(v, 4) for v in values)) == 1:
        return "grey"
    return "other"


def parse_content(content):
    """Filled axis-aligned rectangles (x0, y0, x1, y1, colour) and placed texts (string, x, y, rotated)."""
    rects, texts = [], []
    operands, path = [], []
    ctm, fill = IDENTITY, None
    stack = []
    tm = tlm = IDENTITY
    leading = 0.0
    in_text = False
    array = None

    def numbers(k):
        return [float(v) for v in operands[-k:]]

    for tok in TOKEN.findall(content):
        if tok == "[":
            array = []
            continue
        if tok == "]":
            operands.append(array)
            array = None
            continue
        if array is not None:
            array.append(tok)
            continue
        if tok.startswith("(") or tok.startswith("/") or re.fullmatch(r"[-+]?(\d+\.?\d*|\.\d+)", tok):
            operands.append(tok)
            continue
        op = tok
        try:
            if op == "q":
                stack.append((ctm, fill))
            elif op == "Q":
                ctm, fill = stack.pop()
            elif op == "cm":
                ctm = multiply(numbers(6), ctm)
            elif op == "rg":
                fill = colour_name(numbers(3))
            elif op == "g":
                fill = colour_name(numbers(1))
            elif op == "k":
                c, m_, y, k = numbers(4)
                fill = colour_name([(1 - c) * (1 - k), (1 - m_) * (1 - k), (1 - y) * (1 - k)])
            elif op in ("sc", "scn", "cs"):
                fill = None if not in_text else fill
            elif op == "re" and not in_text:
                x, y, w, h = numbers(4)
                a, b, c, d, e, f = ctm
                if abs(b) > 1e-9 or abs(c) > 1e-9:
                    raise ExtractionError("a rectangle under a rotated transformation")
                xs = sorted((a * x + e, a * (x + w) + e))
                ys = sorted((d * y + f, d * (y + h) + f))
                path.append((xs[0], ys[0], xs[1], ys[1]))
            elif op in ("m", "l", "c", "v", "y", "h"):
                pass  # outlines: only rectangles carry values here
            elif op in ("f", "f*", "F", "B", "B*", "b", "b*"):
                rects.extend(r + (fill,) for r in path)
                path = []
            elif op in ("n", "S", "s"):
                path = []
            elif op == "BT":
                in_text = True
                tm = tlm = IDENTITY
            elif op == "ET":
                in_text = False
            elif op == "Tm":
                tm = tlm = numbers(6)
            elif op in ("Td", "TD"):
                tx, ty = numbers(2)
                if op == "TD":
                    leading = -ty
                tm = tlm = multiply([1.0, 0.0, 0.0, 1.0, tx, ty], tlm)
            elif op == "TL":
                leading = numbers(1)[0]
            elif op == "T*":
                tm = tlm = multiply([1.0, 0.0, 0.0, 1.0, 0.0, -leading], tlm)
            elif op in ("Tj", "TJ", "'", '"'):
                if op in ("'", '"'):
                    tm = tlm = multiply([1.0, 0.0, 0.0, 1.0, 0.0, -leading], tlm)
                last = operands[-1]
                pieces = last if isinstance(last, list) else [last]
                string = "".join(unescape(p) for p in pieces if isinstance(p, str) and p.startswith("("))
                placed = multiply(tm, ctm)
                rotated = abs(placed[0]) < 1e-9 and abs(placed[1]) > 1e-9
                texts.append((string, placed[4], placed[5], rotated))
        except (ValueError, IndexError) as error:
            raise ExtractionError(f"operator {op} with operands {operands[-6:]}: {error}")
        operands = []
    return rects, texts


def least_squares(pairs):
    n = len(pairs)
    mean_y = sum(p[0] for p in pairs) / n
    mean_v = sum(p[1] for p in pairs) / n
    slope = sum((p[0] - mean_y) * (p[1] - mean_v) for p in pairs) / sum((p[0] - mean_y) ** 2 for p in pairs)
    return mean_v - slope * mean_y, slope


def find_panels(rects, texts, wanted):
    """The bar panels of the page whose tick labels read as one of the lists in wanted: each one's value axis
    (from its grey tick marks and their labels) and its bars."""
    grey = [r for r in rects if r[4] == "grey"]
    axes = [r for r in grey if r[2] - r[0] < 1.0 and r[3] - r[1] > 30.0]
    panels = []
    for ax in axes:
        axis_x = ax[0]
        ticks = sorted(0.5 * (r[1] + r[3]) for r in grey
                       if 1.5 < r[2] - r[0] < 3.0 and r[3] - r[1] < 1.0 and abs(r[2] - axis_x) < 0.5
                       and ax[1] - 1.0 < 0.5 * (r[1] + r[3]) < ax[3] + 1.0)
        labels = sorted(((y, t) for t, x, y, rot in texts
                         if not rot and re.fullmatch(r"\d+(,\d+)?", t) and axis_x - 25 < x < axis_x
                         and ax[1] - 6 < y < ax[3] + 2), key=lambda p: p[0])
        if [number(label) for _, label in labels] not in wanted:
            continue  # another figure's axis (a scatter plot, the AISI 1045 panel): not read
        if len(labels) != len(ticks):
            raise ExtractionError(f"axis at x = {axis_x:.3f}: {len(ticks)} ticks, {len(labels)} labels")
        offsets = [t - y for t, (y, _) in zip(ticks, labels)]
        if max(offsets) - min(offsets) > LABEL_OFFSET_SPREAD_PT:
            raise ExtractionError(f"axis at x = {axis_x:.3f}: tick labels not at one offset ({offsets})")
        pairs = [(t, number(label)) for t, (_, label) in zip(ticks, labels)]
        intercept, slope = least_squares(pairs)
        worst = max(abs((v - intercept) / slope - y) for y, v in pairs)
        if worst > TICK_RESIDUAL_TOLERANCE_PT:
            raise ExtractionError(f"axis at x = {axis_x:.3f}: ticks off a line by {worst:.3f} pt")
        zero_y = -intercept / slope
        base = [r for r in grey if r[3] - r[1] < 1.0 and r[2] - r[0] > 100.0 and abs(0.5 * (r[1] + r[3]) - zero_y) < 1.0]
        if len(base) != 1:
            raise ExtractionError(f"axis at x = {axis_x:.3f}: {len(base)} category axes at its zero")
        x_end = base[0][2]
        bars = {"black": [], "white": []}
        for x0, y0, x1, y1, colour in rects:
            if colour in bars and 3.0 < x1 - x0 < 12.0 and axis_x < x0 < x_end and abs(y0 - zero_y) < BAR_BASE_TOLERANCE_PT:
                bars[colour].append((x0, y0, x1, y1))
        title = " ".join(t for t, x, y, rot in sorted(texts, key=lambda s: s[2])
                         if rot and axis_x - 45 < x < axis_x - 5 and ax[1] - 15 < y < ax[3] + 5)
        panels.append({"axis_x": axis_x, "ticks": [v for _, v in pairs], "intercept": intercept, "slope": slope,
                       "zero_y": zero_y, "bottom_y": base[0][1], "x_end": x_end, "title": title,
                       "black": sorted(bars["black"]), "white": sorted(bars["white"]),
                       "worst_tick_pt": worst})
    return panels


def read_panel(panel, conditions, name):
    """[(condition, exp, sim)] for one panel: the black bar is the experiment, the white one the simulation."""
    black, white = panel["black"], panel["white"]
    if len(black) != len(conditions) or len(white) != len(conditions):
        raise ExtractionError(f"{name}: {len(black)} black and {len(white)} white bars for {len(conditions)} conditions")
    value = lambda y: panel["intercept"] + panel["slope"] * y  # noqa: E731
    rows = []
    for condition, b, w in zip(conditions, black, white):
        if not 3.0 < w[0] - b[0] < 8.0:
            raise ExtractionError(f"{name}: the simulation bar at {w[0]:.3f} does not follow the experiment's at {b[0]:.3f}")
        for bar in (b, w):
            height = bar[3] - bar[1]
            if abs(height / DEVICE_QUANTUM_PT - round(height / DEVICE_QUANTUM_PT)) > 0.02:
                raise ExtractionError(f"{name}: a bar of {height} pt is not on the {DEVICE_QUANTUM_PT} pt grid")
        rows.append((condition, value(b[3]), value(w[3])))
    return rows


def table_row_below(texts, panel, expected):
    """The condition row printed under a panel must read as expected (the joined strings of one text show)."""
    below = [t for t, x, y, rot in texts if not rot and panel["axis_x"] < x < panel["x_end"]
             and panel["bottom_y"] - 40 < y < panel["bottom_y"]]
    if expected not in below:
        raise ExtractionError(f"no condition row '{expected}' under the panel at x = {panel['axis_x']:.3f} (found {below})")


def read_klocke(pdf):
    content = page_content(pdf, 5)
    rects, texts = parse_content(content)
    panels = find_panels(rects, texts, [ticks for ticks, _ in PANELS.values()])
    found = {}
    for name, (ticks, title) in PANELS.items():
        matches = [p for p in panels if [round(t, 6) for t in p["ticks"]] == ticks]
        if len(matches) != 1:
            raise ExtractionError(f"Klocke page 5: {len(matches)} panels with ticks {ticks}")
        if title.replace(" ", "") not in matches[0]["title"].replace(" ", ""):  # word spaces are kerning there
            raise ExtractionError(f"Klocke page 5: the panel with ticks {ticks} is titled '{matches[0]['title']}'")
        found[name] = matches[0]
    for name, conditions in (("Ff", FIG7_CONDITIONS), ("serration", FIG9_CONDITIONS)):
        table_row_below(texts, found[name], "".join(str(v) for v, _ in conditions))
        table_row_below(texts, found[name], "".join(f for _, f in conditions))
    values = {}
    for name in PANELS:
        conditions = FIG7_CONDITIONS if name in ("Fc", "Ff") else FIG9_CONDITIONS
        values[name] = read_panel(found[name], conditions, name)
    resolution = {name: abs(found[name]["slope"]) * DEVICE_QUANTUM_PT for name in PANELS}
    text = klocke_text(pdf)
    return values, resolution, found, text


FIG3_TICKS = [0, 0.1, 0.2, 0.3, 0.4, 0.5]
FIG3_LEGEND = "uncoatedcementedcarbide, Inconel 718"  # word spaces are kerning in the stream
FIG3_MARKER_PT = (3.5, 4.0)  # the Inconel 718 series' filled squares (the AISI 1045 series has diamonds)


def read_klocke_fig3(pdf):
    """[(v_rel in m/min, mu)] of Fig. 3's Inconel 718 series (filled squares), the x axis from its two ticks
    (0 and 100 m/min), the y axis from its six labelled ticks."""
    rects, texts = parse_content(page_content(pdf, 3))
    panels = find_panels(rects, texts, [FIG3_TICKS])
    if len(panels) != 1 or "Coulomb" not in panels[0]["title"]:
        raise ExtractionError(f"Klocke page 3: {len(panels)} panels with ticks {FIG3_TICKS}")
    panel = panels[0]
    x_ticks = sorted(0.5 * (r[0] + r[2]) for r in rects if r[4] == "grey" and r[2] - r[0] < 1.0
                     and 2.0 < r[3] - r[1] < 3.0 and abs(r[3] - panel["bottom_y"]) < 1.0)
    if len(x_ticks) != 2 or not any(t == "0100" and abs(y - panel["bottom_y"] + 12) < 3 for t, x, y, rot in texts):
        raise ExtractionError(f"Klocke Fig. 3: x ticks {x_ticks}, or no '0 ... 100' labels under them")
    if not any(t.startswith("relative velocity") for t, x, y, rot in texts):
        raise ExtractionError("Klocke Fig. 3: no 'relative velocity' axis title")
    legend = [(x, y) for t, x, y, rot in texts if t == FIG3_LEGEND]
    if len(legend) != 1:
        raise ExtractionError(f"Klocke Fig. 3: {len(legend)} legend entries '{FIG3_LEGEND}'")
    squares = []
    for x0, y0, x1, y1, colour in rects:
        w, h = x1 - x0, y1 - y0
        if colour == "black" and FIG3_MARKER_PT[0] < w < FIG3_MARKER_PT[1] and abs(w - h) < 1e-3 \
                and panel["axis_x"] < x0 < panel["x_end"] + 5 and y0 > panel["zero_y"]:
            xc, yc = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
            if xc < legend[0][0] and abs(yc - legend[0][1]) < 5:
                continue  # the legend's own marker
            squares.append((xc, yc))
    if len(squares) != 5:
        raise ExtractionError(f"Klocke Fig. 3: {len(squares)} Inconel 718 markers")
    value = lambda y: panel["intercept"] + panel["slope"] * y  # noqa: E731
    speed = lambda x: 100.0 * (x - x_ticks[0]) / (x_ticks[1] - x_ticks[0])  # noqa: E731
    resolution = (100.0 * DEVICE_QUANTUM_PT / (x_ticks[1] - x_ticks[0]), abs(panel["slope"]) * DEVICE_QUANTUM_PT)
    return [(speed(x), value(y)) for x, y in sorted(squares)], resolution


def klocke_text(pdf):
    """The paper's running text (all pages' text shows joined; line breaks and hyphenation left in)."""
    pieces = []
    for page in range(1, 7):
        _, texts = parse_content(page_content(pdf, page))
        pieces.extend(t for t, x, y, rot in texts)
    return " ".join(pieces)


KLOCKE_SENTENCES = {
    "hardness": r"In-?\s*conel 718 with 46\.1 HRC",
    "ABn": r"A = (\d+) MPa, B = (\d+), n = (\d+,\d+)\.",
    "mC": r"m = (\d+,\d+); C = (\d+,\d+); D\s*crit\s*= (\d+,\d+); p = (\d+,\d+) %",
    "reference": r"\(\s*\S?\s*0 = 0,001;\s*T\s*0 = 20 \S*C\)",
    "tool": r"uncoated cemented carbide inserts \(WC-\s*6CO\)",
    "angles": r"All tool rake angles are 0\S*, all tool flank angles\s+are 7\S*",
    "workpiece": r"The workpiece dimensions are 50 mm x 35 mm x 3 mm",
    "dynamometer": r"piezoelectric dynamometer \(Kistler 9255B\)",
    "error": r"The average error between the experimental and numeri-\s*cal data is ca\. 10 %",
}


def check_klocke_text(text):
    flat = re.sub(r"\s+", " ", text)
    found = {}
    for key, pattern in KLOCKE_SENTENCES.items():
        m = re.search(pattern, flat)
        if not m:
            raise ExtractionError(f"Klocke et al. text: '{key}' ({pattern}) is not there")
        found[key] = m.groups()
    return found


# ---------------------------------------------------------------------------------------------- write

def fmt(x, digits=7):
    return f"{x:.{digits}g}"


def source_header(commit):
    return [
        "# Source: public GitHub repository zhenzhuzz/Inconel718-Cutting (Zhen Zhu; a student's course project report of",
        "# January 2023, README rewritten 2025-08-12), commit " + commit + ".",
    ]


def write_cutting_tests(out, commit, fc, ff, report):
    lines = [
        "# Dry orthogonal cutting (broaching) of aged Inconel 718 with uncoated carbide inserts (H13A), rake 0 deg, flank",
        "# 10 deg, cutting-edge radius r_beta 10/20/30 um, feed (uncut chip thickness) f = 0.05 mm, cutting speed 20/40/80",
        "# m/min; Forst RASX 8x2200x600M/CNC broaching machine with a piezoelectric dynamometer, WZL RWTH Aachen.",
        "# Measurements from R. Bedzra, 'Finite element simulation of two dimensional orthogonal cutting process and",
        "# comparison with experiments', RWTH Aachen University, 2013 (thesis), as tabulated by the repository: the thesis",
        "# itself is NOT in the snapshot (Master_thesis.pdf is listed but absent) and was not read. Each condition was",
        "# repeated three times (report); only the mean is given, NO scatter. The CUT WIDTH IS NOT STATED anywhere: the",
        "# forces are in N as printed, for an unknown width (see README.md).",
    ] + source_header(commit) + [
        "# Files: README.md tables '\u88684.11' (cutting force) and '\u88684.12' (feed force); for r_beta = 10 um the same",
        "# numbers are in 01_Abaqus_FEM_ThermalMechanical_Cutting/Project_report_*.docx Tables 4-1 and 4-2 (checked equal).",
        "# How read: table (markdown / Word XML), by data/zhenzhuzz_inconel718_carbide/extract.py.",
        "# *_exp: measured mean; *_sim_bedzra: the thesis's own 2D FE simulation, NOT a measurement.",
        "cutting_edge_radius[um],cutting_speed[m/min],uncut_chip_thickness[mm],Fc_exp[N],Ff_exp[N],"
        "Fc_sim_bedzra[N],Ff_sim_bedzra[N],source",
    ]
    for radius in RADII_UM:
        for speed in SPEEDS_M_PER_MIN:
            c, f = fc[(radius, speed)], ff[(radius, speed)]
            source = f"README.md 4.11/4.12 row r_beta={radius} @{speed}"
            if radius == 10:
                source += "; docx Tables 4-1/4-2"
            lines.append(",".join([str(radius), str(speed), report["feed_mm"], c["exp"][1], f["exp"][1],
                                   c["sim"][1], f["sim"][1], source]))
    (out / "cutting_tests.csv").write_text("\n".join(lines) + "\n")
    return len(lines)


def write_chip_thickness(out, commit, report):
    feed = float(report["feed_mm"])
    lines = [
        "# Chip thickness after cutting aged Inconel 718 (conditions as in cutting_tests.csv), r_beta = 10 um only: the",
        "# report's Table 4-3 'Measured chip thickness' compares its parameter sets 1-3 (r_beta = 10 um, Table 2-1).",
        "# Which chip thickness is meant (mean, or the maximum h_max of a serrated chip) is NOT stated; the repository's",
        "# 2023-06 notebook labels the same numbers 'h_max (mm)'. No scatter. chip_ratio_exp is DERIVED here as",
        f"# h_chip_exp / f with f = {report['feed_mm']} mm (report, section 2.1), not printed by the source.",
    ] + source_header(commit) + [
        "# File: 01_Abaqus_FEM_ThermalMechanical_Cutting/Project_report_*.docx, Table 4-3. How read: table (Word XML).",
        "# *_sim_bedzra: the thesis's FE simulation, NOT a measurement (the repository's other files give 0.073/0.074 mm",
        "# for the 80 m/min value, a sign these were read from a figure of the thesis: see README.md).",
        "cutting_edge_radius[um],cutting_speed[m/min],uncut_chip_thickness[mm],h_chip_exp[mm],h_chip_sim_bedzra[mm],"
        "chip_ratio_exp_derived[1],source",
    ]
    for speed in (40, 80):
        exp, sim = report["chips"][speed]
        lines.append(",".join(["10", str(speed), report["feed_mm"], exp, sim, fmt(float(exp) / feed, 6),
                               f"docx Table 4-3 Vc={speed} m/min"]))
    (out / "chip_thickness.csv").write_text("\n".join(lines) + "\n")


JC_UNITS = {"A": "MPa", "B": "MPa", "n": "1", "C": "1", "m": "1", "reference_strain_rate": "1/s",
            "T0": "degC", "Tm": "degC"}


def write_johnson_cook(out, commit, readme_jc, report, klocke):
    a, b, n = klocke["ABn"]
    m, c, dcrit, p = klocke["mC"]
    klocke_values = {"A": a, "B": b, "n": n.replace(",", "."), "C": c.replace(",", "."), "m": m.replace(",", "."),
                     "reference_strain_rate": "0.001", "T0": "20", "Tm": ""}
    for key in JC_UNITS:
        values = {float(readme_jc[key]), float(report["jc"][key])} | ({float(klocke_values[key])} if klocke_values[key] else set())
        if len(values) != 1:
            raise ExtractionError(f"Johnson-Cook {key}: README {readme_jc[key]}, docx {report['jc'][key]}, "
                                  f"Klocke {klocke_values[key]} differ")
    lines = [
        "# Johnson-Cook flow stress for aged Inconel 718 (46.1 HRC), sigma = (A + B eps^n)(1 + C ln(epsdot/epsdot0))",
        "# (1 - ((T - T0)/(Tm - T0))^m), as used by the repository's FE model and stated by three files: README.md, the",
        "# report docx (Table 3-8, which labels C in MPa: a typo, C is dimensionless) and the paper it is taken from,",
        "# F. Klocke, D. Lung, S. Buchkremer, 'Inverse identification of the constitutive equation of Inconel 718 and AISI",
        "# 1045 from FE machining simulations', Procedia CIRP 8 (2013) 212-217, doi:10.1016/j.procir.2013.06.091 (in the",
        "# repository as a PDF): A, B, n fitted to Issler's quasi-static flow curve shifted to 46.1 HRC; C, m identified",
        "# INVERSELY from orthogonal cutting with a Deform 2D model, together with a Cockcroft-Latham damage criterion",
        "# (D_crit, p below) and Puls's hybrid friction model. The paper prints the reference values as 'often' used",
        "# (epsdot0 = 0.001, T0 = 20 C); Tm = 1297 C is not in it (README and docx only). JC damage d2, d4 (report Table",
        "# 3-9, the FE model's separation criterion, attributed to Bedzra's thesis) are a different model from Klocke's.",
    ] + source_header(commit) + [
        "# How read: text (README.md, LaTeX-like formulae), table (docx Table 3-8/3-9), text (the PDF's text operators;",
        "# its decimal commas written here as points). Columns readme_md/docx_table/klocke2013_text: the value each prints.",
        "parameter,value,unit,readme_md,docx_table,klocke2013_text",
    ]
    for key, unit in JC_UNITS.items():
        lines.append(",".join([key, fmt(float(readme_jc[key])), unit, readme_jc[key], report["jc"][key],
                               klocke_values[key]]))
    for key, value in report["damage"].items():
        lines.append(",".join([f"jc_damage_{key}", value, "1", "", value + " (Table 3-9)", ""]))
    lines.append(",".join(["cockcroft_latham_D_crit", dcrit.replace(",", "."), "none printed", "", "",
                           dcrit.replace(",", ".")]))
    lines.append(",".join(["cockcroft_latham_p", p.replace(",", "."), "percent of the flow stress", "", "",
                           p.replace(",", ".")]))
    (out / "johnson_cook.csv").write_text("\n".join(lines) + "\n")


def write_properties(out, commit, report, density):
    rows = []
    props = report["properties"]
    for key, unit, label, table in (("workpiece_cp", "J/(kg K)", "specific_heat", "Table 3-4"),
                                    ("workpiece_conductivity", "W/(m K)", "thermal_conductivity", "Table 3-5"),
                                    ("workpiece_expansion", "1e-6/K", "thermal_expansion", "Table 3-7"),
                                    ("tool_cp", "J/(kg K)", "specific_heat", "Table 3-11"),
                                    ("tool_conductivity", "W/(m K)", "thermal_conductivity", "Table 3-12")):
        body = key.split("_")[0]
        for t, v in props[key]:
            rows.append((body, label, t, v, unit, f"docx {table}"))
    for t, e, nu in props["workpiece_elastic"]:
        rows.append(("workpiece", "youngs_modulus", t, e, "GPa", "docx Table 3-6"))
        rows.append(("workpiece", "poissons_ratio", t, nu, "1", "docx Table 3-6"))
    rows.append(("workpiece", "density", "", fmt(density), "kg/m3", "README.md (rho = 8.22 x 10^3 kg/m^3)"))
    rows.append(("tool", "density", "", fmt(report["tool_density"]), "kg/m3", "docx Table 3-10 (15.8 x 10^3)"))
    rows.append(("tool", "thermal_expansion", "", report["tool_expansion_as_printed"], "1e-6/K AS PRINTED",
                 "docx Table 3-10 (README.md says 5.4e-6/K: the 540 looks like a typo)"))
    lines = [
        "# Thermal and elastic properties used by the repository's FE model (aged Inconel 718 workpiece, tungsten-carbide",
        "# tool), most attributed by the report to Bedzra's thesis (2013), which itself was not read. Temperatures in",
        "# degC as printed. The source prints conductivity as N/(s degC), identical to W/(m K), and cp as J/(kg degC).",
        "# These are model inputs quoted from literature, not measurements of this cut.",
    ] + source_header(commit) + [
        "# How read: table (Word XML of Project_report_*.docx; README.md for the workpiece density).",
        "body,property,temperature[degC],value,unit,source",
    ] + [",".join(r) for r in rows]
    (out / "material_properties.csv").write_text("\n".join(lines) + "\n")


def write_klocke(out, commit, values, resolution):
    fig7 = {(v, f): (fc_exp, fc_sim) for (v, f), fc_exp, fc_sim in values["Fc"]}
    fig7f = {(v, f): (e, s) for (v, f), e, s in values["Ff"]}
    hmax = {(v, f): (e, s) for (v, f), e, s in values["hmax"]}
    ser = {(v, f): (e, s) for (v, f), e, s in values["serration"]}
    lines = [
        "# Orthogonal cutting of aged Inconel 718 (46.1 HRC) with uncoated cemented carbide (WC-6Co) inserts, rake 0 deg,",
        "# flank 7 deg, cutting-edge radius r_beta = 30 um (the text layer lacks the value: read from the rendered line",
        "# 'the cutting edge radii are r_beta = 30 um'), dry, on the WZL broaching machine (Forst RASX) with a Kistler 9255B",
        "# dynamometer; workpiece 50 mm x 35 mm x 3 mm; CUT WIDTH NOT STATED. No repeats or scatter given.",
        "# Source: F. Klocke, D. Lung, S. Buchkremer, Procedia CIRP 8 (2013) 212-217, doi:10.1016/j.procir.2013.06.091,",
        "# Fig. 7 (forces) and Fig. 9 (maximum chip thickness h_max and serration ratio h_max/h_min); a copy is in the",
        "# repository (01_Abaqus_FEM_ThermalMechanical_Cutting/Reference/Inverse identification ... simulations.pdf).",
    ] + source_header(commit) + [
        "# How read: vector figure - bar tops from the page's drawing operators (page 5), the value axis from its tick",
        "# marks and labels, black bars = Experiment, white bars = Simulation (the paper's Deform 2D model, NOT a",
        "# measurement). The figures were drawn on a device grid of about 0.2208 pt: *_resolution is one grid step in",
        "# the quantity's unit, the reading's uncertainty (+-1 step); values rounded to well within it. Empty: not in Fig. 9.",
        "cutting_speed[m/min],uncut_chip_thickness[mm],Fc_exp[N],Ff_exp[N],Fc_sim_klocke[N],Ff_sim_klocke[N],"
        "force_resolution_Fc[N],force_resolution_Ff[N],hmax_exp[mm],hmax_sim_klocke[mm],hmax_resolution[mm],"
        "serration_ratio_exp[1],serration_ratio_sim_klocke[1],serration_resolution[1]",
    ]
    for v, f in FIG7_CONDITIONS:
        fc_e, fc_s = fig7[(v, f)]
        ff_e, ff_s = fig7f[(v, f)]
        cells = [str(v), f.replace(",", "."), f"{fc_e:.1f}", f"{ff_e:.1f}", f"{fc_s:.1f}", f"{ff_s:.1f}",
                 f"{resolution['Fc']:.1f}", f"{resolution['Ff']:.1f}"]
        if (v, f) in hmax:
            cells += [f"{hmax[(v, f)][0]:.4f}", f"{hmax[(v, f)][1]:.4f}", f"{resolution['hmax']:.4f}",
                      f"{ser[(v, f)][0]:.3f}", f"{ser[(v, f)][1]:.3f}", f"{resolution['serration']:.3f}"]
        else:
            cells += [""] * 6
        lines.append(",".join(cells))
    (out / "klocke2013_cutting_tests.csv").write_text("\n".join(lines) + "\n")


def write_klocke_fig3(out, commit, points, resolution):
    lines = [
        "# Coulomb friction coefficient against the relative (sliding) velocity, uncoated cemented carbide on Inconel",
        "# 718, as IMPLEMENTED in the FE model of Klocke, Lung, Buchkremer, Procedia CIRP 8 (2013) 212-217, Fig. 3",
        "# ('Implemented Coulomb friction coefficients in the hybrid friction model ... [8]'), attributed there to",
        "# H. Puls, F. Klocke, D. Lung, 'A new experimental methodology to analyse the friction behaviour at the",
        "# tool-chip interface in metal cutting', Production Engineering 6(4-5) (2012) 349-354 (not read here: whether",
        "# and how it measured these values, for which tool and at which pressure, is not checked). Values PLOTTED BY",
        "# THIS SOURCE as a model input, not measurements of the paper. In the hybrid model the frictional stress is",
        "# also limited to the material's flow stress (m_shear = 1). No uncertainty given.",
    ] + source_header(commit) + [
        "# How read: vector figure - the five filled squares of the Inconel 718 series (page 3), x from the axis's two",
        "# ticks (0 and 100 m/min), y from its six labelled ticks (0 ... 0.5); *_resolution: one 0.2208 pt grid step.",
        "relative_velocity[m/min],mu_coulomb,velocity_resolution[m/min],mu_resolution",
    ]
    for v, mu in points:
        lines.append(f"{v:.1f},{mu:.4f},{resolution[0]:.2f},{resolution[1]:.4f}")
    (out / "klocke2013_fig3_friction_as_plotted.csv").write_text("\n".join(lines) + "\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repo", required=True, help="a clone (or bare git directory) of " + REPOSITORY)
    parser.add_argument("--commit", default=COMMIT)
    parser.add_argument("--out-dir", default=str(Path(__file__).parent))
    args = parser.parse_args()
    out = Path(args.out_dir)
    out.mkdir(parents=True, exist_ok=True)
    try:
        readme = git_show(args.repo, args.commit, README).decode("utf-8")
        report_bytes = git_show(args.repo, args.commit, REPORT_DOCX)
        klocke_pdf = git_show(args.repo, args.commit, KLOCKE_PDF)
    except subprocess.CalledProcessError as error:
        sys.exit(f"extract: git show failed: {error.stderr.decode(errors='replace').strip()}")
    try:
        fc, ff, readme_jc, density = read_readme(readme)
        report = read_report(report_bytes)
        for quantity, table in (("Fc", fc), ("Ff", ff)):
            for speed, (exp, sim) in report["forces"][quantity].items():
                if (float(exp), float(sim)) != (table[(10, speed)]["exp"][0], table[(10, speed)]["sim"][0]):
                    raise ExtractionError(f"{quantity} at r_beta = 10 um, {speed} m/min: docx {exp}/{sim} differs "
                                          f"from README {table[(10, speed)]}")
        values, resolution, _, text = read_klocke(klocke_pdf)
        friction, friction_resolution = read_klocke_fig3(klocke_pdf)
        klocke = check_klocke_text(text)
    except (ExtractionError, KeyError, zipfile.BadZipFile) as error:
        sys.exit(f"extract: {error}")
    write_cutting_tests(out, args.commit, fc, ff, report)
    write_chip_thickness(out, args.commit, report)
    write_johnson_cook(out, args.commit, readme_jc, report, klocke)
    write_properties(out, args.commit, report, density)
    write_klocke(out, args.commit, values, resolution)
    write_klocke_fig3(out, args.commit, friction, friction_resolution)
    print(f"extract: 9 force conditions, 2 chip thicknesses, the Johnson-Cook set, material properties and "
          f"Klocke et al.'s {len(FIG7_CONDITIONS)} + {len(FIG9_CONDITIONS)} figure conditions and {len(friction)} "
          f"friction points written to {out}")


if __name__ == "__main__":
    main()
