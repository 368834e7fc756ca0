"""eyestudy: speed versus error of the render plan on your own shot.

    eyestudy [options] usdFilePath outputImagePath

Renders the stage at one frame at a few time budgets twice -- with the automatic render plan, and with every eye
feature on (MNEE for every light, the all-solutions search, sclera scattering) -- and compares each image with a
long reference rendered with every feature on. Writes, next to the output:
  <stem>.reference.exr  the reference (reused by later runs when stage, frame, camera, size and spp match)
  <stem>.study.csv      budget, mode, samples, seconds, relative RMSE over the eyes' pixels and over the frame
  <stem>.study.png      the table as a plot (when matplotlib is installed)
and the automatic plan's image at the largest budget as outputImagePath. Relative RMSE = sqrt(mean((img - ref)^2))
/ mean(ref), over RGB; the eyes' pixels are those whose first hit (primId AOV) is an eye prim. A trimmed version
drops the worst 0.1% of pixels (one firefly in the reference otherwise decides the number); both are in the table.
"""
import argparse
import csv
import functools
import json
import os
import sys

import numpy as np

from .console import ProgressBar
from .errors import EyeRenderError, run_command
from .job import COMPLEXITY_REFINE_LEVELS, open_stage

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
    p.add_argument("--new-reference", action="store_true", help="re-render the reference even if one matches")
    p.add_argument("--quiet", "-q", action="store_true")
    return p


def rel_rmse(img, ref, mask=None):
    """sqrt(mean over pixels (and RGB) of (img - ref)^2) / mean(ref), over `mask` (bool (h, w)) or the frame."""
    a, b = img[:, :, :3], ref[:, :, :3]
    if mask is not None:
        if not mask.any():
            return float("nan")
        a, b = a[mask], b[mask]
    mean = float(b.mean())
    return float(np.sqrt(((a - b) ** 2).mean()) / mean) if mean > 0 else float("nan")


def trimmed_rel_rmse(img, ref, mask=None, keep=0.999):
    """rel_rmse without the worst (1 - keep) of the pixels by squared difference: a single firefly (in the image or
    the reference) otherwise decides the whole number."""
    a, b = img[:, :, :3], ref[:, :, :3]
    if mask is not None:
        if not mask.any():
            return float("nan")
        a, b = a[mask], b[mask]
    a, b = a.reshape(-1, 3), b.reshape(-1, 3)
    d2 = ((a - b) ** 2).mean(axis=1)
    kept = d2 <= np.quantile(d2, keep)
    mean = float(b[kept].mean())
    return float(np.sqrt(d2[kept].mean()) / mean) if mean > 0 else float("nan")


def eye_mask(session, prim_ids, eye_prims):
    """Pixels whose first hit is one of `eye_prims`: primIds count the render index's rprims in path order."""
    ids = [i for i, prim in enumerate(session.index.rprim_ids()) if prim in set(eye_prims)]
    return np.isin(np.rint(prim_ids).astype(int), ids)


def _reference(args, stage_path, frame, make_session, progress):
    from ._hdeye import read_exr, read_exr_attributes

    stem = os.path.splitext(args.outputImagePath)[0]
    path = stem + ".reference.exr"
    key = {"stage": os.path.abspath(stage_path), "mtime": os.path.getmtime(stage_path), "frame": frame,
           "camera": args.camera, "width": args.imageWidth, "height": args.imageHeight,
           "complexity": args.complexity, "spp": args.reference_spp, "settings": EVERY_FEATURE}
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
    from .render_session import write_images

    write_images(path, {"color": session.image("color"), "primId": session.image("primId")},
                 attributes={STUDY_ATTRIBUTE: json.dumps(key)})
    return session.image("color"), session.image("primId")[:, :, 0], path


def _bar(args, label):
    bar = ProgressBar(not args.quiet)
    bar.label = label
    return bar


def run(argv=None):
    """eyestudy with the command line `argv` (None: sys.argv); returns the exit status."""
    args = build_parser().parse_args(argv)
    from pxr import Usd

    from .plan import authored_eye_values, make_overrides, plan_dict

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
    _plot(rows, stem + ".study.png", progress)
    return 0


