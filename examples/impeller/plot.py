#!/usr/bin/python3
"""Plots of the impeller example (run by run.sh): OUT/tilt.png, tilt, lead and nearest distance
along the path (angles.csv of OUT/field and OUT/nominal). deviation.png is written by
`fieldpath check` itself. Usage: plot.py OUT"""
import csv
import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_angles(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {key: [float(r[key]) for r in rows] for key in rows[0]}


def main():
    out = Path(sys.argv[1])
    field = read_angles(out / "field" / "angles.csv")
    nominal = read_angles(out / "nominal" / "angles.csv")
    required = json.loads((out / "field" / "report.json").read_text())["clearance"]["required_mm"]
    index = list(range(len(field["s_mm"])))

    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(11, 6.5), sharex=True)
    ax1.plot(index, field["tilt_deg"], label="tilt (field)")
    ax1.plot(index, field["lead_deg"], label="lead (field)")
    ax1.set_ylabel("angle, deg")
    ax1.legend(loc="upper right")
    ax1.grid(alpha=0.3)
    ax2.plot(index, field["nearest_mm"], label="field path")
    ax2.plot(index, nominal["nearest_mm"], label="nominal path", alpha=0.7)
    ax2.axhline(required, color="k", ls="--", lw=0.8, label=f"required {required} mm")
    ax2.set_ylabel("clearance (FCL), mm")
    ax2.set_xlabel("posture (passes 1 to 7 in order)")
    ax2.legend(loc="upper right")
    ax2.grid(alpha=0.3)
    passes = field["pass"]
    for i in range(1, len(passes)):
        if passes[i] != passes[i - 1]:
            for ax in (ax1, ax2):
                ax.axvline(i, color="grey", lw=0.5)
    fig.suptitle("Impeller channel: tool axis along the path and clearance to the blades")
    fig.tight_layout()
    tmp = out / "tilt.tmp.png"  # written then renamed: no truncated tilt.png (DESIGN.md)
    fig.savefig(tmp, dpi=110)
    tmp.replace(out / "tilt.png")


if __name__ == "__main__":
    main()
