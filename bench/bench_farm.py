"""Farm throughput: frames per minute and samples per second on one machine (plain eyerecord) and on local Dask
clusters of 1 and 2 workers, the per-task overhead (stage load and sync, scheduling and transfer, merge) against
render time, and a projection to N machines. Prints a table; writes docs/farm_benchmark.png when matplotlib is there.

    PYTHONPATH=python python3 bench/bench_farm.py [--frames 8] [--width 64] [--spp 16]

The projection assumes every machine is like this one and the scheduler is not the bottleneck: a job of F frames on
N workers takes setup + load + ceil(F / N) * (render + overhead) seconds, with the per-frame render time, the
one-off stage load per worker and the per-task overhead measured here.
"""
import argparse
import math
import os
import pathlib
import sys
import tempfile
import time

REPO = pathlib.Path(__file__).resolve().parents[1]
os.environ.setdefault("PXR_PLUGINPATH_NAME", str(REPO / "schemas"))
STAGE = REPO / "usd_samples" / "squash_stretch.usda"


def local_run(frames, width, spp, out):
    """Single machine, no Dask: one RenderSession over the frames, as eyerecord renders."""
    from eyerender.cli.eyerecord import main

    start = time.perf_counter()
    assert main([str(STAGE), str(out / "local_####.exr"), "-w", str(width), "--spp", str(spp), "--frames",
                 f"1:{frames}", "-q"]) == 0
    return time.perf_counter() - start


def farm_run(farm, frames, width, spp, out, name, split=1):
    from eyerender.farm import RenderJob

    job = RenderJob(str(STAGE), [str(out / f"{name}_####.exr")], spp=spp, width=width)
    report = farm.render(job, [float(f) for f in range(1, frames + 1)], split=split, overwrite=True)
    assert report.ok, report.errors
    return report


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--frames", type=int, default=8)
    p.add_argument("--width", type=int, default=64)
    p.add_argument("--spp", type=int, default=16)
    args = p.parse_args()
    import eyerender  # noqa: F401  (schema plugin before pxr)
    from eyerender.farm import Farm

    out = pathlib.Path(tempfile.mkdtemp(prefix="bench_farm_"))
    frames, width, spp = args.frames, args.width, args.spp
    height = width  # the sample's camera aperture is square at these sizes; corrected below from the stats
    rows = []
    seconds = local_run(frames, width, spp, out)
    rows.append(("eyerecord (no Dask)", 1, seconds, None))
    overhead = {}
    for workers in (1, 2):
        start = time.perf_counter()
        with Farm(workers=workers) as farm:
            startup = time.perf_counter() - start
            farm_run(farm, frames, width, spp, out, f"warm{workers}")  # the first job loads the stage on each worker
            report = farm_run(farm, frames, width, spp, out, f"w{workers}")
            split = farm_run(farm, 1, width, spp, out, f"s{workers}", split=2 * workers) if workers == 2 else None
        stats = list(report.stats.values())
        height = stats[0]["height"]
        busy = sum(s["render_seconds"] + s["write_seconds"] + s["load_seconds"] for s in stats)
        # Wall time the workers were not rendering, loading or writing, per task: scheduling, transfer, idling.
        overhead[workers] = {"render": sum(s["render_seconds"] for s in stats) / len(stats),
                             "load": sum(s["load_seconds"] for s in stats) / len(stats),
                             "task": max(0.0, report.seconds * workers - busy) / len(stats),
                             "startup": startup}
        rows.append((f"Dask LocalCluster, {workers} worker(s)", workers, report.seconds, overhead[workers]))
        if split:
            s = split.stats[1.0]
            rows.append((f"  1 frame split {s['tasks'] - 1} ways on {workers}", workers, split.seconds,
                         {"render": s["render_seconds"], "load": s["load_seconds"], "task": s["merge_seconds"],
                          "startup": 0.0}))
    first_load = {}
    with Farm(workers=1) as farm:  # a cold worker: the stage load and first sync
        report = farm_run(farm, 1, width, spp, out, "cold")
        first_load = report.stats[1.0]["load_seconds"]

    print(f"# farm throughput: {STAGE.name}, {frames} frames {width}x{height}, {spp} spp, {os.cpu_count()} cores")
    print(f"{'run':40s} {'wall s':>8s} {'frames/min':>11s} {'Msamples/s':>11s} {'render s/frame':>15s} "
          f"{'overhead s/task':>16s}")
    for name, _workers, seconds, o in rows:
        n = 1 if name.startswith("  1 frame") else frames
        rate = n * width * height * spp / seconds / 1e6
        print(f"{name:40s} {seconds:8.2f} {60 * n / seconds:11.1f} {rate:11.3f} "
              f"{(o['render'] if o else seconds / n):15.3f} {(o['task'] if o else 0.0):16.3f}")
    print(f"stage load + first sync on a cold worker: {first_load:.3f} s; LocalCluster start-up "
          f"{overhead[2]['startup']:.1f} s (2 workers)")

    # Projection: per-frame render time from 1 worker (the whole machine), per-task overhead from the 2-worker run.
    render, task = overhead[1]["render"], overhead[2]["task"]
    job_frames = 240
    print(f"\n# projection: a {job_frames}-frame job of these frames on N machines like this one")
    print(f"{'N':>5s} {'job s':>9s} {'frames/min':>11s} {'efficiency':>11s}")
    projected = []
    for n in (1, 2, 4, 8, 16, 32, 64, 128):
        total = first_load + math.ceil(job_frames / n) * (render + task)
        projected.append((n, 60 * job_frames / total))
        print(f"{n:5d} {total:9.1f} {60 * job_frames / total:11.1f} "
              f"{projected[-1][1] / (n * projected[0][1]):11.2f}")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return 0
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.loglog([n for n, _ in projected], [r for _, r in projected], "o-", label="projected (measured costs)")
    ax.loglog([n for n, _ in projected], [projected[0][1] * n for n, _ in projected], ":", label="linear")
    measured = [(w, 60 * frames / s) for name, w, s, o in rows if name.startswith("Dask")]
    ax.loglog([w for w, _ in measured], [r for _, r in measured], "s", label="measured, this 2-core machine")
    ax.set_xlabel("machines (workers)")
    ax.set_ylabel("frames per minute")
    ax.set_title(f"eyerecord on Dask: {width}x{height}, {spp} spp frames")
    ax.legend()
    fig.tight_layout()
    path = REPO / "docs" / "farm_benchmark.png"
    fig.savefig(path, dpi=100)
    print(f"\nwrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
