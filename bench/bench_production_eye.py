#!/usr/bin/env python3
"""bench_production_eye: how the production eye sample (usd_samples/production_head.usda: mesh eyes in a lidded,
skinned head with lashes and tear lines under a textured dome, a rect key and a small fill) converges.

Renders the whole frame (1920 x 1080 by default: the eyes about 200 pixels across) with eyerecord on 2 threads: a
reference of --reference-spp samples per pixel, then each --budgets time limit with two seeds. Over both eyes' pixels
(the reference's beauty at least 99 % eye light by the nonEye AOV, brighter than a tenth of their median: the pupil's
dark core is left out, as scene B leaves it out) it prints the relative RMSE per pixel of each seed, the noise and
the floor (the error the two seeds share: it holds the reference's own noise too), the samples per pixel reached
and the seconds to 2 % extrapolated as 1/sqrt(t) from each budget; then the reference's summary line (time to first
pixel, samples per second) and the render plan's lines.

    python3 bench/bench_production_eye.py [-w 1920] [--budgets 20,80] [--reference-spp 1024]
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_STAGE = os.path.join(HERE, "..", "usd_samples", "production_head.usda")
FRAME = 12
GOAL = 0.02

def render(stage, width, scratch, label, seed, spp=0, seconds=0.0):
    """One eyerecord render of frame FRAME with the nonEye AOV; returns ({channel: array}, spp, seconds, log lines)."""
    import eyerender
    out = os.path.join(scratch, f"{label}.#.exr")
    budget = ["--spp", str(spp)] if spp else ["--time-limit", str(seconds)]
    cmd = [sys.executable, "-m", "eyerender.cli.eyerecord", stage, out, "--frames", str(FRAME), "-w", str(width),
           "--threads", "2", "--seed", str(seed), "--aov", "nonEye", "--enableDomeLightVisibility", *budget]
    run = subprocess.run(cmd, capture_output=True, text=True, check=False)
    log = (run.stdout + run.stderr).splitlines()
    if run.returncode != 0:
        sys.exit(f"bench_production_eye: eyerecord failed: {' '.join(log)[-300:]}")
    summary = re.search(r"(\d+) spp, ([0-9.]+) s", run.stdout + run.stderr)
    image = eyerender.read_exr(out.replace("#", str(FRAME)))
    return image, int(summary.group(1)), float(summary.group(2)), log


def grey(image, prefix=""):
    return np.mean([image[prefix + c] for c in "RGB"], axis=0).astype(np.float64)


def eye_mask(reference):
    beauty, non_eye = grey(reference), grey(reference, "nonEye.")
    eye = (beauty > 0) & (non_eye <= 0.01 * beauty)
    return eye & (beauty >= 0.1 * np.median(beauty[eye]))


def errors(images, reference, mask):
    """Relative RMSE per pixel of each image, the noise of one render (from the pair) and the floor they share."""
    ref = grey(reference)[mask]
    e = [(grey(im)[mask] - ref) / ref for im in images]
    rmse = [float(np.sqrt(np.mean(x * x))) for x in e]
    noise = float(np.sqrt(np.mean((e[0] - e[1]) ** 2) / 2))
    floor = float(np.sqrt(max(0.0, np.mean(e[0] * e[1]))))
    return rmse, noise, floor


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stage", default=DEFAULT_STAGE)
    parser.add_argument("--budgets", default="20,80", help="seconds, comma separated")
    parser.add_argument("--reference-spp", type=int, default=1024)
    parser.add_argument("-w", "--width", type=int, default=1920, help="image width (the height follows: 16:9)")
    args = parser.parse_args(argv)
    budgets = [float(b) for b in args.budgets.split(",")]
    with tempfile.TemporaryDirectory() as scratch:
        reference, ref_spp, ref_s, log = render(args.stage, args.width, scratch, "reference", 7, spp=args.reference_spp)
        mask = eye_mask(reference)
        print(f"reference: {ref_spp} spp in {ref_s:.0f} s over a {reference['R'].shape[1]} x "
              f"{reference['R'].shape[0]} window, {int(mask.sum())} eye pixels")
        print("\n".join(x for x in log if "plan" in x))
        print("\n| budget s | spp | relative RMSE (seed 1, seed 2) | noise | floor | seconds to 2 % |")
        print("|---|---|---|---|---|---|")
        for seconds in budgets:
            images, spps = [], []
            for seed in (1, 2):
                image, spp, _, _ = render(args.stage, args.width, scratch, f"b{seconds:g}s{seed}", seed,
                                          seconds=seconds)
                images.append(image)
                spps.append(spp)
            rmse, noise, floor = errors(images, reference, mask)
            to_goal = seconds * (np.mean(rmse) / GOAL) ** 2
            print(f"| {seconds:g} | {spps[0]}, {spps[1]} | {rmse[0]:.2%}, {rmse[1]:.2%} | {noise:.2%} | {floor:.2%} | "
                  f"{to_goal:.0f} |")
        print("\n" + [x for x in log if "first pixel" in x][-1])
    return 0


if __name__ == "__main__":
    sys.exit(main())
