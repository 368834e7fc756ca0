"""bench_motion: what motion blur costs per sample, on the saccading eye with MNEE.

Scene: usd_samples/saccade.usda at frame 11, where the eye turns 10 degrees within the camera's 180-degree
shutter (-0.25, 0.25 frames); MNEE on for its key light (the render plan's other choices as it makes them).
Modes: sharp (--shutter 0: today's render) and blurred (the camera's shutter: the eye's transform as two time
steps, every camera path at its own time in the shutter). A still frame (10) under the same shutter checks that
blur costs nothing where nothing moves.

Measured per mode (median over --repeats renders of --spp samples, each a fresh pass over the same session):
seconds per sample (one sample per pixel over the image) and rays per second; and the ratio to sharp.

Usage: python3 bench/bench_motion.py [--width 96] [--spp 8] [--repeats 5] [--threads 0]
"""
import argparse
import pathlib
import statistics

from pxr import Usd

from eyerender import RenderSession
from eyerender.plan import make_overrides

SACCADE = pathlib.Path(__file__).resolve().parents[1] / "usd_samples" / "saccade.usda"
MODES = (("sharp", 11, (0.0, 0.0)), ("blurred", 11, None), ("still frame, shutter open", 10, None))


def measure(width, spp, repeats, threads, frame, shutter):
    """(median seconds per sample, median rays per second, whether the render was blurred)."""
    stage = Usd.Stage.Open(str(SACCADE))
    session = RenderSession(stage, width=width, time=Usd.TimeCode(frame), shutter=shutter,
                            settings={"threads": threads}, plan_overrides=make_overrides(mnee=True))
    session.render(spp=1)  # first sync and the BVH build, not what a sample costs
    per_sample, rates = [], []
    for _ in range(repeats):
        stats = session.render(spp=spp)
        per_sample.append(stats["seconds"] / stats["samples_per_pixel"])
        rates.append(stats["rays_per_second"])
    return statistics.median(per_sample), statistics.median(rates), session.scene.shutter.blurred


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--width", type=int, default=96, help="pixels (square image; default 96)")
    parser.add_argument("--spp", type=int, default=8, help="samples per render (default 8)")
    parser.add_argument("--repeats", type=int, default=5, help="renders per mode, the median is kept (default 5)")
    parser.add_argument("--threads", type=int, default=0, help="render threads (default: all cores)")
    args = parser.parse_args(argv)
    rows = [(name, frame, *measure(args.width, args.spp, args.repeats, args.threads, frame, shutter))
            for name, frame, shutter in MODES]
    sharp = rows[0][2]
    print(f"saccade.usda, {args.width}x{args.width}, MNEE on, median of {args.repeats} x {args.spp} spp")
    print(f"{'mode':<28} {'frame':>5} {'ms/sample':>10} {'Mrays/s':>8} {'x sharp':>8} {'blurred':>8}")
    for name, frame, seconds, rate, blurred in rows:
        print(f"{name:<28} {frame:>5} {1e3 * seconds:>10.1f} {rate / 1e6:>8.2f} {seconds / sharp:>8.2f} "
              f"{str(blurred):>8}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
