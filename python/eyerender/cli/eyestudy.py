"""eyestudy: speed versus error of the render plan on your own shot.

    eyestudy [options] usdFilePath outputImagePath

Renders the stage at one frame at a few time budgets twice -- with the automatic render plan, and with every eye
feature on (MNEE for every light, the all-solutions search, sclera scattering) -- and compares each image with a
long reference rendered with every feature on. Writes, next to the output:
  <stem>.reference.exr  the reference (reused by later runs when stage, frame, camera, size and spp match)
  <stem>.study.csv      mode, budget, samples, seconds, relative RMSE, noise and bias over the eyes' pixels and
                        over the frame
  <stem>.study.png      the table as a plot (unless --no-plot)
and the automatic plan's image at the largest budget as outputImagePath. Each budget is rendered with two seeds;
the relative error per pixel is (img - ref) / sqrt(ref^2 + 0.01 mean(ref)^2) over RGB, so black pixels do not
divide by zero, and the two seeds split its RMSE into noise and bias (eyerender.image_error). The eyes' pixels are
those whose first hit (primId AOV) is an eye prim.
"""
import argparse
import csv
import functools
import json
import os
import sys

import numpy as np

from ..console import ProgressBar
from ..errors import EyeRenderError, run_command
from ..image_error import error_noise_bias
from ..job import COMPLEXITY_REFINE_LEVELS, open_stage
from ..shutter import parse_shutter_arguments, settings_override

STUDY_ATTRIBUTE = "eyerender:study"  # the reference EXR's key: what it was rendered from
EVERY_FEATURE = {"mnee": True, "mnee_all_solutions": True, "sclera_scattering": True}


