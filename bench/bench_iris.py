"""bench_iris: speed against error on the iris of scene B, the side-lit analytic eye with an independent reference.

Renders the scene with the real command line (`python -m eyerender.eyerecord`, two threads, each budget with two
seeds), compares every render with the scene's reference through its own compare.py (relative RMSE per iris pixel,
glint excluded; with two seeds the noise and the bias floor sqrt(mean(e1 e2)), the error both seeds share), and prints
a table: relative RMSE per budget (the mean of the two seeds), error x sqrt(seconds), samples per pixel reached, and
the floor at the longest budget. --markdown and --plot write the table and the figure docs/iris_benchmark.md shows.

Usage: python3 bench/bench_iris.py [--budgets 2.5,10] [--floor-spp N] [--build LABEL=PYTHON ...]
                                   [--lever "LABEL=EYERECORD FLAGS" ...] [--scene-dir DIR]
                                   [--csv FILE] [--plot FILE] [--from-csv A.csv,B.csv]
--lever measures this build with extra eyerecord flags (the sampler, splitting), for example
    --lever "independent=--sampler independent" --lever "zsobol=--sampler zsobol"
    --lever "zsobol+chamber2=--sampler zsobol --chamber-splits 2"
levers and builds render in turn, interleaved, like builds.
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
SCENE_B_PIXELS = 32879  # the iris pixels compare.py counts (its pixels=), for CSVs that do not record them
FIELDS = ("label", "fixed_spp", "seconds", "relrmse", "relrmse_seed2", "noise", "floor", "bias", "spp", "err_sqrt_s",
          "pixels", "msamples_per_s")
IMAGE_PIXELS = 256 * 256


def render(python, scene_dir, seconds, seed, out, spp=0, flags=()):
    """One eyerecord render by `python`'s eyerender (with the extra eyerecord `flags`), `seconds` long or of `spp`
    samples per pixel; returns the samples per pixel it reached and the seconds it took (from its summary line)."""
    budget = ["--spp", str(spp)] if spp else ["--time-limit", str(seconds)]
    cmd = [python, "-m", "eyerender.eyerecord", "--camera", "/World/main_cam", "--imageWidth", "256",
           *budget, "--threads", "2", "--seed", str(seed), "--quiet", *flags, os.path.join(scene_dir, "sceneB.usda"),
           out]
    run = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if run.returncode != 0:
        sys.exit(f"bench_iris: eyerecord failed ({run.returncode}): {run.stderr.strip()[-200:]}")
    summary = re.search(r"(\d+) spp, ([0-9.]+) s", run.stdout + run.stderr)
    return (int(summary.group(1)), float(summary.group(2))) if summary else (0, 0.0)


def compare(scene_dir, a, b):
    """compare.py's numbers for two renders of different seeds, as a dict of floats."""
    script = os.path.join(scene_dir, "compare.py")
    run = subprocess.run([sys.executable, script, a, b], capture_output=True, text=True, check=False)
    values = dict(re.findall(r"(\w+)=([-+0-9.eE]+)", run.stdout))
    if "floor" not in values:
        sys.exit(f"bench_iris: compare.py gave no numbers: {(run.stdout + run.stderr).strip()[-200:]}")
    second = subprocess.run([sys.executable, script, b], capture_output=True, text=True, check=False)
    values["relRMSE2"] = re.search(r"relRMSE=([0-9.]+)", second.stdout).group(1)
    return {k: float(v) for k, v in values.items()}


def measure(scene_dir, budgets, builds, floor_spp=0, keep_dir=None, floor_labels=None):
    """One row per build and time budget, then (floor_spp > 0) one per build of floor_spp samples per pixel, its time
    the mean of the two seeds'. builds: (label, python) pairs, rendered in turn at every budget and seed so that the
    machine's changing load falls on all of them alike. A build may carry a third element, eyerecord flags (a lever).
    floor_labels: the labels that render the floor pair (None: all)."""
    rows = []
    runs = [(seconds, 0) for seconds in budgets] + ([(0, floor_spp)] if floor_spp else [])
    with tempfile.TemporaryDirectory() as scratch:
        tmp = keep_dir or scratch
        for seconds, spp in runs:
            done = {}
            chosen = [k for k, b in enumerate(builds) if not spp or floor_labels is None or b[0] in floor_labels]
            for seed in (1, 2):
                for k in chosen:
                    python, flags = builds[k][1], builds[k][2] if len(builds[k]) > 2 else ()
                    budget = f"{spp}spp" if spp else f"{seconds:g}s"
                    out = os.path.join(tmp, f"build{k}_{budget}_seed{seed}.exr")
                    done[k, seed] = (out, *render(python, scene_dir, seconds, seed, out, spp, flags))
            for k in chosen:
                label = builds[k][0]
                (a, spp1, s1), (b, spp2, s2) = done[k, 1], done[k, 2]
                c = compare(scene_dir, a, b)
                err = 0.5 * (c["relRMSE"] + c["relRMSE2"])
                taken = seconds or 0.5 * (s1 + s2)
                rows.append({"label": label, "fixed_spp": spp, "seconds": taken, "relrmse": c["relRMSE"],
                             "relrmse_seed2": c["relRMSE2"], "noise": c["noise"], "floor": c["floor"],
                             "bias": c["bias"], "spp": 0.5 * (spp1 + spp2), "err_sqrt_s": err * math.sqrt(taken),
                             "pixels": c["pixels"],
                             "msamples_per_s": (spp1 + spp2) * IMAGE_PIXELS / max(s1 + s2, 1e-9) / 1e6})
                budget = f"{spp} spp" if spp else f"{seconds:g} s"
                print(f"  {label}: {budget} done (relRMSE {err:.4f})", file=sys.stderr)
    return rows


