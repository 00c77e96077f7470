#!/usr/bin/env python3
"""The friction-law study's table and figure: reads OUT/<law>/p*_v*_T*/result.json as written by
bench/studies/friction_laws/friction_laws_study.sh and prints, per law and point, mu +- its standard error and mu's work
split (interface = the adhesive part, plastic = ploughing, normal = the normal load's work), then
draws mu against p, v and T through the box centre, one line per law (OUT/friction_laws.png), and
mu at the box's corners when they were run (OUT/friction_laws_corners.png). With --against OTHER
(e.g. the dry study beside a lubricated one) the other study's laws are drawn dashed in the same
figure and hatched beside each corner's bar, so lubricated and dry can be read off one plot, and a
second table gives, per law and point both studies ran, the change of mu paired over the draws (the
same tool and chip seeds in both: their common error cancels); where the box's corners were run, a
corner table (the other study's final contact fraction, mu, the paired change, the wetted share and
the work split side by side) and an edge table (mu's change along each edge of the box that joins two
corners both studies ran, in each study) follow.

  /usr/bin/python3 bench/studies/friction_laws/plot_friction_laws.py OUT [--against OTHER]
"""
import json
import pathlib
import re
import statistics
import sys


def point_of(name):
    m = re.match(r"p([\d.]+)MPa_v([\d.]+)m_min_T([\d.]+)C", name)
    return tuple(float(g) for g in m.groups()) if m else None


def draw_wetted_share(draw):
    """One draw's wetted share of the contact, mean over the steps of mu's window (None without any)."""
    start, end = draw.get("mu_window_sliding_distance_m", [0.0, float("inf")])
    in_window = [h.get("wetted_contact_fraction", 0.0) for h in draw.get("history", [])
                 if start <= h.get("sliding_distance_m", -1.0) <= end]
    return sum(in_window) / len(in_window) if in_window else None


def window_wetted_share(result):
    """The wetted share of the contact, mean over the steps of mu's window and over the draws (a
    contact patch switches between wetted and dry as the liquid reaches its edge, so the last step
    alone can say 0 or 1 where the window saw either)."""
    shares = [x for x in map(draw_wetted_share, result.get("draws", [])) if x is not None]
    return f"{sum(shares) / len(shares):.2f}" if shares else ""


def paired_changes_and_shares(result, other):
    """Per draw that pairs (same tool and chip seeds): (the draw's window wetted share, its relative
    change of mu from `other`)."""
    theirs = {(d["tool_seed"], d["chip_seed"]): d["mu"] for d in other.get("draws", []) if d.get("completed")}
    return [(draw_wetted_share(d), d["mu"] / theirs[key] - 1.0) for d in result.get("draws", []) if d.get("completed")
            for key in [(d["tool_seed"], d["chip_seed"])] if key in theirs]


def paired_change(result, other):
    """Mean relative change of mu from `other` to `result` over the draws both ran with the same tool
    and chip seeds, and its standard error (None when fewer than two draws pair)."""
    changes = [change for _, change in paired_changes_and_shares(result, other)]
    if len(changes) < 2:
        return None
    return statistics.mean(changes), statistics.stdev(changes) / len(changes) ** 0.5


def final_contact_fraction(result):
    """The contact fraction of each draw's last step, mean over the draws ("" without any)."""
    shares = [d["history"][-1]["contact_area_fraction"] for d in result.get("draws", []) if d.get("history")]
    return f"{sum(shares) / len(shares):.2f}" if shares else ""


def edge_change(start, end):
    """mu's change from the point `start` to the point `end` of one study: the ratio of the means over
    the draws, and the standard error of the per-draw changes (the draws at both points share their tool
    and chip seeds, so the change is paired; None when fewer than two draws pair)."""
    changes = [change for _, change in paired_changes_and_shares(end, start)]
    if len(changes) < 2:
        return None
    return end["mu"] / start["mu"] - 1.0, statistics.stdev(changes) / len(changes) ** 0.5


def corner_points(points, centre):
    """The points that differ from the box's centre in all three coordinates."""
    return [pt for pt in points if sum(pt[i] != centre[i] for i in range(3)) == 3]


