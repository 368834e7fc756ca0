"""bench_iris: speed against error on the iris of scene B, the side-lit analytic eye with an independent reference.

Renders the scene with the real command line (`python -m eyerender.cli.eyerecord`, two threads, each budget with two
seeds), compares every render with the scene's reference through its own compare.py (relative RMSE per iris pixel,
glint excluded; with two seeds the noise and the bias floor sqrt(mean(e1 e2)), the error both seeds share), and prints
a table: relative RMSE per budget (the mean of the two seeds), error x sqrt(seconds), samples per pixel reached, the
floor at the longest budget, and the relative RMSE with the corneal glint included (over the whole iris mask) and over
the glint's own pixels, as a markdown table. --plot writes the figure docs/iris_benchmark.md shows.

Usage: python3 bench/bench_iris.py [--budgets 2.5,10] [--floor-spp N] [--build LABEL=PYTHON ...]
                                   [--lever "LABEL=EYERECORD FLAGS" ...] [--scene-dir DIR]
                                   [--estimators path,cache,controlVariate] [--grazing DEGREES] [--key-noise A,B]
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
--estimators renders every build with each chamber-light estimator (eyerecord --chamber-estimator), interleaved.
--grazing D also measures a variant of scene B whose key is D degrees off the gaze (same azimuth and distance), 128
pixels wide, where chamber light is all the light the shadowed part of the iris gets: its reference is the path
estimator at --grazing-reference-spp (two seeds), the shadow is where a first-order render (the chamber walk cut after
the iris bounce's exit) is below 1 % of the iris median, and the table gives each estimator's relative RMSE there and
over the iris (about 3 min at the defaults, on top of the scene B rows).
--key-noise A,B measures, per build and budget, the noise of one render over the iris (two seeds) at scene B's full
size with the key moved to each angle: the issue's hidden scenes, at 50 and 75 degrees, have no reference here, so
this is their noise alone (their bias: the --grazing rows).
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
          "pixels", "msamples_per_s", "with_glint", "glint")
IMAGE_PIXELS = 256 * 256


def render(python, scene_dir, seconds, seed, out, spp=0, extra=(), scene="sceneB.usda", width=256):
    """One eyerecord render by `python`'s eyerender, `seconds` long or of `spp` samples per pixel, with the extra
    eyerecord arguments `extra`; returns the samples per pixel it reached and the seconds it took (from its summary
    line)."""
    budget = ["--spp", str(spp)] if spp else ["--time-limit", str(seconds)]
    cmd = [python, "-m", "eyerender.cli.eyerecord", "--camera", "/World/main_cam", "--imageWidth", str(width),
           *budget, "--threads", "2", "--seed", str(seed), "--quiet", *extra, os.path.join(scene_dir, scene), out]
    run = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if run.returncode != 0:
        sys.exit(f"bench_iris: eyerecord failed ({run.returncode}): {run.stderr.strip()[-200:]}")
    summary = re.search(r"(\d+) spp, ([0-9.]+) s", run.stdout + run.stderr)
    return (int(summary.group(1)), float(summary.group(2))) if summary else (0, 0.0)


def compare(scene_dir, a, b):
    """compare.py's numbers for two renders of different seeds, as a dict of floats; for a scene directory without
    a compare.py (scene C), the same numbers computed here from its reference.npy and mask.npy."""
    script = os.path.join(scene_dir, "compare.py")
    if not os.path.isfile(script):
        return compare_here(scene_dir, a, b)
    run = subprocess.run([sys.executable, script, a, b], capture_output=True, text=True, check=False)
    values = dict(re.findall(r"(\w+)=([-+0-9.eE]+)", run.stdout))
    if "floor" not in values:
        sys.exit(f"bench_iris: compare.py gave no numbers: {(run.stdout + run.stderr).strip()[-200:]}")
    second = subprocess.run([sys.executable, script, b], capture_output=True, text=True, check=False)
    values["relRMSE2"] = re.search(r"relRMSE=([0-9.]+)", second.stdout).group(1)
    return {k: float(v) for k, v in values.items()}


def compared_pixels(scene_dir):
    """compare.py's pixels: (the reference, float64 (h, w); the mask of pixels whose footprint is all albedo-0.5
    annulus (mask channel 2) minus the glint (the reference over 20 x the iris median, grown by 3 pixels))."""
    import numpy as np
    ref = np.load(os.path.join(scene_dir, "reference.npy")).astype(np.float64)
    iris = np.load(os.path.join(scene_dir, "mask.npy"))[..., 2] == 1
    bright = ref > 20 * np.median(ref[iris])
    glint = bright.copy()
    for dy in range(-3, 4):
        for dx in range(-3, 4):
            glint |= np.roll(np.roll(bright, dy, 0), dx, 1)
    return ref, iris & ~glint & (ref > 0)


def compare_here(scene_dir, a, b):
    """compare.py's numbers, computed here over compared_pixels: relative errors per pixel."""
    import numpy as np
    ref, sel = compared_pixels(scene_dir)
    e1, e2 = ((load_exr(p)[sel] - ref[sel]) / ref[sel] for p in (a, b))
    return {"relRMSE": float(np.sqrt(np.mean(e1 ** 2))), "relRMSE2": float(np.sqrt(np.mean(e2 ** 2))),
            "bias": float(e1.mean()), "pixels": float(sel.sum()), "noise": float(np.sqrt(np.mean((e1 - e2) ** 2) / 2)),
            "floor": float(np.sqrt(max(np.mean(e1 * e2), 0.0)))}


