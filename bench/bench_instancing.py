"""Instancing scaling: a PointInstancer of N copies of one Catmull-Clark mesh (an 8 x 8 quad grid, level 2) rendered
through shared instancers and, up to --flatten-max, through the flattened reference (one mesh per copy). Each case
runs in its own subprocess so its peak memory (ru_maxrss) is its own; prints one table row per case (medians over
--repeats runs).

    python3 bench/bench_instancing.py                # 1, 10, 100, 1000, 10000 instances
    python3 bench/bench_instancing.py --counts 1 100 --repeats 3
"""
import argparse
import json
import statistics
import subprocess
import sys

CHILD = r"""
import json, resource, sys, time
from pxr import Gf, Usd, UsdGeom, UsdLux
from eyerender import RenderSession
count, flatten, width = int(sys.argv[1]), sys.argv[2] == "1", int(sys.argv[3])
stage = Usd.Stage.CreateInMemory()
UsdGeom.Camera.Define(stage, "/World/main_cam").AddTranslateOp().Set(Gf.Vec3d(0, 0, 30))
UsdLux.DomeLight.Define(stage, "/World/dome")
pi = UsdGeom.PointInstancer.Define(stage, "/World/crowd")
mesh = UsdGeom.Mesh.Define(stage, "/World/crowd/protos/grid")
n = 8
mesh.CreatePointsAttr([(i / n - 0.5, j / n - 0.5, 0.1 * ((i + j) % 2)) for j in range(n + 1) for i in range(n + 1)])
mesh.CreateFaceVertexCountsAttr([4] * n * n)
row = n + 1
mesh.CreateFaceVertexIndicesAttr([v for j in range(n) for i in range(n) for v in
                                  (j * row + i, j * row + i + 1, (j + 1) * row + i + 1, (j + 1) * row + i)])
pi.CreatePrototypesRel().SetTargets([mesh.GetPath()])
side = max(1, round(count ** 0.5))
pi.CreatePositionsAttr([(20.0 * (k % side) / side - 10, 20.0 * (k // side) / side - 10, 0) for k in range(count)])
pi.CreateProtoIndicesAttr([0] * count)
start = time.perf_counter()
session = RenderSession(stage, width=width, height=width, refine_level=2, flatten_instances=flatten)
session.index.sync_all()
sync = time.perf_counter() - start
start = time.perf_counter()
session.render(spp=1)
render = time.perf_counter() - start
print(json.dumps({"sync": sync, "render": render, "rss": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss}))
"""


def run(count, flatten, width):
    out = subprocess.run([sys.executable, "-c", CHILD, str(count), "1" if flatten else "0", str(width)],
                         capture_output=True, text=True, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--counts", type=int, nargs="+", default=[1, 10, 100, 1000, 10000])
    parser.add_argument("--flatten-max", type=int, default=1000, help="largest count also run flattened")
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--width", type=int, default=128, help="image width and height, pixels")
    args = parser.parse_args()
    print("| instances | mode | peak RSS (MB) | sync (s) | render 1 spp (s) |")
    print("|---:|---|---:|---:|---:|")
    for count in args.counts:
        for flatten in (False, True):
            if flatten and count > args.flatten_max:
                continue
            runs = [run(count, flatten, args.width) for _ in range(args.repeats)]
            med = {k: statistics.median(r[k] for r in runs) for k in runs[0]}
            print(f"| {count} | {'flattened' if flatten else 'instanced'} | {med['rss'] / 1024:.0f} | "
                  f"{med['sync']:.2f} | {med['render']:.2f} |", flush=True)


if __name__ == "__main__":
    main()
