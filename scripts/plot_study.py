#!/usr/bin/python3
"""Pictures of `fieldpath study` (seed 004 Figs. 5-6) from the CSVs it writes.

Usage: /usr/bin/python3 plot_study.py DIR
Reads DIR/study.csv, DIR/lines.csv, DIR/tilt.csv; writes DIR/speed_vs_error.png,
DIR/force_error_lines.png, DIR/tilt_along_path.png (each to a temporary name, then renamed).
Exit 1 when matplotlib is missing (the caller says so and keeps the CSVs).
"""
import csv
import math
import os
import sys
import tempfile
from collections import OrderedDict

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    sys.stderr.write("plot_study.py: matplotlib is missing (apt-get install python3-matplotlib)\n")
    sys.exit(1)


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def positive(values):
    """Whether any value is a positive finite number (what a log scale can show)."""
    return any(v > 0 and math.isfinite(v) for v in values)


def num(text):
    try:
        return float(text)
    except ValueError:
        return math.nan


def save(fig, path):
    # A temporary of this process's own making (mkstemp: O_EXCL, a fresh name), renamed into
    # place: a fixed NAME.tmp.png was written through a link planted under that name.
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".",
                               suffix=".tmp.png", dir=os.path.dirname(path) or ".")
    try:
        with os.fdopen(fd, "wb") as out:
            fig.savefig(out, format="png", dpi=120, bbox_inches="tight")
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)  # as a file the user makes (mkstemp's is 0600)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    finally:
        plt.close(fig)


def colours(names):
    """One colour per variant, the same in every picture; the exact direct field in black."""
    palette = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    others = [n for n in names if n != "direct"]
    table = {n: palette[i % len(palette)] for i, n in enumerate(others)}
    table["direct"] = "k"
    return table


def grouped(rows, key):
    groups = OrderedDict()
    for row in rows:
        groups.setdefault(row[key], []).append(row)
    return groups


