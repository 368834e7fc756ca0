"""eyerecord --scheduler / --workers: the command line's farm render, built on eyerender.farm.

Prints one line per failed frame ("eyerecord: error: frame F: ...") and a summary line; the exit status is 1 if
any frame failed. Progress for the whole job: a bar on a terminal, one line per finished frame elsewhere (farm logs).
"""
import logging
import os
import sys

from .errors import EyeRenderError
from .frames import has_placeholder, parse_frames


def _job_from_args(args, spp, COMPLEXITY_REFINE_LEVELS):
    from .eyerecord import plan_options
    from .farm_job import RenderJob

    outputs = [args.outputImagePath]
    if args.png and args.outputImagePath.lower().endswith(".exr"):
        outputs.append(args.outputImagePath[:-4] + ".png")
    purposes = [p for group in (args.purposes or ["proxy"]) for p in group.split(",") if p]
    return RenderJob(
        stage_path=args.usdFilePath, outputs=tuple(outputs), spp=spp, width=args.imageWidth,
        height=args.imageHeight, camera=args.camera, aovs=tuple(args.aov or ()),
        render_settings_prim=args.renderSettingsPrimPath, purposes=tuple(purposes),
        refine_level=COMPLEXITY_REFINE_LEVELS[args.complexity], cornea_model=args.cornea_model,
        settings=(("seed", args.seed), ("threads", args.threads), ("max_depth", args.max_depth),
                  ("mnee", not args.no_mnee), ("mnee_all_solutions", args.mnee_all_solutions)),
        exposure=args.exposure, time_limit=args.time_limit, plan=plan_options(args))


class _FarmProgressBar:
    """The job's progress on a terminal's stderr: frames, samples, time, time left."""

    def __init__(self, enabled):
        self.enabled = enabled and sys.stderr.isatty()

    def __call__(self, p):
        if not self.enabled:
            return
        eta = f"{p.eta:5.1f} s" if p.eta is not None else "  ?"
        sys.stderr.write(f"\rframes {p.frames_done}/{p.frames_total}  samples {p.samples_done}/{p.samples_total}  "
                         f"{p.seconds:6.1f} s  eta {eta} ")
        sys.stderr.flush()


def run_farm(args, spp, complexity_levels):
    """eyerecord's run() for --scheduler/--workers; returns the exit status."""
    # Rendering the outputs of frames: same rules as the local path.
    frames = parse_frames(args.frames) if args.frames else [None]
    if len(frames) > 1 and not has_placeholder(args.outputImagePath):
        raise EyeRenderError(f"{len(frames)} frames need a '#' placeholder in the output name "
                             f"({args.outputImagePath})")
    if args.workers is not None and args.workers < 1:
        raise EyeRenderError("--workers must be at least 1")
    split = None if args.split in (None, "auto") else _parse_split(args.split)
    if split and split > 1 and args.time_limit:
        raise EyeRenderError("--time-limit cannot be combined with --split: the sample ranges would not add up")
    job = _job_from_args(args, spp, complexity_levels)
    if not os.path.isfile(job.stage_path) and args.workers:  # local workers see this machine's files
        raise EyeRenderError(f"{args.usdFilePath}: no such file")
    # Dask logs worker losses and reschedules as warnings; the report says what matters, once.
    logging.getLogger("distributed").setLevel(logging.ERROR)

    from .farm import Farm

    bar = _FarmProgressBar(not args.quiet)
    logged = not args.quiet and not bar.enabled

    def on_frame(frame, stats, error):
        if logged and stats:
            print(f"eyerecord: frame {_name(frame)} done on {stats['worker']}", file=sys.stderr)

    with Farm(scheduler=args.scheduler, workers=args.workers, timeout=args.scheduler_timeout) as farm:
        report = farm.render(job, frames, split=split, overwrite=args.overwrite, progress=bar, on_frame=on_frame)
    if bar.enabled:
        sys.stderr.write("\n")
    warnings = dict.fromkeys(w for s in report.stats.values() for w in s["warnings"])
    for warning in warnings:
        print(f"eyerecord: warning: {warning}", file=sys.stderr)
    non_finite = sum(s["non_finite_samples"] for s in report.stats.values())
    if non_finite:
        print(f"eyerecord: warning: {non_finite} NaN/Inf samples were dropped (a renderer bug)", file=sys.stderr)
    for frame, error in report.errors.items():
        print(f"eyerecord: error: frame {_name(frame)}: {error}", file=sys.stderr)
    written = [p for f in frames if f in report.stats for p in job.output_paths(f)]
    shown = "nothing written" if not written else written[0] if len(written) == 1 else \
        f"{written[0]} .. {written[-1]} ({len(written)} files)"
    print(f"eyerecord: {report.summary()} -> {shown}")
    return 0 if report.ok else 1


def _name(frame):
    return "(default time)" if frame is None else f"{frame:g}"


def _parse_split(text):
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise EyeRenderError(f"--split: '{text}' is not a positive number of sample ranges or 'auto'")
    return value


__all__ = ["run_farm"]