def table(rows):
    lines = ["| code | budget | seconds | rel RMSE (seed 1 / 2) | noise | floor (two seeds) | mean bias | spp "
             "| error x sqrt(s) | M samples/s |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        budget = f"{r['fixed_spp']:.0f} spp" if r.get("fixed_spp") else f"{r['seconds']:g} s"
        lines.append(f"| {r['label']} | {budget} | {r['seconds']:.1f} "
                     f"| {100 * r['relrmse']:.2f} % / {100 * r['relrmse_seed2']:.2f} % "
                     f"| {100 * r['noise']:.2f} % | {100 * r['floor']:.2f} % | {100 * r['bias']:+.2f} % "
                     f"| {r['spp']:.0f} | {r['err_sqrt_s']:.3f} | {float(r.get('msamples_per_s') or 0):.2f} |")
    return "\n".join(lines)


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    for label in dict.fromkeys(r["label"] for r in rows):
        timed = [r for r in rows if r["label"] == label and not r.get("fixed_spp")] or \
            [r for r in rows if r["label"] == label]
        errors = [50 * (r["relrmse"] + r["relrmse_seed2"]) for r in timed]
        line, = ax.loglog([r["seconds"] for r in timed], errors, "o-", label=f"{label}: rel RMSE")
        # Floors from the fixed-sample pairs only (at a few seconds the noise makes them meaningless). A floor of 0
        # (the seeds share no error) is drawn at what the pair resolves: 2 sigma of mean(e1 e2), noise^2 / sqrt(N).
        for r in rows:
            if r["label"] != label or not r.get("fixed_spp"):
                continue
            resolved = r["noise"] * math.sqrt(2) / (r.get("pixels") or SCENE_B_PIXELS) ** 0.25
            if r["floor"] > 0:
                ax.loglog([r["seconds"]], [100 * r["floor"]], "s", color=line.get_color(), markersize=9,
                          label=f"{label}: floor at {r['fixed_spp']:.0f} spp")
            else:
                ax.loglog([r["seconds"]], [100 * resolved], "v", color=line.get_color(), markersize=9,
                          label=f"{label}: floor at {r['fixed_spp']:.0f} spp below this")
    ax.set_xlabel("render time, s (2 threads)")
    ax.set_ylabel("% of the reference (iris pixels)")
    ax.set_ylim(bottom=0.05)
    ax.set_title("Scene B iris: error against time")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--budgets", default="2.5,10", help="comma-separated render budgets, seconds")
    ap.add_argument("--scene-dir", default=DEFAULT_SCENE_DIR)
    ap.add_argument("--build", action="append", metavar="LABEL=PYTHON",
                    help="a build to measure: a label and the Python whose eyerender package renders (repeatable, "
                         "for example main's in its own venv; default: this Python's, as 'this build')")
    ap.add_argument("--lever", action="append", metavar="LABEL=FLAGS",
                    help="measure this Python's build with extra eyerecord flags, e.g. \"zsobol=--sampler zsobol\" "
                         "(repeatable; rendered in turn with the builds)")
    ap.add_argument("--floor-levers", help="comma-separated labels that render the floor pair (default: all)")
    ap.add_argument("--floor-spp", type=int, default=0,
                    help="also render both seeds at this many samples per pixel, for the bias floor (0: none)")
    ap.add_argument("--csv", help="write the rows to this CSV")
    ap.add_argument("--keep-dir", help="keep the renders in this folder (default: a temporary one)")
    ap.add_argument("--from-csv", help="comma-separated CSVs to read instead of rendering")
    ap.add_argument("--plot", help="write the figure to this PNG")
    args = ap.parse_args()
    if args.from_csv:
        rows = []
        for path in args.from_csv.split(","):
            with open(path) as f:
                rows += [{k: (v if k == "label" else float(v or 0)) for k, v in r.items()} for r in csv.DictReader(f)]
    else:
        if not os.path.isfile(os.path.join(args.scene_dir, "sceneB.usda")):
            sys.exit(f"bench_iris: no sceneB.usda in {args.scene_dir} (--scene-dir)")
        budgets = [float(b) for b in args.budgets.split(",") if b]
        default = [] if args.lever else [f"this build={sys.executable}"]
        builds = [tuple(b.split("=", 1)) for b in args.build or default]
        if not all(len(b) == 2 and b[1] for b in builds):
            sys.exit("bench_iris: --build takes LABEL=PYTHON")
        for lever in args.lever or []:
            label, _, flags = lever.partition("=")
            if not label:
                sys.exit("bench_iris: --lever takes LABEL=FLAGS")
            builds.append((label, sys.executable, tuple(flags.split())))
        if args.keep_dir:
            os.makedirs(args.keep_dir, exist_ok=True)
        floor_labels = set(args.floor_levers.split(",")) if args.floor_levers else None
        rows = measure(args.scene_dir, budgets, builds, args.floor_spp, args.keep_dir, floor_labels)
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