def build_parser():
    p = argparse.ArgumentParser(prog="eyestudy", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("usdFilePath")
    p.add_argument("outputImagePath", help=".exr: the plan's image at the largest budget; the study files go beside it")
    p.add_argument("--frame", "-f", type=float, help="the frame to study (default: the stage's start)")
    p.add_argument("--camera", "-cam")
    p.add_argument("--imageWidth", "-w", type=int, default=256)
    p.add_argument("--imageHeight", type=int)
    p.add_argument("--complexity", "-c", choices=COMPLEXITY_REFINE_LEVELS, default="high")
    p.add_argument("--budgets", default="2,5,15", help="time budgets in seconds, comma-separated (default 2,5,15)")
    p.add_argument("--reference-spp", type=int, default=1024, help="reference samples per pixel (default 1024)")
    p.add_argument("--threads", type=int, default=0)
    p.add_argument("--shutter", nargs="+", type=float, metavar="FRAMES", help="OPEN CLOSE frames relative to the "
                   "frame, over the camera's shutter (as eyerecord's --shutter; 0: sharp)")
    p.add_argument("--new-reference", action="store_true", help="re-render the reference even if one matches")
    p.add_argument("--no-plot", action="store_true", help="do not write <stem>.study.png")
    p.add_argument("--quiet", "-q", action="store_true")
    return p


def eye_mask(session, prim_ids, eye_prims):
    """Pixels whose first hit is one of `eye_prims`: primIds count the render index's rprims in path order."""
    ids = [i for i, prim in enumerate(session.index.rprim_ids()) if prim in set(eye_prims)]
    return np.isin(np.rint(prim_ids).astype(int), ids)


def _reference(args, stage_path, frame, make_session, progress):
    from .._hdeye import read_exr, read_exr_attributes

    stem = os.path.splitext(args.outputImagePath)[0]
    path = stem + ".reference.exr"
    key = {"stage": os.path.abspath(stage_path), "mtime": os.path.getmtime(stage_path), "frame": frame,
           "camera": args.camera, "width": args.imageWidth, "height": args.imageHeight,
           "complexity": args.complexity, "spp": args.reference_spp, "settings": EVERY_FEATURE,
           "shutter": args.shutter}
    if os.path.exists(path) and not args.new_reference:
        try:
            if json.loads(read_exr_attributes(path).get(STUDY_ATTRIBUTE, "null")) == key:
                channels = read_exr(path)
                progress(f"reusing the reference {path}")
                img = np.stack([channels[c] for c in "RGB"], axis=2)
                return img, channels["primId"], path
        except (RuntimeError, ValueError):
            pass
    session = make_session(EVERY_FEATURE, None, seed=7919)
    bar = _bar(args, "reference")
    session.render(spp=args.reference_spp, progress=bar)
    bar.finish()
    from ..render_session import write_images

    write_images(path, {"color": session.image("color"), "primId": session.image("primId")},
                 attributes={STUDY_ATTRIBUTE: json.dumps(key)})
    return session.image("color"), session.image("primId")[:, :, 0], path


def _bar(args, label, time_limit=0.0):
    bar = ProgressBar(not args.quiet, time_limit)
    bar.label = label
    return bar


def run(argv=None):
    """eyestudy with the command line `argv` (None: sys.argv); returns the exit status."""
    args = build_parser().parse_args(argv)
    from pxr import Usd

    from ..plan import authored_eye_values, make_overrides, plan_dict

    budgets = _check_args(args)
    stage = open_stage(args.usdFilePath)
    frame = args.frame if args.frame is not None else stage.GetStartTimeCode()
    time = Usd.TimeCode(frame)
    level = COMPLEXITY_REFINE_LEVELS[args.complexity]
    make_session = functools.partial(_make_session, args, stage, level, time)
    progress = functools.partial(_progress, args.quiet)
    overrides = make_overrides(refine_level_ceiling=level, authored=authored_eye_values(stage, time))
    planned = make_session({}, overrides)
    plan = planned.plan()
    for line in plan.summary_lines():
        print(f"eyestudy: {line}")
    eyes = [e["prim"] for e in plan_dict(plan)["eyes"]]
    ref, ref_prim, ref_path = _reference(args, args.usdFilePath, frame, make_session, progress)
    mask = eye_mask(planned, ref_prim, eyes)
    rows = _measure(args, budgets, make_session, overrides, ref, mask)
    stem = os.path.splitext(args.outputImagePath)[0]
    _write_table(rows, stem + ".study.csv")
    print(f"eyestudy: {int(mask.sum())} eye pixels; reference {ref_path}; table {stem}.study.csv")
    if not args.no_plot:
        _plot(rows, stem + ".study.png")
    return 0


def _check_args(args):
    """The time budgets (seconds, ascending), after checking them and the output."""
    from ..render_session import check_writable

    parse_shutter_arguments(args.shutter)  # bad values fail before any render
    budgets = sorted(float(b) for b in args.budgets.split(",") if b.strip())
    if not budgets or min(budgets) <= 0:
        raise EyeRenderError("--budgets must be positive seconds")
    if not args.outputImagePath.lower().endswith(".exr"):
        raise EyeRenderError("the output must be an .exr (the study files are written beside it)")
    check_writable(args.outputImagePath)
    return budgets


def _make_session(args, stage, level, time, settings, overrides, seed=0):
    """A session of the studied shot with RenderSettings overrides `settings` and PlanOverrides `overrides`."""
    from ..render_session import RenderSession

    s = dict(settings)
    s.update(seed=seed, threads=args.threads)
    shutter = settings_override(stage, stage.GetMetadata("renderSettingsPrimPath") or None,
                                parse_shutter_arguments(args.shutter))
    return RenderSession(stage, width=args.imageWidth, height=args.imageHeight, camera=args.camera,
                         aovs=("color", "primId"), refine_level=level, time=time, settings=s,
                         plan_overrides=overrides, shutter=shutter)


def _progress(quiet, msg):
    if not quiet:
        print(f"eyestudy: {msg}", file=sys.stderr)


SEEDS = (0, 1)  # two independent renders per budget: their difference is noise, what they share is bias


def _measure(args, budgets, make_session, overrides, ref, mask):
    """One table row per mode and budget: samples, seconds, and relative RMSE, noise and bias against the reference
    `ref` (over the eyes' pixels `mask` and over the frame) from one render per seed. Writes the plan's image
    (first seed) at the largest budget as the output."""
    rows = []
    for mode, settings, ov in (("plan", {}, overrides), ("every feature", EVERY_FEATURE, None)):
        sessions = [make_session(settings, ov, seed=seed) for seed in SEEDS]
        for budget in budgets:
            imgs, spp, seconds = [], [], []
            for seed, session in zip(SEEDS, sessions):
                bar = _bar(args, f"{mode} {budget:g} s seed {seed}", budget)
                stats = session.render(spp=1 << 20, time_limit=budget, progress=bar)
                bar.finish()
                imgs.append(session.image("color"))
                spp.append(stats["samples_per_pixel"])
                seconds.append(stats["seconds"])
            row = {"mode": mode, "budget_s": budget, "spp": min(spp), "seconds": sum(seconds) / len(seconds)}
            for region, m in (("eye", mask), ("frame", None)):
                rmse, noise, bias = error_noise_bias(imgs[0], imgs[1], ref, m)
                row.update({f"{region}_rel_rmse": rmse, f"{region}_noise": noise, f"{region}_bias": bias})
            row["eye_pixels"] = int(mask.sum())
            rows.append(row)
            if mode == "plan" and budget == budgets[-1]:
                sessions[0].write(args.outputImagePath)
    return rows


def _write_table(rows, csv_path):
    """The rows to `csv_path` and, as a Markdown table, to stdout."""
    with open(csv_path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print("| mode | budget s | spp | seconds | eye rel RMSE | eye noise | eye bias | frame rel RMSE | frame noise | "
          "frame bias |\n|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|")
    for r in rows:
        print(f"| {r['mode']} | {r['budget_s']:g} | {r['spp']} | {r['seconds']:.1f} | {r['eye_rel_rmse']:.4f} | "
              f"{r['eye_noise']:.4f} | {r['eye_bias']:.4f} | {r['frame_rel_rmse']:.4f} | {r['frame_noise']:.4f} | "
              f"{r['frame_bias']:.4f} |")


def _plot(rows, path):
    """Relative RMSE (solid) and bias (dotted) against seconds per mode, eyes and frame side by side."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(8, 3.4))
    for ax, region, title in ((axes[0], "eye", "eyes' pixels"), (axes[1], "frame", "frame")):
        for mode, marker, color in (("plan", "o", "C0"), ("every feature", "s", "C1")):
            sel = [r for r in rows if r["mode"] == mode]
            t = [r["seconds"] for r in sel]
            ax.loglog(t, [r[f"{region}_rel_rmse"] for r in sel], marker + "-", color=color, label=f"{mode} RMSE")
            ax.loglog(t, [r[f"{region}_bias"] for r in sel], marker + ":", color=color, label=f"{mode} bias")
        ax.set_xlabel("render seconds")
        ax.set_ylabel("relative error")
        ax.set_title(title)
        ax.legend(fontsize="small")
    fig.tight_layout()
    tmp = path + ".tmp.png"
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    os.replace(tmp, path)
    print(f"eyestudy: plot {path}")


def main(argv=None):
    return run_command("eyestudy", run, argv)


if __name__ == "__main__":
    sys.exit(main())
