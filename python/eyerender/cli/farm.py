"""eyerecord --scheduler / --workers: the command line's farm render, built on eyerender.farm.

Prints one line per failed frame ("eyerecord: error: frame F: ...") and a summary line; the exit status is 1 if
any frame failed. Progress for the whole job: a bar on a terminal, one line per finished frame elsewhere (farm logs).
"""
import logging
import os
import sys

from ..console import FarmProgressBar, describe_written, print_warnings, warn_non_finite
from ..errors import EyeRenderError
from ..farm.job import RenderJob
from ..job import frames_to_render, output_patterns, session_options


def run_farm(args, spp):
    """eyerecord's run() for --scheduler/--workers, `spp` samples per pixel; returns the exit status."""
    for flag, value in (("--sessionLayer", args.sessionLayer), ("--mask", args.mask),
                        ("--colorCorrectionMode", None if args.colorCorrectionMode == "sRGB" else 1)):
        if value is not None:  # a farm job carries the stage's path alone, and writes sRGB PNGs
            raise EyeRenderError(f"{flag} is not supported with a farm render (--scheduler/--workers)")
    split = farm_split(args)
    if args.outputImagePath is None:
        job = products_job(args, spp)
        frames = frames_to_render(args.frames, job.products[0].name, args.defaultTime)
    else:
        frames = frames_to_render(args.frames, args.outputImagePath, args.defaultTime)  # the local path's rules
        job = RenderJob.from_options(args.usdFilePath, output_patterns(args.outputImagePath, args.png),
                                     session_options(args), spp=spp, exposure=args.exposure,
                                     time_limit=args.time_limit)
    if not os.path.isfile(job.stage_path) and args.workers:  # local workers see this machine's files
        raise EyeRenderError(f"{args.usdFilePath}: no such file")
    # Dask logs worker losses and reschedules as warnings; the report says what matters, once.
    logging.getLogger("distributed").setLevel(logging.ERROR)
    report = render_on_farm(args, job, frames, split)
    print_report(report, job, frames)
    return 0 if report.ok else 1


def products_job(args, spp):
    """The RenderJob of the render settings prim's products (no outputImagePath): one session renders them all, so
    products asking for different cameras or sizes are an error here (render them locally). The warnings of vars
    that cannot be written are printed here, once."""
    from ..job import open_stage, product_sessions

    warnings = []
    groups = product_sessions(open_stage(args.usdFilePath), session_options(args), warnings.append)
    print_warnings(warnings)
    if len(groups) > 1:
        raise EyeRenderError(f"the products ask for {len(groups)} cameras or image sizes: a farm render has one "
                             "(render them locally, or with -cam / -w)")
    options, products = groups[0]
    for product in products:
        frames_to_render(args.frames, product.name, args.defaultTime)  # each name's placeholder, checked
    return RenderJob.from_options(args.usdFilePath, (), options, spp=spp, exposure=args.exposure,
                                  time_limit=args.time_limit, products=tuple(products), png=args.png)


def farm_split(args):
    """Sample ranges per frame from --split (None: auto), after checking --workers and --split."""
    if args.workers is not None and args.workers < 1:
        raise EyeRenderError("--workers must be at least 1")
    split = None if args.split in (None, "auto") else _parse_split(args.split)
    if split and split > 1 and args.time_limit:
        raise EyeRenderError("--time-limit cannot be combined with --split: the sample ranges would not add up")
    return split


def render_on_farm(args, job, frames, split):
    """The FarmReport of `job`'s frames on the cluster the command line names, with its progress shown."""
    from ..farm import Farm

    bar = FarmProgressBar(not args.quiet)
    logged = not args.quiet and not bar.enabled

    def on_frame(frame, stats, error):
        if logged and stats:
            print(f"eyerecord: frame {_name(frame)} done on {stats['worker']}", file=sys.stderr)

    with Farm(scheduler=args.scheduler, workers=args.workers, timeout=args.scheduler_timeout) as farm:
        report = farm.render(job, frames, split=split, overwrite=args.overwrite, progress=bar, on_frame=on_frame)
    bar.finish()
    return report


def print_report(report, job, frames):
    """The frames' warnings, one error line per failed frame, and the summary line."""
    print_warnings(w for s in report.stats.values() for w in s["warnings"])
    warn_non_finite(sum(s["non_finite_samples"] for s in report.stats.values()))
    for frame, error in report.errors.items():
        print(f"eyerecord: error: frame {_name(frame)}: {error}", file=sys.stderr)
    written = [p for f in frames if f in report.stats for p in job.output_paths(f)]
    print(f"eyerecord: {report.summary()} -> {describe_written(written)}")


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
