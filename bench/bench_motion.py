"""bench_motion: what motion blur costs per sample, on the saccading eye with MNEE.

Scene: usd_samples/saccade.usda at frame 11, where the eye turns 10 degrees within the camera's 180-degree
shutter (-0.25, 0.25 frames); MNEE on for its key light (the render plan's other choices as it makes them).
Modes: sharp (--shutter 0: today's render) and blurred (the camera's shutter: the eye's transform as two time
steps, every camera path at its own time in the shutter). A still frame (10) under the same shutter checks that
blur costs nothing where nothing moves. The blink (usd_samples/blink.usda, frame 10, the upper lid closing: its
points as time steps, Embree multi-segment geometry) measures deformation blur the same way.

Measured per mode (median over --repeats renders of --spp samples on the same session, the modes interleaved):
seconds per sample (one sample per pixel over the image) and rays per second; and the ratio to sharp.

Usage: python3 bench/bench_motion.py [--width 96] [--spp 8] [--repeats 5] [--threads 0]
"""
import argparse
import pathlib
import statistics

from pxr import Usd

from eyerender import RenderSession
from eyerender.plan import make_overrides

SAMPLES = pathlib.Path(__file__).resolve().parents[1] / "usd_samples"
# (stage, mode, frame, shutter override: None for the camera's); each stage's first row is its sharp reference.
MODES = (("saccade", "sharp", 11, (0.0, 0.0)), ("saccade", "blurred", 11, None),
         ("saccade", "still frame, shutter open", 10, None),
         ("blink", "sharp", 10, (0.0, 0.0)), ("blink", "blurred", 10, None))


def open_session(stage_name, width, threads, frame, shutter):
    stage = Usd.Stage.Open(str(SAMPLES / f"{stage_name}.usda"))
    session = RenderSession(stage, width=width, time=Usd.TimeCode(frame), shutter=shutter,
                            settings={"threads": threads}, plan_overrides=make_overrides(mnee=True))
    session.render(spp=1)  # first sync and the BVH build, not what a sample costs
    return session


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--width", type=int, default=96, help="pixels (square image; default 96)")
    parser.add_argument("--spp", type=int, default=8, help="samples per render (default 8)")
    parser.add_argument("--repeats", type=int, default=5, help="renders per mode, the median is kept (default 5)")
    parser.add_argument("--threads", type=int, default=0, help="render threads (default: all cores)")
    args = parser.parse_args(argv)
    sessions = [open_session(stage, args.width, args.threads, frame, shutter) for stage, _, frame, shutter in MODES]
    per_sample, rates = [[] for _ in MODES], [[] for _ in MODES]
    for _ in range(args.repeats):  # modes interleaved, so a change in the machine's load hits them alike
        for k, session in enumerate(sessions):
            stats = session.render(spp=args.spp)
            per_sample[k].append(stats["seconds"] / stats["samples_per_pixel"])
            rates[k].append(stats["rays_per_second"])
    print(f"{args.width}x{args.width}, MNEE on, median of {args.repeats} x {args.spp} spp (modes interleaved)")
    print(f"{'stage':<8} {'mode':<27} {'frame':>5} {'ms/sample':>10} {'Mrays/s':>8} {'x sharp':>8} {'blurred':>8}")
    sharp = {}
    for k, (stage_name, name, frame, _) in enumerate(MODES):
        seconds, rate = statistics.median(per_sample[k]), statistics.median(rates[k])
        sharp.setdefault(stage_name, seconds)
        print(f"{stage_name:<8} {name:<27} {frame:>5} {1e3 * seconds:>10.1f} {rate / 1e6:>8.2f} "
              f"{seconds / sharp[stage_name]:>8.2f} {str(sessions[k].scene.shutter.blurred):>8}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
