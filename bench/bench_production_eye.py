#!/usr/bin/env python3
"""bench_production_eye: how the production eye sample (usd_samples/production_head.usda: mesh eyes in a lidded,
skinned head with lashes and tear lines under a textured dome, a rect key and a small fill) converges.

Renders the whole frame (1920 x 1080 by default: the eyes about 200 pixels across) with eyerecord on 2 threads: a
reference of --reference-spp samples per pixel, then each --budgets time limit with two seeds. Over both eyes' pixels
(the reference's beauty at least 99 % eye light by the nonEye AOV, brighter than a tenth of their median: the pupil's
dark core is left out, as scene B leaves it out) it prints the relative RMSE per pixel of each seed, the noise and
the floor (the error the two seeds share: it holds the reference's own noise too), the samples per pixel reached
and the seconds to 2 % extrapolated as 1/sqrt(t) from each budget; then the reference's summary line (time to first
pixel, samples per second) and the render plan's lines, and where the noise is: each eye AOV's (SHEET_AOVS; with
nonEye they sum to the beauty) share of the eyes' light and its noise relative to the eyes' light, from the two
seeds of each budget (the shares of variance add up to the beauty's but for the AOVs' correlation). --sheet PNG
also draws a contact sheet: the reference frame, the right eye at the reference and at each budget (seed 1), and the
reference's eye AOVs, all at one exposure.

    python3 bench/bench_production_eye.py [-w 1920] [--budgets 20,80] [--reference-spp 1024] [--sheet PNG]
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
SHEET_AOVS = ("iris", "glint", "sclera", "limbalArc")


def render(stage, width, scratch, label, seed, spp=0, seconds=0.0, aovs=()):
    """One eyerecord render of frame FRAME with the nonEye AOV and `aovs`; returns ({channel: array}, spp, seconds,
    log lines)."""
    import eyerender
    out = os.path.join(scratch, f"{label}.#.exr")
    budget = ["--spp", str(spp)] if spp else ["--time-limit", str(seconds)]
    cmd = [sys.executable, "-m", "eyerender.cli.eyerecord", stage, out, "--frames", str(FRAME), "-w", str(width),
           "--threads", "2", "--seed", str(seed), *[x for a in ("nonEye", *aovs) for x in ("--aov", a)],
           "--enableDomeLightVisibility", *budget]
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


def right_eye_box(mask):
    """(rows, columns) slices around the eye pixels in the image's right half, with a margin of half their size."""
    half = mask.copy()
    half[:, : mask.shape[1] // 2] = False
    ys, xs = np.nonzero(half)
    if len(ys) == 0:
        ys, xs = np.nonzero(mask)
    cy, cx, r = (ys.min() + ys.max()) // 2, (xs.min() + xs.max()) // 2, max(np.ptp(ys), np.ptp(xs)) + 1
    return (slice(max(0, cy - r), cy + r), slice(max(0, cx - r), cx + r))


def draw_sheet(path, reference, ref_spp, renders, mask):
    """The contact sheet: the reference frame on top; below, the right eye at the reference and each budget's seed-1
    render, then the reference's SHEET_AOVS over the same eye. One exposure: the eye's 99.5th percentile at white."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scale = 1 / np.percentile(grey(reference)[mask], 99.5)

    def shown(image, prefix=""):
        rgb = np.clip(np.stack([image[prefix + c] for c in "RGB"], -1) * scale, 0, 1)
        return np.where(rgb <= 0.0031308, 12.92 * rgb, 1.055 * rgb ** (1 / 2.4) - 0.055)

    box = right_eye_box(mask)
    crops = [(f"reference, {ref_spp} spp", shown(reference)[box])]
    crops += [(f"{seconds:g} s, {spp} spp", shown(image)[box]) for seconds, spp, image in renders]
    crops += [(f"{aov} AOV", shown(reference, aov + ".")[box]) for aov in SHEET_AOVS]
    columns = max(len(renders) + 1, len(SHEET_AOVS))
    fig = plt.figure(figsize=(3 * columns, 3 * columns * 9 / 16 + 6.4))
    grid = fig.add_gridspec(3, columns, height_ratios=[columns * 9 / 16, 1, 1])
    top = fig.add_subplot(grid[0, :])
    top.imshow(shown(reference))
    top.set_title(f"usd_samples/production_head.usda, frame {FRAME}: reference ({ref_spp} spp)")
    for k, (title, crop) in enumerate(crops):
        row, column = (1, k) if k < len(renders) + 1 else (2, k - len(renders) - 1)
        ax = fig.add_subplot(grid[row, column])
        ax.imshow(crop)
        ax.set_title(title, fontsize=9)
    for ax in fig.axes:
        ax.set_xticks([]), ax.set_yticks([])
    fig.tight_layout()
    folder = os.path.dirname(os.path.abspath(path))
    with tempfile.NamedTemporaryFile(dir=folder, suffix=".png", delete=False) as tmp:
        fig.savefig(tmp.name, dpi=100)
    os.replace(tmp.name, path)
    print(f"contact sheet: {path}")


def aov_noise(images, reference, mask):
    """Per SHEET_AOVS: (its share of the eyes' light in the reference, the noise of one render of it relative to the
    eyes' light, per pixel)."""
    ref = grey(reference)[mask]
    out = {}
    for aov in SHEET_AOVS:
        a, b = (grey(im, aov + ".")[mask] for im in images)
        out[aov] = (float(np.mean(grey(reference, aov + ".")[mask] / ref)),
                    float(np.sqrt(np.mean(((a - b) / ref) ** 2) / 2)))
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stage", default=DEFAULT_STAGE)
    parser.add_argument("--budgets", default="20,80", help="seconds, comma separated")
    parser.add_argument("--reference-spp", type=int, default=1024)
    parser.add_argument("-w", "--width", type=int, default=1920, help="image width (the height follows: 16:9)")
    parser.add_argument("--sheet", metavar="PNG", help="also write the contact sheet there")
    args = parser.parse_args(argv)
    budgets = [float(b) for b in args.budgets.split(",")]
    with tempfile.TemporaryDirectory() as scratch:
        reference, ref_spp, ref_s, log = render(args.stage, args.width, scratch, "reference", 7, spp=args.reference_spp,
                                                aovs=SHEET_AOVS)
        mask = eye_mask(reference)
        print(f"reference: {ref_spp} spp in {ref_s:.0f} s over a {reference['R'].shape[1]} x "
              f"{reference['R'].shape[0]} window, {int(mask.sum())} eye pixels")
        print("\n".join(x for x in log if "plan" in x))
        print("\n| budget s | spp | relative RMSE (seed 1, seed 2) | noise | floor | seconds to 2 % |")
        print("|---|---|---|---|---|---|")
        shown, parts = [], []  # (seconds, spp, seed 1's image) for the sheet; (seconds, aov_noise) per budget
        for seconds in budgets:
            images, spps = [], []
            for seed in (1, 2):
                image, spp, _, _ = render(args.stage, args.width, scratch, f"b{seconds:g}s{seed}", seed,
                                          seconds=seconds, aovs=SHEET_AOVS)
                images.append(image)
                spps.append(spp)
            shown.append((seconds, spps[0], images[0]))
            parts.append((seconds, aov_noise(images, reference, mask)))
            rmse, noise, floor = errors(images, reference, mask)
            to_goal = seconds * (np.mean(rmse) / GOAL) ** 2
            print(f"| {seconds:g} | {spps[0]}, {spps[1]} | {rmse[0]:.2%}, {rmse[1]:.2%} | {noise:.2%} | {floor:.2%} | "
                  f"{to_goal:.0f} |")
        print("\n| budget s | " + " | ".join(f"{aov}: share, noise" for aov in SHEET_AOVS) + " |")
        print("|---|" + "---|" * len(SHEET_AOVS))
        for seconds, noise_by_aov in parts:
            cells = [f"{share:.1%}, {noise:.2%}" for share, noise in noise_by_aov.values()]
            print(f"| {seconds:g} | " + " | ".join(cells) + " |")
        print("\n" + [x for x in log if "first pixel" in x][-1])
        if args.sheet:
            draw_sheet(args.sheet, reference, ref_spp, shown, mask)
    return 0


if __name__ == "__main__":
    sys.exit(main())
