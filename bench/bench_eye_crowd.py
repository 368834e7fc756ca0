"""bench_eye_crowd: what a crowd of eyes costs per frame, by the number of eyes and the chamber-light estimator.

Authors a stage of N instanceable references to usd_samples/assets/eye.usda (the procedural eye mesh) on a square
grid under one sphere light, framed so the grid fills the image (the eyes shrink as N grows: 54 px across for one,
14 px for 64 at 256 px), and renders it with the real command line (`python -m eyerender.cli.eyerecord`, two threads,
a fixed sample count), each case --repeats times, interleaved across builds and estimators. Prints one markdown
table: median wall seconds of the render (eyerecord's summary line, in hundredths: sync, plan, chamber-light caches
and samples, without the interpreter's start-up) per eye count, build and estimator. The chamber-light cache is
built once per eye and frame (its MNEE at every node), so this is where its cost shows.

Usage: python3 bench/bench_eye_crowd.py [--counts 1,4,16,64] [--spp 4] [--width 256] [--repeats 3]
                                        [--estimators cache,path] [--build LABEL=PYTHON ...]
--build measures another installation of eyerender (a venv's python) beside this one, for before/after pairs.
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile

EYE_ASSET = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "usd_samples", "assets", "eye.usda")

STAGE = r"""
import sys
from pxr import Gf, Usd, UsdGeom, UsdLux
count, path, asset = int(sys.argv[1]), sys.argv[2], sys.argv[3]
stage = Usd.Stage.CreateNew(path)
UsdGeom.SetStageMetersPerUnit(stage, 0.01)
UsdGeom.SetStageUpAxis(stage, "Y")
stage.SetDefaultPrim(UsdGeom.Xform.Define(stage, "/World").GetPrim())
key = UsdLux.SphereLight.Define(stage, "/World/Key")
key.CreateIntensityAttr(3000)
key.CreateRadiusAttr(1)
UsdGeom.Xformable(key).AddTranslateOp().Set(Gf.Vec3d(25, 30, 45))
side = max(1, round(count ** 0.5))
for k in range(count):
    eye = stage.DefinePrim(f"/World/Eye{k}", "Xform")
    eye.GetReferences().AddReference(asset)
    eye.SetInstanceable(True)
    UsdGeom.Xformable(eye).AddTranslateOp().Set(Gf.Vec3d(3.0 * (k % side - side / 2), 3.0 * (k // side - side / 2), 0))
camera = UsdGeom.Camera.Define(stage, "/World/main_cam")
camera.CreateFocalLengthAttr(50)
camera.CreateHorizontalApertureAttr(24)
camera.CreateVerticalApertureAttr(24)
UsdGeom.Xformable(camera).AddTranslateOp().Set(Gf.Vec3d(-1.5, -1.5, 6.0 * side + 10))
stage.Save()
"""


def author(python, count, path):
    subprocess.run([python, "-c", STAGE, str(count), path, os.path.abspath(EYE_ASSET)], check=True)


def render(python, stage, out, spp, width, estimator):
    """Seconds of one render, from eyerecord's summary line."""
    cmd = [python, "-m", "eyerender.cli.eyerecord", stage, out, "--imageWidth", str(width), "--spp", str(spp),
           "--threads", "2", "--overwrite", "--quiet", "--chamber-estimator", estimator]
    run = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if run.returncode != 0:
        sys.exit(f"bench_eye_crowd: eyerecord failed ({run.returncode}): {run.stderr.strip()[-300:]}")
    summary = re.search(r"spp, ([0-9.]+) s", run.stdout + run.stderr)
    if not summary:
        sys.exit("bench_eye_crowd: no summary line in eyerecord's output")
    return float(summary.group(1))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--counts", default="1,4,16,64", help="eye counts, comma-separated")
    ap.add_argument("--spp", type=int, default=4)
    ap.add_argument("--width", type=int, default=256, help="image width and height, pixels")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--estimators", default="cache,path", help="eyerecord --chamber-estimator values")
    ap.add_argument("--build", action="append", default=[], metavar="LABEL=PYTHON",
                    help="also measure this python's eyerender (repeatable); this one is 'this'")
    args = ap.parse_args()
    builds = [("this", sys.executable)]
    for b in args.build:
        label, sep, python = b.partition("=")
        if not sep:
            sys.exit("bench_eye_crowd: --build takes LABEL=PYTHON")
        builds.append((label, python))
    counts = [int(c) for c in args.counts.split(",")]
    estimators = args.estimators.split(",")
    times = {}
    with tempfile.TemporaryDirectory() as tmp:
        for count in counts:
            stage = os.path.join(tmp, f"crowd{count}.usda")
            author(sys.executable, count, stage)
            for r in range(args.repeats):
                for label, python in builds:
                    for estimator in estimators:
                        t = render(python, stage, os.path.join(tmp, "out.exr"), args.spp, args.width, estimator)
                        times.setdefault((count, label, estimator), []).append(t)
                        print(f"bench_eye_crowd: {count} eyes, {label}, {estimator}, run {r + 1}: {t:.2f} s",
                              file=sys.stderr)
    columns = [(label, e) for label, _ in builds for e in estimators]
    print(f"| eyes | {' | '.join(f'{label} {e} s' for label, e in columns)} |")
    print("| --- |" + " --- |" * len(columns))
    for count in counts:
        cells = [f"{statistics.median(times[(count, label, e)]):.2f}" for label, e in columns]
        print(f"| {count} | {' | '.join(cells)} |")
    print(f"\n{args.width} x {args.width}, {args.spp} spp, 2 threads; median of {args.repeats} renders per cell. "
          f"Load average at the end: {os.getloadavg()[0]:.2f}.")


if __name__ == "__main__":
    main()
