#!/usr/bin/env python3
"""Plots the CSV of bench_intersect: time per ray (ns) against hit-position error (micrometres),
log-log, one series per cornea model and method; Embree points are labelled with their ring count.

Left panel: worst position error; right panel: 99th percentile (the worst case is set by rays within
a degree of grazing, where any surface approximation moves the hit far along the ray).
The double analytic method is the reference, so its error is 0; it is drawn on the bottom edge.

Usage: plot_intersect.py CSV [PNG]   (PNG defaults to docs/intersection_benchmark.png)
"""
import csv
import sys
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import NullFormatter, ScalarFormatter  # noqa: E402

DEFAULT_PNG = Path(__file__).resolve().parent.parent / "docs" / "intersection_benchmark.png"
ERROR_COLUMNS = [("pos_err_max_um", "worst hit-position error (µm)"),
                 ("pos_err_p99_um", "99th percentile hit-position error (µm)")]
MODEL_COLORS = {"ellipsoidCone": "tab:blue", "paraboloid": "tab:orange"}
METHOD_MARKERS = {"analytic float": "s", "analytic double": "D", "embree rtcIntersect1": "o"}


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def group_series(rows):
    """(model, method) -> rows in file order (Embree rows ascend in ring count)."""
    series = defaultdict(list)
    for row in rows:
        series[(row["model"], row["method"])].append(row)
    return series


def zero_floor(rows, column):
    """A value below every positive error, where zero errors are drawn on a log axis."""
    positive = [float(r[column]) for r in rows if float(r[column]) > 0]
    return min(positive) / 10 if positive else 1e-6


def plot_panel(ax, series, column, label, floor):
    ax.set_xscale("log")
    ax.set_yscale("log")
    for (model, method), rows in series.items():
        errors = [max(float(r[column]), floor) for r in rows]
        times = [float(r["ns_per_ray"]) for r in rows]
        ax.plot(errors, times, marker=METHOD_MARKERS.get(method, "x"), color=MODEL_COLORS.get(model),
                linestyle="-" if len(rows) > 1 else "none", label=f"{model}, {method}")
        for row, x, y in zip(rows, errors, times):
            if row["tessellation"]:
                ax.annotate(row["tessellation"].split(" x ")[0], (x, y), textcoords="offset points",
                            xytext=(4, 4), fontsize=7, color=MODEL_COLORS.get(model))
    ax.axvline(floor, color="grey", linewidth=0.5, linestyle=":")
    ax.text(floor, ax.get_ylim()[1], "error 0 (reference) ", rotation=90, fontsize=7, color="grey",
            ha="right", va="top")
    ax.yaxis.set_major_formatter(ScalarFormatter())
    ax.yaxis.set_minor_formatter(NullFormatter())
    ax.set_yticks([100, 150, 200, 300, 400, 600, 800])
    ax.set_xlabel(label)
    ax.set_ylabel("median time per ray, one thread (ns)")
    ax.grid(True, which="both", linewidth=0.3)


def main(argv):
    if len(argv) not in (2, 3):
        sys.exit(__doc__)
    rows = read_rows(argv[1])
    out = Path(argv[2]) if len(argv) == 3 else DEFAULT_PNG
    series = group_series(rows)
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.5))
    for ax, (column, label) in zip(axes, ERROR_COLUMNS):
        plot_panel(ax, series, column, label, zero_floor(rows, column))
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=8, frameon=False)
    fig.suptitle("Ray / anterior-surface intersection: speed vs accuracy "
                 "(Embree points labelled with mesh rings N; N x 4N grid)")
    fig.tight_layout(rect=(0, 0.1, 1, 1))
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(sys.argv)