def _check_args(args):
    """The time budgets (seconds, ascending), after checking them and the output."""
    from .render_session import check_writable

    budgets = sorted(float(b) for b in args.budgets.split(",") if b.strip())
    if not budgets or min(budgets) <= 0:
        raise EyeRenderError("--budgets must be positive seconds")
    if not args.outputImagePath.lower().endswith(".exr"):
        raise EyeRenderError("the output must be an .exr (the study files are written beside it)")
    check_writable(args.outputImagePath)
    return budgets


def _make_session(args, stage, level, time, settings, overrides, seed=0):
    """A session of the studied shot with RenderSettings overrides `settings` and PlanOverrides `overrides`."""
    from .render_session import RenderSession

    s = dict(settings)
    s.update(seed=seed, threads=args.threads)
    return RenderSession(stage, width=args.imageWidth, height=args.imageHeight, camera=args.camera,
                         aovs=("color", "primId"), refine_level=level, time=time, settings=s,
                         plan_overrides=overrides)


def _progress(quiet, msg):
    if not quiet:
        print(f"eyestudy: {msg}", file=sys.stderr)


def _measure(args, budgets, make_session, overrides, ref, mask):
    """One table row per mode and budget: samples, seconds and errors against the reference `ref` (over the eyes'
    pixels `mask` and the frame). Writes the plan's image at the largest budget as the output."""
    rows = []
    for mode, settings, ov in (("plan", {}, overrides), ("every feature", EVERY_FEATURE, None)):
        session = make_session(settings, ov)
        for budget in budgets:
            bar = _bar(args, f"{mode} {budget:g} s")
            stats = session.render(spp=1 << 20, time_limit=budget, progress=bar)
            bar.finish()
            img = session.image("color")
            rows.append({"mode": mode, "budget_s": budget, "spp": stats["samples_per_pixel"],
                         "seconds": stats["seconds"], "eye_rel_rmse": rel_rmse(img, ref, mask),
                         "frame_rel_rmse": rel_rmse(img, ref),
                         "eye_trimmed": trimmed_rel_rmse(img, ref, mask), "frame_trimmed": trimmed_rel_rmse(img, ref),
                         "eye_pixels": int(mask.sum())})
            if mode == "plan" and budget == budgets[-1]:
                session.write(args.outputImagePath)
    return rows


def _write_table(rows, csv_path):
    """The rows to `csv_path` and, as a Markdown table, to stdout."""
    with open(csv_path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print("| mode | budget s | spp | seconds | eye rel RMSE | frame rel RMSE | eye (trimmed 0.1%) | frame (trimmed) |\n"
          "|---|--:|--:|--:|--:|--:|--:|--:|")
    for r in rows:
        print(f"| {r['mode']} | {r['budget_s']:g} | {r['spp']} | {r['seconds']:.1f} | {r['eye_rel_rmse']:.4f} | "
              f"{r['frame_rel_rmse']:.4f} | {r['eye_trimmed']:.4f} | {r['frame_trimmed']:.4f} |")


def _plot(rows, path, progress):
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        progress("matplotlib is not installed: no plot")
        return
    fig, axes = plt.subplots(1, 2, figsize=(8, 3.4))
    for ax, key, title in ((axes[0], "eye_trimmed", "eyes' pixels (trimmed 0.1%)"),
                           (axes[1], "frame_trimmed", "frame (trimmed 0.1%)")):
        for mode, style in (("plan", "o-"), ("every feature", "s--")):
            sel = [r for r in rows if r["mode"] == mode]
            ax.loglog([r["seconds"] for r in sel], [r[key] for r in sel], style, label=mode)
        ax.set_xlabel("render seconds")
        ax.set_ylabel("relative RMSE")
        ax.set_title(title)
        ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"eyestudy: plot {path}")


def main(argv=None):
    return run_command("eyestudy", run, argv)


if __name__ == "__main__":
    sys.exit(main())