def glint_included(scene_dir, paths):
    """The relative RMSE over the whole iris mask with the corneal glint (every pixel compare.py counts and the
    glint's), and over the glint's own pixels (the reference above 20x the iris median, not grown), each the mean over
    the renders `paths`."""
    import numpy as np
    ref = np.load(os.path.join(scene_dir, "reference.npy")).astype(np.float64)
    iris = np.load(os.path.join(scene_dir, "mask.npy"))[..., 2] == 1
    whole, glint = iris & (ref > 0), ref > 20 * np.median(ref[iris])
    errors = [(load_exr(p) - ref) / np.where(ref > 0, ref, 1) for p in paths]
    return tuple(float(np.mean([np.sqrt(np.mean(e[m] ** 2)) for e in errors])) for m in (whole, glint))


def measure(scene_dir, budgets, builds, floor_spp=0, keep_dir=None, floor_labels=None, scene="sceneB.usda"):
    """One row per build and time budget, then (floor_spp > 0) one per build of floor_spp samples per pixel, its time
    the mean of the two seeds'. builds: (label, python) pairs, rendered in turn at every budget and seed so that the
    machine's changing load falls on all of them alike. A build may carry a third element, its eyerecord
    flags (a lever, an estimator).
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
                    out = os.path.join(tmp, f"{scene[:-5]}_build{k}_{budget}_seed{seed}.exr")
                    done[k, seed] = (out, *render(python, scene_dir, seconds, seed, out, spp, flags, scene))
            for k in chosen:
                label = builds[k][0]
                (a, spp1, s1), (b, spp2, s2) = done[k, 1], done[k, 2]
                c = compare(scene_dir, a, b)
                err = 0.5 * (c["relRMSE"] + c["relRMSE2"])
                with_glint, glint = glint_included(scene_dir, (a, b))
                taken = seconds or 0.5 * (s1 + s2)
                rows.append({"label": label, "fixed_spp": spp, "seconds": taken, "relrmse": c["relRMSE"],
                             "relrmse_seed2": c["relRMSE2"], "noise": c["noise"], "floor": c["floor"],
                             "bias": c["bias"], "spp": 0.5 * (spp1 + spp2), "err_sqrt_s": err * math.sqrt(taken),
                             "pixels": c["pixels"],
                             "msamples_per_s": (spp1 + spp2) * IMAGE_PIXELS / max(s1 + s2, 1e-9) / 1e6,
                             "with_glint": with_glint, "glint": glint})
                budget = f"{spp} spp" if spp else f"{seconds:g} s"
                print(f"  {label}: {budget} done (relRMSE {err:.4f})", file=sys.stderr)
    return rows


GRAZING_WIDTH = 128  # pixels: a quarter of scene B's, so that the path reference takes about a minute per seed
# A first-order render for the shadow mask: the chamber walk ends at its second event (the iris bounce's exit), so no
# light that reflected inside the chamber reaches the image.
FIRST_ORDER = """
import sys
import numpy as np
from pxr import Usd
from eyerender.plan import make_overrides
from eyerender.render_session import RenderSession
session = RenderSession(Usd.Stage.Open(sys.argv[1]), width=int(sys.argv[2]), camera="/World/main_cam",
                        settings={"threads": 2, "seed": 9, "chamber_estimator": "path"},
                        plan_overrides=make_overrides(chamber_events=2))
