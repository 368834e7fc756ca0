#!/usr/bin/env python3
"""Plots the speed-versus-error CSV of bench_mnee: relative RMSE of the iris irradiance map against
single-thread wall time, log-log, one panel per cornea model (rows) and sphere-light angle (columns),
one series per method (MNEE single-seed, MNEE all-solutions, path tracing), points labelled with
their samples per cell at powers of 16.

Solid lines: the measured rel RMSE against the light-tracing reference. Faint dashed lines: the same
with the reference's own variance subtracted (rel RMSE excess). The grey band is the reference's rms
relative noise: errors below it are not measurable. Dotted lines: 1, 2 and 5 % targets.

Usage: plot_mnee.py PREFIX|CONVERGENCE_CSV [PNG]   (PNG defaults to docs/mnee_benchmark.png)
        PREFIX as given to `bench_mnee --csv PREFIX` (reads PREFIX_convergence.csv), or that CSV's path.
"""
import csv
import sys
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

DEFAULT_PNG = Path(__file__).resolve().parent.parent / "docs" / "mnee_benchmark.png"
METHOD_STYLE = {
    "MNEE single-seed": ("tab:blue", "o"),
    "MNEE all-solutions": ("tab:green", "s"),
    "path tracing": ("tab:red", "^"),
}
TARGETS = [0.01, 0.02, 0.05]


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def main(argv):
    if len(argv) not in (2, 3):
        sys.exit(__doc__)
    source = argv[1] if argv[1].endswith(".csv") else argv[1] + "_convergence.csv"
    rows = read_rows(source)
    out = Path(argv[2]) if len(argv) == 3 else DEFAULT_PNG

    models = list(dict.fromkeys(r["model"] for r in rows))
    angles = list(dict.fromkeys(r["light_deg"] for r in rows))
    series = defaultdict(list)  # (model, angle, method) -> rows in file order (ascending spp)
    floors = {}
    for r in rows:
        series[(r["model"], r["light_deg"], r["method"])].append(r)
        floors[(r["model"], r["light_deg"])] = float(r["ref_rms_rel_sigma"])

    fig, axes = plt.subplots(len(models), len(angles), figsize=(6.2 * len(angles), 4.8 * len(models)),
                             squeeze=False, sharex=True, sharey=True)
    for a, model in enumerate(models):
        for b, angle in enumerate(angles):
            ax = axes[a][b]
            ax.set_xscale("log")
            ax.set_yscale("log")
            floor = floors[(model, angle)]
            ax.axhspan(1e-4, floor, color="0.85", zorder=0)
            ax.text(60, floor * 0.8, f"reference noise ({100 * floor:.2f} %)", fontsize=7, color="0.35",
                    va="top", ha="right")
            for t in TARGETS:
                ax.axhline(t, color="0.5", linewidth=0.6, linestyle=":")
                ax.text(2e-5, t * 1.05, f"{100 * t:.0f} %", fontsize=7, color="0.4")
            for method, (color, marker) in METHOD_STYLE.items():
                pts = series.get((model, angle, method), [])
                if not pts:
                    continue
                times = [float(p["seconds"]) for p in pts]
                rmse = [float(p["rel_rmse"]) for p in pts]
                excess = [max(float(p["rel_rmse_excess"]), 1e-4) for p in pts]
                ax.plot(times, rmse, color=color, marker=marker, markersize=3.5, linewidth=1.2, label=method)
                ax.plot(times, excess, color=color, linewidth=0.8, linestyle="--", alpha=0.5)
                for p, x, y in zip(pts, times, rmse):
                    spp = int(p["spp"])
                    if spp in (1, 16, 256, 4096, 65536) or p is pts[-1]:
                        ax.annotate(str(spp), (x, y), textcoords="offset points", xytext=(3, 4), fontsize=6.5,
                                    color=color)
            ax.set_xlim(1e-5, 100)
            ax.set_ylim(2e-3, 100)
            ax.set_title(f"{model}, sphere light at {angle}°", fontsize=10)
            ax.grid(True, which="major", linewidth=0.3)
            if a == len(models) - 1:
                ax.set_xlabel("wall time for the whole iris map, one thread (s)")
            if b == 0:
                ax.set_ylabel("relative RMSE vs light-tracing reference")
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", ncol=3, frameon=False)
    fig.suptitle("Iris irradiance (16 x 16 grid) from a 5 mm sphere light at 100 mm: error vs time "
                 "(labels: samples per cell; dashed: reference noise subtracted)", fontsize=10, y=0.955)
    fig.tight_layout(rect=(0, 0, 1, 0.94))
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=130)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(sys.argv)