def box_centre(points):
    """The middle value of each coordinate over the points run."""
    return tuple(sorted({pt[i] for pt in points})[len({pt[i] for pt in points}) // 2] for i in range(3))


def print_corner_tables(laws, name, other, other_name, corners):
    """Per law, the corners both studies completed side by side, then mu's change along each edge of
    the box between two such corners, in this study and in the other."""
    def both_completed(law, pt):
        return laws[law].get(pt, {}).get("completed") and other.get(law, {}).get(pt, {}).get("completed")
    def split(result, key):
        value = result.get("work_split", {}).get(key)
        return f"{value:.4f}" if value is not None else ""
    def cell(change):
        return f"{100 * change[0]:+.1f} % ± {100 * change[1]:.1f} %" if change else "fewer than two paired draws"
    for law in laws:
        done = [pt for pt in corners if both_completed(law, pt)]
        if not done:
            continue
        print(f"\n{law} at the corners (contact: {other_name}'s final contact fraction, mean over the draws)\n")
        print(f"| p [MPa] | v [m/min] | T [C] | contact ({other_name}) | mu | mu ({other_name}) | change, paired over the draws "
              f"| wetted (window) | interface / {other_name} | plastic / {other_name} |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        for pt in done:
            r, o = laws[law][pt], other[law][pt]
            p, v, t = pt
            print(f"| {p:g} | {v:g} | {t:g} | {final_contact_fraction(o)} | {r['mu']:.4f} ± {r.get('mu_std_error') or 0:.4f} "
                  f"| {o['mu']:.4f} ± {o.get('mu_std_error') or 0:.4f} | {cell(paired_change(r, o))} | {window_wetted_share(r)} "
                  f"| {split(r, 'mu_interface')} / {split(o, 'mu_interface')} "
                  f"| {split(r, 'mu_bulk_plastic')} / {split(o, 'mu_bulk_plastic')} |")
        names = ("p", "v", "T")
        units = ("MPa", "m/min", "C")
        print(f"\n{law} along the box's edges (ratio of the mean mu over the draws ± the standard error of the per-draw changes)\n")
        print(f"| change | {name} | {other_name} |")
        print("|---|---|---|")
        for a in done:
            for b in done:
                moved = [i for i in range(3) if a[i] != b[i]]
                if len(moved) != 1 or a[moved[0]] > b[moved[0]]:
                    continue
                i = moved[0]
                fixed = ", ".join(f"{a[j]:g} {units[j]}" for j in range(3) if j != i)
                print(f"| {names[i]} {a[i]:g} → {b[i]:g} {units[i]} at {fixed} "
                      f"| {cell(edge_change(laws[law][a], laws[law][b]))} | {cell(edge_change(other[law][a], other[law][b]))} |")


def read_study(out):
    """{law: {(p, v, T): result.json}} for every point of the study that has a result."""
    laws = {}
    for law_dir in sorted(p for p in out.iterdir() if p.is_dir()):
        rows = {}
        for run in sorted(law_dir.iterdir()):
            point = point_of(run.name)
            result = run / "result.json"
            if point is None or not result.exists():
                continue
            rows[point] = json.load(open(result))
        if rows:
            laws[law_dir.name] = rows
    return laws


def main():
    usage = "usage: plot_friction_laws.py OUT [--against OTHER]"
    args = sys.argv[1:]
    if len(args) not in (1, 3) or (len(args) == 3 and args[1] != "--against"):
        sys.exit(usage)
    out = pathlib.Path(args[0])
    laws = read_study(out)
    if not laws:
        sys.exit(f"{out}: no runs yet")
    other, other_name = {}, ""
    if len(args) == 3:
        other_dir = pathlib.Path(args[2])
        other, other_name = read_study(other_dir), other_dir.name
        if not other:
            sys.exit(f"{other_dir}: no runs to compare against")
    print("| law | p [MPa] | v [m/min] | T [C] | mu | interface | plastic | normal load | wetted (window) | wall [s] |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for law, rows in laws.items():
        for (p, v, t), r in sorted(rows.items()):
            if not r.get("completed"):
                print(f"| {law} | {p:g} | {v:g} | {t:g} | failed: {r.get('reason', '')[:60]} | | | | | |")
                continue
            mu = f"{r['mu']:.4f}" + (f" ± {r['mu_std_error']:.4f}" if r.get("mu_std_error") else "")
            split = r.get("work_split", {})
            parts = [split.get(k) for k in ("mu_interface", "mu_bulk_plastic", "mu_normal_load")]
            cells = [f"{x:.4f}" if x is not None else "" for x in parts]
            wet = window_wetted_share(r)
            print(f"| {law} | {p:g} | {v:g} | {t:g} | {mu} | {' | '.join(cells)} | {wet} | {r['diagnostics']['wall_seconds']:.0f} |")
    if other:
        print(f"\n| law | p [MPa] | v [m/min] | T [C] | mu | mu ({other_name}) | change, paired over the draws | wetted (window) |")
        print("|---|---|---|---|---|---|---|---|")
        for law, rows in laws.items():
            for pt, r in sorted(rows.items()):
                o = other.get(law, {}).get(pt)
                if o is None or not r.get("completed") or not o.get("completed"):
                    continue
                change = paired_change(r, o)
                cell = f"{100 * change[0]:+.1f} % ± {100 * change[1]:.1f} %" if change else "fewer than two paired draws"
                p, v, t = pt
                print(f"| {law} | {p:g} | {v:g} | {t:g} | {r['mu']:.4f} | {o['mu']:.4f} | {cell} | {window_wetted_share(r)} |")
        # Does the change follow how much of the contact the liquid reaches? Least squares through the
        # origin of the per-draw change on the per-draw window wetted share, per law, over every paired point.
        for law, rows in laws.items():
            pairs = [(share, change) for pt, r in rows.items() if r.get("completed") and other.get(law, {}).get(pt, {}).get("completed")
                     for share, change in paired_changes_and_shares(r, other[law][pt]) if share is not None]
            shares, changes = [x for x, _ in pairs], [y for _, y in pairs]
            if len(pairs) >= 3 and statistics.pstdev(shares) > 0 and statistics.pstdev(changes) > 0:
                slope = sum(x * y for x, y in pairs) / sum(x * x for x in shares)
                print(f"{law}: change of mu = {slope:+.3f} x the window's wetted share over {len(pairs)} draws "
                      f"(least squares through the origin; correlation {statistics.correlation(shares, changes):+.2f})")
    all_points = sorted({pt for rows in laws.values() for pt in rows})
    centre = box_centre(all_points)
    corners = corner_points(all_points, centre)
    if other and corners:
        print_corner_tables(laws, out.name, other, other_name, corners)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    # One colour per law, whichever study it comes from: the other study's line is the same colour, dashed.
    cycle = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    colour = {law: cycle[i % len(cycle)] for i, law in enumerate(dict.fromkeys(list(laws) + list(other)))}
    series = [(law, law, rows, False) for law, rows in laws.items()] + \
             [(law, f"{law} ({other_name})", rows, True) for law, rows in other.items()]
    fig, axes = plt.subplots(1, 3, figsize=(13, 4), sharey=True)
    for axis, (ax, label) in enumerate(zip(axes, ["contact pressure [MPa]", "sliding velocity [m/min]", "temperature [°C]"])):
        for law, legend, rows, dashed in series:
            xs, ys, es = [], [], []
            for pt, r in sorted(rows.items()):
                if all(pt[i] == centre[i] for i in range(3) if i != axis) and r.get("completed"):
                    xs.append(pt[axis]); ys.append(r["mu"]); es.append(r.get("mu_std_error") or 0.0)
            if xs:
                ax.errorbar(xs, ys, yerr=[1.96 * e for e in es], marker="s" if dashed else "o", capsize=3,
                            linestyle="--" if dashed else "-", alpha=0.6 if dashed else 1.0,
                            color=colour[law], label=legend)
        ax.set_xlabel(label)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("mu (95 % interval of the mean over the tools)")
    axes[0].legend()
    fig.suptitle(f"mu through the box centre, per interfacial law ({out.name}" + (f"; dashed: {other_name})" if other else ")"))
    fig.tight_layout()
    fig.savefig(out / "friction_laws.png", dpi=110)
    print(f"figure: {out / 'friction_laws.png'}")
    # The corners (CORNERS=1): every point off the three lines through the centre, μ per law side by side.
    if corners:
        fig, ax = plt.subplots(figsize=(11, 4))
        # Each law's bar beside the other study's (hatched) for the same law; a law this study ran only
        # through the centre has no bar here, nor its hatched twin.
        order = list(colour)
        def has_corners(rows):
            return any(rows.get(pt, {}).get("completed") for pt in corners)
        bars = sorted((item for item in series if has_corners(laws.get(item[0], {})) and has_corners(item[2])),
                      key=lambda item: (order.index(item[0]), item[3]))
        width = 0.8 / len(bars)
        for k, (law, legend, rows, dashed) in enumerate(bars):
            xs, ys, es = [], [], []
            for c, pt in enumerate(corners):
                r = rows.get(pt)
                if r is not None and r.get("completed"):
                    xs.append(c + (k - (len(bars) - 1) / 2) * width); ys.append(r["mu"]); es.append(1.96 * (r.get("mu_std_error") or 0.0))
            ax.bar(xs, ys, width, yerr=es, capsize=2, label=legend, color=colour[law],
                   hatch="//" if dashed else None, alpha=0.45 if dashed else 1.0)
        ax.set_xticks(range(len(corners)))
        ax.set_xticklabels([f"{p:g} MPa\n{v:g} m/min\n{t:g} °C" for p, v, t in corners], fontsize=8)
        ax.set_ylabel("mu (95 % interval)")
        ax.legend()
        ax.grid(alpha=0.3, axis="y")
        fig.suptitle("mu at the corners of the box, per interfacial law" + (f" (hatched: {other_name})" if other else ""))
        fig.tight_layout()
        fig.savefig(out / "friction_laws_corners.png", dpi=110)
        print(f"figure: {out / 'friction_laws_corners.png'}")


if __name__ == "__main__":
    main()