session.render(spp=int(sys.argv[3]))
np.save(sys.argv[4], session.image("color")[..., :3].mean(-1))
"""


def write_grazing_scene(scene_dir, degrees, out_dir):
    """Scene B with its key moved to `degrees` off the gaze at the same azimuth (200 degrees) and distance (100 mm);
    returns the file's name in out_dir."""
    with open(os.path.join(scene_dir, "sceneB.usda")) as f:
        text = f.read()
    a, phi = math.radians(degrees), math.radians(200)
    position = f"({100 * math.sin(a) * math.cos(phi):.9f}, {100 * math.sin(a) * math.sin(phi):.9f}, " \
               f"{100 * math.cos(a):.9f})"
    moved, n = re.subn(r'(def SphereLight "Key".*?double3 xformOp:translate = )\([^)]*\)',
                       lambda m: m.group(1) + position, text, count=1, flags=re.DOTALL)
    if n != 1:
        sys.exit("bench_iris: sceneB.usda has no SphereLight Key with a translate to move")
    name = f"sceneB_key{degrees:g}.usda"
    with open(os.path.join(out_dir, name), "w") as f:
        f.write(moved)
    return name


def load_exr(path):
    """An EXR's grey value (the mean of R, G, B), float64 (height, width)."""
    import numpy as np
    import OpenEXR
    with OpenEXR.File(path) as f:
        ch = f.channels()
        key = "RGBA" if "RGBA" in ch else "RGB"
        return np.asarray(ch[key].pixels, dtype=np.float64)[..., :3].mean(-1)


def measure_grazing(scene_dir, degrees, budgets, builds, reference_spp, keep_dir=None):
    """The grazing variant's rows: per build and budget, the relative RMSE (mean of two seeds) over the shadowed iris
    and over the whole iris, against the first build's path estimator at reference_spp (two seeds averaged)."""
    import numpy as np
    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        tmp = keep_dir or scratch
        scene = write_grazing_scene(scene_dir, degrees, tmp)
        python = builds[0][1]
        refs = []
        for seed in (101, 102):
            out = os.path.join(tmp, f"grazing_reference_seed{seed}.exr")
            render(python, tmp, 0, seed, out, reference_spp, ("--chamber-estimator", "path"), scene, GRAZING_WIDTH)
            refs.append(load_exr(out))
            print(f"  grazing reference seed {seed} done", file=sys.stderr)
        first_path = os.path.join(tmp, "grazing_first_order.npy")
        run = subprocess.run([python, "-c", FIRST_ORDER, os.path.join(tmp, scene), str(GRAZING_WIDTH), "64",
                              first_path], capture_output=True, text=True, check=False)
        if run.returncode != 0:
            sys.exit(f"bench_iris: the first-order render failed: {run.stderr.strip()[-200:]}")
        first = np.load(first_path)
        ref = 0.5 * (refs[0] + refs[1])
        # Scene B's iris mask (256 px), a pixel here where its whole 2 x 2 block is iris; the glint as compare.py
        # excludes it.
        full = np.load(os.path.join(scene_dir, "mask.npy"))[..., 2] == 1
        iris = full.reshape(GRAZING_WIDTH, 2, GRAZING_WIDTH, 2).all(axis=(1, 3))
        median = np.median(ref[iris])
        sel = iris_selection(ref, iris)
        shadow = sel & (first < 0.01 * median)
        def rms(x):  # nan for an empty selection (a key that leaves no iris pixel in shadow), without a warning
            return float(np.sqrt(np.mean(x ** 2))) if x.size else float("nan")

        ref_noise = {name: rms((refs[0][m] - refs[1][m]) / (2 * ref[m]))
                     for name, m in (("shadow", shadow), ("iris", sel))}
        print(f"  grazing: {int(shadow.sum())} shadowed of {int(sel.sum())} iris pixels; reference noise "
              f"{100 * ref_noise['shadow']:.2f} % (shadow) / {100 * ref_noise['iris']:.2f} % (iris)", file=sys.stderr)
        for seconds in budgets:
            done = {}
            for seed in (1, 2):
                for k, (_, python_k, *extra) in enumerate(builds):
                    out = os.path.join(tmp, f"grazing_build{k}_{seconds:g}s_seed{seed}.exr")
                    spp, _ = render(python_k, tmp, seconds, seed, out, 0, *extra, scene=scene, width=GRAZING_WIDTH)
                    done[k, seed] = (load_exr(out), spp)
            for k, (label, *_) in enumerate(builds):
                errors = {}
                for name, m in (("shadow", shadow), ("iris", sel)):
                    errors[name] = [rms((done[k, seed][0][m] - ref[m]) / ref[m]) for seed in (1, 2)]
                rows.append({"label": label, "seconds": seconds, "shadow": errors["shadow"], "iris": errors["iris"],
                             "spp": 0.5 * (done[k, 1][1] + done[k, 2][1]), "shadow_pixels": int(shadow.sum()),
                             "ref_noise_shadow": ref_noise["shadow"], "ref_noise_iris": ref_noise["iris"]})
                print(f"  grazing {label}: {seconds:g} s done", file=sys.stderr)
    return rows


