"""bench_iris: speed against error on the iris of scene B, the side-lit analytic eye with an independent reference.

Renders the scene with the real command line (`python -m eyerender.eyerecord`, two threads, each budget with two
seeds), compares every render with the scene's reference through its own compare.py (relative RMSE per iris pixel,
glint excluded; with two seeds the noise and the bias floor sqrt(mean(e1 e2)), the error both seeds share), and prints
a table: relative RMSE per budget (the mean of the two seeds), error x sqrt(seconds), samples per pixel reached, and
the floor at the longest budget. --markdown and --plot write the table and the figure docs/iris_benchmark.md shows.

Usage: python3 bench/bench_iris.py [--budgets 2.5,10] [--floor-spp N] [--scene-dir DIR] [--label NAME] [--csv FILE]
                                   [--plot FILE --from-csv A.csv,B.csv]
Default budgets 2.5 and 10 s (about 40 s of rendering); the published run is --budgets 2.5,10,40 --floor-spp 512
(about 5 min): at 40 s the noise (3-5 %) still hides a floor below 0.5 %, so the floor is measured on a pair of
fixed-sample renders, where the machine's load changes the time but not the error.
The scene directory defaults to $EYERENDER_SCENE_B or /work/shared/bench/sceneB (sceneB.usda, compare.py, the
reference). Times are wall-clock budgets of the progressive render on a shared machine: error x sqrt(s) is the
number to compare (it is constant for an unbiased estimator whose noise falls as 1/sqrt(time)).
"""
import argparse
import csv
import math
import os
import re
import subprocess
import sys
import tempfile

DEFAULT_SCENE_DIR = os.environ.get("EYERENDER_SCENE_B", "/work/shared/bench/sceneB")
# The interpreter whose eyerender package renders (--python: another build, e.g. main's, in its own venv).
PYTHON = sys.executable
FIELDS = ("label", "seconds", "relrmse", "relrmse_seed2", "noise", "floor", "bias", "spp", "err_sqrt_s")


def render(scene_dir, seconds, seed, out, spp=0):
    """One eyerecord render, `seconds` long or of `spp` samples per pixel; returns the samples per pixel it reached
    and the seconds it took (from its summary line)."""
    budget = ["--spp", str(spp)] if spp else ["--time-limit", str(seconds)]
    cmd = [PYTHON, "-m", "eyerender.eyerecord", "--camera", "/World/main_cam", "--imageWidth", "256",
           *budget, "--threads", "2", "--seed", str(seed), "--quiet", os.path.join(scene_dir, "sceneB.usda"), out]
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"bench_iris: eyerecord failed ({run.returncode}): {run.stderr.strip()[-200:]}")
    summary = re.search(r"(\d+) spp, ([0-9.]+) s", run.stdout + run.stderr)
    return (int(summary.group(1)), float(summary.group(2))) if summary else (0, 0.0)


def compare(scene_dir, a, b):
    """compare.py's numbers for two renders of different seeds, as a dict of floats."""
    run = subprocess.run([sys.executable, os.path.join(scene_dir, "compare.py"), a, b], capture_output=True, text=True)
    values = dict(re.findall(r"(\w+)=([-+0-9.eE]+)", run.stdout))
    if "floor" not in values:
        sys.exit(f"bench_iris: compare.py gave no numbers: {(run.stdout + run.stderr).strip()[-200:]}")
    second = subprocess.run([sys.executable, os.path.join(scene_dir, "compare.py"), b], capture_output=True, text=True)
    values["relRMSE2"] = re.search(r"relRMSE=([0-9.]+)", second.stdout).group(1)
    return {k: float(v) for k, v in values.items()}


def measure(scene_dir, budgets, label, floor_spp=0):
    """One row per time budget, then (floor_spp > 0) one of floor_spp samples per pixel, its time the median."""
    rows = []
    runs = [(seconds, 0) for seconds in budgets] + ([(0, floor_spp)] if floor_spp else [])
    with tempfile.TemporaryDirectory() as tmp:
        for seconds, spp in runs:
            paths = [os.path.join(tmp, f"b{seed}.exr") for seed in (1, 2)]
            done = [render(scene_dir, seconds, seed, p, spp) for seed, p in zip((1, 2), paths)]
            c = compare(scene_dir, *paths)
            err = 0.5 * (c["relRMSE"] + c["relRMSE2"])
            taken = seconds or 0.5 * (done[0][1] + done[1][1])
            rows.append(dict(label=label, seconds=taken, relrmse=c["relRMSE"], relrmse_seed2=c["relRMSE2"],
                             noise=c["noise"], floor=c["floor"], bias=c["bias"], spp=0.5 * (done[0][0] + done[1][0]),
                             err_sqrt_s=err * math.sqrt(taken)))
            print(f"  {label}: {f'{spp} spp' if spp else f'{seconds:g} s'} done (relRMSE {err:.4f})", file=sys.stderr)
    return rows


def table(rows):
    lines = ["| code | seconds | rel RMSE (seed 1 / 2) | noise | floor (two seeds) | mean bias | spp | error x sqrt(s) |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['label']} | {r['seconds']:g} | {100 * r['relrmse']:.2f} % / {100 * r['relrmse_seed2']:.2f} % "
                     f"| {100 * r['noise']:.2f} % | {100 * r['floor']:.2f} % | {100 * r['bias']:+.2f} % "
                     f"| {r['spp']:.0f} | {r['err_sqrt_s']:.3f} |")
    return "\n".join(lines)


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    for label in dict.fromkeys(r["label"] for r in rows):
        mine = [r for r in rows if r["label"] == label]
        s = [r["seconds"] for r in mine]
        ax.loglog(s, [50 * (r["relrmse"] + r["relrmse_seed2"]) for r in mine], "o-", label=f"{label}: rel RMSE")
        ax.loglog(s, [100 * r["floor"] for r in mine], "s--", label=f"{label}: two-seed floor")
    ax.set_xlabel("render time, s (2 threads)")
    ax.set_ylabel("% of the reference (iris pixels)")
    ax.set_title("Scene B iris: error against time")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--budgets", default="2.5,10", help="comma-separated render budgets, seconds")
    ap.add_argument("--scene-dir", default=DEFAULT_SCENE_DIR)
    ap.add_argument("--label", default="this build")
    ap.add_argument("--floor-spp", type=int, default=0,
                    help="also render both seeds at this many samples per pixel, for the bias floor (0: none)")
    ap.add_argument("--csv", help="write the rows to this CSV")
    ap.add_argument("--from-csv", help="comma-separated CSVs to read instead of rendering")
    ap.add_argument("--plot", help="write the figure to this PNG")
    ap.add_argument("--python", default=sys.executable, help="the Python whose eyerender package renders")
    args = ap.parse_args()
    global PYTHON
    PYTHON = args.python
    if args.from_csv:
        rows = []
        for path in args.from_csv.split(","):
            with open(path) as f:
                rows += [{k: (v if k == "label" else float(v)) for k, v in r.items()} for r in csv.DictReader(f)]
    else:
        if not os.path.isfile(os.path.join(args.scene_dir, "sceneB.usda")):
            sys.exit(f"bench_iris: no sceneB.usda in {args.scene_dir} (--scene-dir)")
        budgets = [float(b) for b in args.budgets.split(",") if b]
        rows = measure(args.scene_dir, budgets, args.label, args.floor_spp)
    print(table(rows))
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=FIELDS)
            w.writeheader()
            w.writerows(rows)
    if args.plot:
        plot(rows, args.plot)


if __name__ == "__main__":
    main()