def speed_vs_error(study, out):
    """Total time against max force error, one point per variant, Pareto front marked."""
    fig, ax = plt.subplots(figsize=(7, 5))
    points = []
    exact_floor = None
    for row in study:
        err, t = num(row["max_force_error_pct"]), num(row["total_s"])
        points.append((row["variant"], err, t))
    exact = 1e-6  # %: float rounding between the two exact methods
    # A variant whose error was not measured (no point counted: an empty cell) has no place on
    # the error axis: left out and said (a field of gain 0 stopped the picture: log scale of NaN).
    unmeasured = [n for n, e, t in points if math.isnan(e) and not math.isnan(t)]
    points = [(n, e, t) for n, e, t in points if not math.isnan(e)]
    errs = [e for _, e, _ in points if e > exact]
    exact_floor = min(errs) / 10 if errs else 1e-3
    shown = [(n, max(e, exact_floor), t, e if e > exact else 0.0) for n, e, t in points if not math.isnan(t)]
    if unmeasured:
        ax.text(0.99, 0.01, "error not measured (no point counted): " + ", ".join(unmeasured),
                transform=ax.transAxes, ha="right", va="bottom", fontsize=7)
    # Pareto front: no other variant is both faster and more accurate.
    front = [p for p in shown
             if not any((q[2] <= p[2] and q[1] <= p[1]) and (q[2] < p[2] or q[1] < p[1]) for q in shown)]
    front.sort(key=lambda p: p[1])
    colour = colours([r["variant"] for r in study])
    # Each point numbered, the names in a key under the plot: long names written beside the
    # points overlapped each other and the axes where variants sit close (a build and its
    # reference at the same error).
    for k, (name, e, t, raw) in enumerate(shown, start=1):
        ratio = "plane_ratio" in name
        marker = "s" if raw <= 0 else {(False, False): "o", (True, False): "^", (False, True): "D",
                                       (True, True): "v"}[("quadratic" in name, ratio)]
        label = "%d  %s%s" % (k, name, " (exact)" if raw <= 0 else "")
        ax.scatter(e, t, marker=marker, s=50, zorder=3, color=colour[name], label=label)
        ax.annotate(str(k), (e, t), textcoords="offset points", xytext=(6, 3), fontsize=8)
    ax.plot([p[1] for p in front], [p[2] for p in front], "k--", lw=1, label="Pareto front", zorder=2)
    if shown:  # (log scales of nothing stop the picture)
        ax.set_xscale("log")
        ax.set_yscale("log")
    ax.set_xlabel("max relative force error, % (exact methods drawn at the left edge)")
    ax.set_ylabel("total time (field + path), s")
    ax.set_title("Speed against error (seed 004 Table 1-2)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="upper left", bbox_to_anchor=(0.0, -0.13), fontsize=8, frameon=False)
    save(fig, os.path.join(out, "speed_vs_error.png"))


def force_error_lines(lines, out, colour):
    """Relative error along line a and line b per voxel variant (like seed Fig. 5)."""
    fig, axes = plt.subplots(2, 2, figsize=(12, 8), sharex="col")
    for col, name in enumerate(["a", "b"]):
        rows = [r for r in lines if r["line"] == name]
        groups = grouped(rows, "variant")
        top, bottom = axes[0][col], axes[1][col]
        first = True
        for variant, vr in groups.items():
            t = [num(r["t_mm"]) for r in vr]
            if first:
                top.plot(t, [num(r["direct_force"]) for r in vr], "k-", lw=2, label="direct (exact)")
                first = False
            top.plot(t, [num(r["variant_force"]) for r in vr], lw=1, label=variant, color=colour[variant])
            bottom.plot(t, [100 * num(r["relative_error"]) for r in vr], lw=1, label=variant,
                        color=colour[variant])
        top.set_title("line %s: |F| along the line" % name)
        top.set_ylabel("|F|")
        peak = max([num(r["direct_force"]) for r in rows] + [1e-30])
        # Log scales only over positive values: a line of no points counted (a field of gain 0,
        # a line step longer than the line) stopped every picture after this one (a study sweep's).
        if positive([num(r["direct_force"]) for r in rows]):
            top.set_yscale("log")
            top.set_ylim(bottom=peak * 1e-4)
        bottom.set_title("line %s: relative error (counted points only)" % name)
        bottom.set_ylabel("|F_v - F_d| / |F_d|, %")
        if positive([num(r["relative_error"]) for r in rows]):
            bottom.set_yscale("log")
        else:
            bottom.text(0.5, 0.5, "no point of this line counted", transform=bottom.transAxes,
                        ha="center", va="center")
        bottom.set_xlabel("t along the line, mm")
        for ax in (top, bottom):
            ax.grid(True, which="both", alpha=0.3)
        top.legend(fontsize=7)
    fig.suptitle("Force error along the study lines (seed 004 Fig. 5)")
    save(fig, os.path.join(out, "force_error_lines.png"))


def tilt_along_path(tilt, out, colour):
    """Tilt of the middle pass against arc length per variant, and its difference (seed Fig. 6)."""
    groups = grouped(tilt, "variant")
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 7), sharex=True)
    direct = groups.get("direct")
    ref = [num(r["tilt_deg"]) for r in direct] if direct else None
    for variant, vr in groups.items():
        s = [num(r["s_mm"]) for r in vr]
        y = [num(r["tilt_deg"]) for r in vr]
        top.plot(s, y, "-", lw=2 if variant == "direct" else 1, label=variant, color=colour[variant])
        if ref and variant not in ("direct", "brute force"):
            bottom.plot(s, [a - b for a, b in zip(y, ref)], lw=1, label=variant, color=colour[variant])
    p = tilt[0]["pass"] if tilt else "?"
    top.set_title("Tilt along the middle pass (pass %s)" % p)
    top.set_ylabel("tilt, deg")
    bottom.set_ylabel("tilt - tilt(direct), deg")
    bottom.set_xlabel("arc length s, mm")
    for ax in (top, bottom):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("Influence of the voxels on the tool axis (seed 004 Fig. 6)")
    save(fig, os.path.join(out, "tilt_along_path.png"))


def main():
    if len(sys.argv) != 2:
        sys.stderr.write(__doc__)
        return 2
    out = sys.argv[1]
    study = read(os.path.join(out, "study.csv"))
    colour = colours([r["variant"] for r in study])
    speed_vs_error(study, out)
    force_error_lines(read(os.path.join(out, "lines.csv")), out, colour)
    tilt_along_path(read(os.path.join(out, "tilt.csv")), out, colour)
    return 0


if __name__ == "__main__":
    sys.exit(main())