def iris_selection(ref, iris):
    """The iris pixels compare.py would score in an image without a reference of its own: `iris` minus the glint
    (pixels over 20 x the iris median and their neighbours) and unlit pixels."""
    import numpy as np
    median = np.median(ref[iris])
    bright = ref > 20 * median
    glint = bright.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            glint |= np.roll(np.roll(bright, dy, 0), dx, 1)
    return iris & ~glint & (ref > 0)


def measure_key_noise(scene_dir, angles, budgets, builds, keep_dir=None):
    """Per key angle, build and budget: the noise of one render over the iris at scene B's full size with its key
    moved (write_grazing_scene), from two seeds, rms((a - b) / (sqrt 2 (a + b) / 2)). No reference, so no bias: the
    grazing rows bound that."""
    import numpy as np
    rows = []
    iris = np.load(os.path.join(scene_dir, "mask.npy"))[..., 2] == 1
    with tempfile.TemporaryDirectory() as scratch:
        tmp = keep_dir or scratch
        for degrees in angles:
            scene = write_grazing_scene(scene_dir, degrees, tmp)
            for seconds in budgets:
                for k, (label, python, *extra) in enumerate(builds):
                    images, spp = [], []
                    for seed in (1, 2):
                        out = os.path.join(tmp, f"key{degrees:g}_build{k}_{seconds:g}s_seed{seed}.exr")
                        n, _ = render(python, tmp, seconds, seed, out, 0, *extra, scene=scene)
                        images.append(load_exr(out)), spp.append(n)
                    a, b = images
                    mean = 0.5 * (a + b)
                    sel = iris_selection(mean, iris)
                    noise = float(np.sqrt(np.mean(((a[sel] - b[sel]) / (math.sqrt(2) * mean[sel])) ** 2)))
                    rows.append({"label": label, "degrees": degrees, "seconds": seconds, "noise": noise,
                                 "spp": 0.5 * (spp[0] + spp[1]), "pixels": int(sel.sum())})
                    print(f"  key {degrees:g} deg, {label}: {seconds:g} s done", file=sys.stderr)
    return rows


def key_noise_table(rows):
    lines = ["| code | key off the gaze | budget | noise of one render over the iris | spp |", "|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['label']} | {r['degrees']:g} deg | {r['seconds']:g} s | {100 * r['noise']:.2f} % "
                     f"| {r['spp']:.0f} |")
    return "\n".join(lines)


def grazing_table(rows, degrees):
    lines = [f"| code (key {degrees:g} deg off the gaze) | budget | rel RMSE, shadowed iris (seed 1 / 2) "
             "| rel RMSE, iris (seed 1 / 2) | spp |", "|---|---|---|---|---|"]
    for r in rows:
        shadow, iris = r["shadow"], r["iris"]
        shadowed = f"{100 * shadow[0]:.2f} % / {100 * shadow[1]:.2f} %" if r["shadow_pixels"] else "(no shadow)"
        lines.append(f"| {r['label']} | {r['seconds']:g} s | {shadowed} "
                     f"| {100 * iris[0]:.2f} % / {100 * iris[1]:.2f} % | {r['spp']:.0f} |")
    if rows:
        lines.append(f"\n{rows[0]['shadow_pixels']} shadowed pixels; the reference's own noise "
                     f"{100 * rows[0]['ref_noise_shadow']:.2f} % there, {100 * rows[0]['ref_noise_iris']:.2f} % over "
                     "the iris (it is in every error above).")
    return "\n".join(lines)


def table(rows):
    lines = ["| code | budget | seconds | rel RMSE (seed 1 / 2) | noise | floor (two seeds) | mean bias | spp "
             "| error x sqrt(s) | M samples/s | glint included | the glint's pixels |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        budget = f"{r['fixed_spp']:.0f} spp" if r.get("fixed_spp") else f"{r['seconds']:g} s"
        lines.append(f"| {r['label']} | {budget} | {r['seconds']:.1f} "
                     f"| {100 * r['relrmse']:.2f} % / {100 * r['relrmse_seed2']:.2f} % "
                     f"| {100 * r['noise']:.2f} % | {100 * r['floor']:.2f} % | {100 * r['bias']:+.2f} % "
                     f"| {r['spp']:.0f} | {r['err_sqrt_s']:.3f} | {float(r.get('msamples_per_s') or 0):.2f} "
                     f"| {100 * float(r.get('with_glint') or 0):.2f} % | {100 * float(r.get('glint') or 0):.2f} % |")
    return "\n".join(lines)


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker
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
    # Seconds as plain numbers at the budgets (log-scale minor labels overlap on a short axis).
    seconds = sorted({r["seconds"] for r in rows if not r.get("fixed_spp")})
    ax.set_xticks(seconds, [f"{t:g}" for t in seconds])
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
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
    ap.add_argument("--estimators", help="comma-separated chamber-light estimators to render every build with "
                    "(path, cache, controlVariate; default: the renderer's default alone)")
    ap.add_argument("--grazing", type=float, default=0,
                    help="also measure scene B with its key this many degrees off the gaze (0: not)")
    ap.add_argument("--grazing-reference-spp", type=int, default=512,
                    help="samples per pixel of the grazing variant's path reference, each of two seeds")
    ap.add_argument("--key-noise", help="comma-separated key angles (degrees off the gaze): also measure the noise "
                    "of one render over the iris at scene B's 256 px with its key moved there, per build and budget")
    ap.add_argument("--scene-c", metavar="DIR", help="also measure scene C (made by bench/scene_c.py DIR) at the "
                    "same budgets and floor, in a second table")
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
        if args.estimators:
            estimators = [e for e in args.estimators.split(",") if e]
            single = len(builds) == 1 and not args.build and not args.lever
            builds = [(e if single else f"{label}, {e}", python, (*flags, "--chamber-estimator", e))
                      for label, python, *rest in builds for flags in [rest[0] if rest else ()] for e in estimators]
        if args.keep_dir:
            os.makedirs(args.keep_dir, exist_ok=True)
        floor_labels = set(args.floor_levers.split(",")) if args.floor_levers else None
        rows = measure(args.scene_dir, budgets, builds, args.floor_spp, args.keep_dir, floor_labels) \
            if budgets or args.floor_spp else []
        if args.scene_c:
            scene_c = measure(args.scene_c, budgets, builds, args.floor_spp, args.keep_dir, floor_labels, "sceneC.usda")
        if args.grazing:
            grazing = measure_grazing(args.scene_dir, args.grazing, budgets, builds, args.grazing_reference_spp,
                                      args.keep_dir)
        if args.key_noise:
            key_noise = measure_key_noise(args.scene_dir, [float(a) for a in args.key_noise.split(",") if a],
                                          budgets, builds, args.keep_dir)
    print(table(rows))
    if not args.from_csv and args.scene_c:
        print("\nScene C (rect key, textured dome, small fill):\n")
        print(table(scene_c))
    if not args.from_csv and args.key_noise:
        print()
        print(key_noise_table(key_noise))
    if not args.from_csv and args.grazing:
        print()
        print(grazing_table(grazing, args.grazing))
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=FIELDS)
            w.writeheader()
            w.writerows(rows)
    if args.plot:
        plot(rows, args.plot)


if __name__ == "__main__":
    main()
