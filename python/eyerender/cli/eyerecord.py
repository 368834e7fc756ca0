"""eyerecord: render a USD stage to images, like usdrecord, with the eye renderer.

    eyerecord [options] usdFilePath outputImagePath

.exr outputs hold linear float AOVs (color in R, G, B, A; others as named channels); .png outputs are the colour,
encoded by --colorCorrectionMode (sRGB by default). The flags usdrecord has mean what they mean to usdrecord
(docs/eyerecord.md compares them). Bad input ends with a one-line error and exit status 1 (2 for bad command-line
syntax); a prim that cannot be rendered is skipped with one warning; outputs are written atomically, so a failed
or interrupted render never leaves a half-written image, and a render failing part-way names the files it wrote.
"""
import argparse
import dataclasses
import sys

from ..console import ProgressBar, describe_written, print_warnings, warn_non_finite
from ..denoise import GUIDE_AOVS, denoised_png_path
from ..errors import EyeRenderError, run_command
from ..job import (
    AOV_NAMES,
    CHAMBER_ESTIMATORS,
    COMPLEXITY_REFINE_LEVELS,
    DEFAULT_SPP,
    PURPOSES,
    check_output_extension,
    frame_outputs,
    frames_to_render,
    open_session,
    open_stage,
    output_patterns,
    product_sessions,
    render_settings_path,
    session_options,
)
from ..output_files import COLOR_CORRECTION_MODES, partial_failure
from ..plan import plan_json
from ..product_output import product_outputs, product_summary

RENDERERS = ("Eye", "hdeye")  # --renderer: the display name and the delegate's name; there is no other renderer


def build_parser():
    # No abbreviations: usdrecord's -r must never be taken as a prefix of another flag.
    p = argparse.ArgumentParser(prog="eyerecord", description=__doc__.split("\n\n")[0], allow_abbrev=False,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("usdFilePath", help="the USD file to render")
    p.add_argument("outputImagePath", nargs="?", help="image to write (.exr or .png); '#' placeholders take the "
                   "frame number; omitted: the render settings prim's products (docs/render_products.md)")
    p.add_argument("--camera", "-cam", help="camera prim path or name (default: main_cam, else the first camera, "
                   "else a 50 mm camera framing the stage)")
    time = p.add_mutually_exclusive_group()
    time.add_argument("--frames", "-f", help="frames to render: F, start:end, start:endxstride, comma-separated "
                      "(default: the stage's start time code)")
    time.add_argument("--defaultTime", "-d", action="store_true", help="render at the default time code")
    p.add_argument("--sessionLayer", metavar="SESSIONLAYER", help="open the stage with this layer as its session "
                   "layer (e.g. to pick a variant)")
    p.add_argument("--mask", metavar="PRIMPATH[,PRIMPATH...]", help="populate only these prims, their ancestors "
                   "and descendants (paths separated by commas and/or spaces)")
    p.add_argument("--imageWidth", "-w", type=int, help="width in pixels (default: the render settings', else 960)")
    p.add_argument("--imageHeight", type=int, help="height in pixels (default: from the camera's aperture ratio)")
    # usdrecord's default: UsdAppUtils.complexityArgs adds --complexity with RefinementComplexities.LOW.
    p.add_argument("--complexity", "-c", choices=COMPLEXITY_REFINE_LEVELS, default="low",
                   help="subdivision refinement ceiling: low 0, medium 1, high 2, veryhigh 3 levels (default low, as "
                        "usdrecord); the render plan lowers it per mesh by size on screen")
    p.add_argument("--purposes", action="append", default=None, metavar="PURPOSE[,PURPOSE...]",
                   help=f"extra UsdGeom purposes to render besides 'default' ({', '.join(PURPOSES[1:])}; separated "
                   "by commas and/or spaces; default: proxy)")
    p.add_argument("--renderSettingsPrimPath", "-rs", help="a UsdRender.Settings prim: its resolution, camera, "
                   "purposes and products, each written with exactly its vars (with an outputImagePath: that file, "
                   "with the AOVs of its first product; default: the stage's renderSettingsPrimPath metadata)")
    p.add_argument("--renderPassPrimPath", "-rp", help="a UsdRender.Pass prim: the settings prim its renderSource "
                   "names")
    p.add_argument("--renderer", "-r", choices=RENDERERS, default="Eye", help="the Hydra renderer (only Eye)")
    p.add_argument("--disableCameraLight", action="store_true",
                   help="no camera light for a stage without lights (by default one is added, with a note)")
    p.add_argument("--enableDomeLightVisibility", action="store_true",
                   help="show dome lights in the background (by default they light the scene unseen, as usdrecord)")
    p.add_argument("--shutter", nargs="+", type=float, metavar="FRAMES",
                   help="OPEN CLOSE: shutter open and close in frames relative to the frame (e.g. -0.25 0.25), over "
                   "the camera's shutter:open/close and the render settings'; 0: sharp (docs/motion_blur.md)")
    p.add_argument("--disableMotionBlur", action="store_true",
                   help="a sharp render whatever the stage's shutter (UsdRender's disableMotionBlur; --shutter 0)")
    p.add_argument("--colorCorrectionMode", "-color", choices=COLOR_CORRECTION_MODES, default="sRGB",
                   help="PNG encoding: sRGB, disabled (linear values), openColorIO (sRGB: no OCIO config is read)")
    p.add_argument("--spp", type=int, help="samples per pixel (default 32; with --time-limit alone: until time is up)")
    p.add_argument("--time-limit", type=float, default=0.0, metavar="SECONDS",
                   help="stop each frame's progressive render once this many seconds are spent")
    p.add_argument("--seed", type=int, default=0, help="random seed (the image is a pure function of it)")
    p.add_argument("--threads", type=int, default=0, help="render threads (default: all cores)")
    p.add_argument("--max-depth", type=int, default=8, help="path vertices after the camera (default 8)")
    p.add_argument("--aov", action="append", choices=AOV_NAMES, help="AOV to write to .exr outputs (repeatable; "
                   "color is always written)")
    p.add_argument("--exposure", type=float, default=0.0, help="PNG exposure in stops (default 0)")
    p.add_argument("--png", action="store_true", help="with an .exr output, also write a .png preview beside it")
    p.add_argument("--denoise", action="store_true", help="also write the beauty denoised by Intel Open Image "
                   "Denoise (albedo and normal AOVs as guides): EXR channels denoised.R/G/B, PNG <name>.denoised.png; "
                   "the raw beauty is kept (docs/denoise.md)")
    p.add_argument("--cornea-model", choices=("ellipsoidCone", "paraboloid"), help="A/B: override every eye's model")
    p.add_argument("--no-mnee", action="store_true",
                   help="A/B: iris direct light by path tracing through the cornea instead of MNEE")
    p.add_argument("--mnee-all-solutions", action="store_true", help="search every refraction path (caustic folds)")
    p.add_argument("--chamber-estimator", choices=CHAMBER_ESTIMATORS, default=None,
                   help="how the iris gathers chamber light (default: the renderer's; docs/iris_benchmark.md)")
    p.add_argument("--mnee", action="store_true", help="MNEE on for every eye, whatever the render plan finds")
    p.add_argument("--sampler", choices=("zsobol", "independent"), default="zsobol",
                   help="A/B: paths' random numbers, Owen-scrambled Sobol in Z order (default) or independent hashes")
    p.add_argument("--iris-light-splits", type=int, default=1, metavar="N",
                   help="eyes: MNEE light estimates averaged at a path's first iris vertex (default 1)")
    p.add_argument("--chamber-splits", type=int, default=1, metavar="N",
                   help="eyes: chamber walks continued from a path's first iris vertex (default 1)")
    p.add_argument("--catchlight-samples", type=int, default=None, metavar="N",
                   help="eyes: reflection-only paths per sample in the pixels at a catchlight's edge (1: none; "
                   "default: the renderer's, 16)")
    p.add_argument("--plan", action="store_true", help="print the render plan (JSON) on stdout and exit: nothing is "
                   "rendered or written (docs/render_plan.md)")
    p.add_argument("--no-auto-plan", action="store_true", help="no render plan: MNEE, sclera scattering etc. as the "
                   "flags and the renderer's defaults say")
    p.add_argument("--strict", action="store_true", help="a texture that cannot be read is an error (default: a "
                   "warning, and its fallback renders)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    add_farm_options(p.add_argument_group("render farm (Dask; docs/farm.md)"))
    return p


def add_farm_options(farm):
    """--scheduler/--workers and what a farm render takes besides (cli/farm.py run_farm reads them)."""
    farm.add_argument("--scheduler", metavar="ADDRESS", help="render on the Dask cluster of this scheduler "
                      "(e.g. tcp://127.0.0.1:8786); the stage and outputs must be reachable from its workers")
    farm.add_argument("--workers", type=int, metavar="N", help="render on a local cluster of N worker processes")
    farm.add_argument("--split", metavar="K", help="sample ranges per frame, merged exactly (default auto: "
                      "enough to give every worker work)")
    farm.add_argument("--overwrite", action="store_true",
                      help="re-render frames whose outputs exist (by default a farm job skips them)")
    farm.add_argument("--scheduler-timeout", type=float, default=10.0, metavar="SECONDS",
                      help="how long to try to reach --scheduler (default 10)")


def run(argv=None):
    """eyerecord with the command line `argv` (None: sys.argv); returns the exit status."""
    args = build_parser().parse_args(argv)
    spp = samples_per_pixel(args)
    if args.outputImagePath is None and (args.aov or args.denoise):
        raise EyeRenderError(f"{'--aov' if args.aov else '--denoise'} needs an outputImagePath: render products "
                             "write the vars they order")
    if (args.scheduler or args.workers is not None) and not args.plan:  # --plan never renders
        if args.denoise:
            raise EyeRenderError("--denoise is not available on the farm yet: denoise a local render")
        from .farm import run_farm

        return run_farm(args, spp)
    return render_locally(args, spp)


def samples_per_pixel(args):
    """The samples per pixel to render, after checking the numeric options: --spp, else 32 (with --time-limit
    alone: as many as the time allows)."""
    if args.spp is not None and args.spp < 1:
        raise EyeRenderError("--spp must be at least 1")
    if args.time_limit < 0 or args.threads < 0 or args.max_depth < 1:
        raise EyeRenderError("--time-limit, --threads and --max-depth must be positive")
    for name in ("iris_light_splits", "chamber_splits"):
        if not 1 <= getattr(args, name) <= 64:
            raise EyeRenderError(f"--{name.replace('_', '-')} {getattr(args, name)}: must be 1 to 64")
    if args.catchlight_samples is not None and not 1 <= args.catchlight_samples <= 256:
        raise EyeRenderError(f"--catchlight-samples {args.catchlight_samples}: must be 1 to 256")
    for name in ("imageWidth", "imageHeight"):
        if getattr(args, name) is not None and getattr(args, name) < 1:
            raise EyeRenderError(f"--{name} {getattr(args, name)}: must be at least 1 pixel")
    return args.spp or (1 << 20 if args.time_limit else DEFAULT_SPP)


def render_locally(args, spp):
    """Renders (or with --plan, plans) the frames on this machine; returns the exit status."""
    from ..usd_diagnostics import UsdDiagnostics

    diagnostics = UsdDiagnostics()  # USD's warnings become one line each, printed with the scene's
    stage = open_stage(args.usdFilePath, args.sessionLayer, args.mask)
    options = session_options(args)
    if args.outputImagePath is None:
        return render_products_locally(args, spp, stage, options, diagnostics)
    frames = frames_to_render(args.frames, args.outputImagePath, args.defaultTime)
    outputs = output_patterns(args.outputImagePath, args.png)
    if not args.plan:  # --plan writes nothing
        check_outputs(outputs)
    if args.denoise:  # OIDN's guides
        options = dataclasses.replace(options, aovs=tuple(dict.fromkeys(("color", *options.aovs, *GUIDE_AOVS))))
    session = open_session(stage, options, frames[0])
    if args.plan:
        print(plan_json(session.plan()))
        return 0
    note_unwritten_products(stage, options)
    report_plan_and_warnings(session, planned=not args.no_auto_plan, usd_warnings=diagnostics.take_warnings())

    def write(frame, written):
        for path in frame_outputs(outputs, frame):
            session.write(path, args.exposure, args.colorCorrectionMode, denoise=args.denoise)
            written.append(path)
            if args.denoise and path.lower().endswith(".png"):
                written.append(denoised_png_path(path))

    render_frames([(session, write)], frames, spp, args)
    print_warnings(diagnostics.take_warnings())
    return 0


def render_products_locally(args, spp, stage, options, diagnostics):
    """Renders the render settings prim's products (no outputImagePath): one session per camera and resolution
    the products ask for, each frame rendered once per session and written to every product of it."""
    warnings = []
    groups = product_sessions(stage, options, warnings.append)
    frames = frames_to_render(args.frames, groups[0][1][0].name, args.defaultTime)
    for _, products in groups:
        for product in products:
            frames_to_render(args.frames, product.name, args.defaultTime)  # each name's placeholder, checked
            if not args.plan:
                check_outputs(product_outputs(product, args.png))
    sessions = [(open_session(stage, group_options, frames[0]), products) for group_options, products in groups]
    if args.plan:
        print(plan_json(sessions[0][0].plan()))
        return 0
    for _, products in groups:
        for product in products:
            print(f"eyerecord: {product_summary(product)}")
    print_warnings(warnings)
    for n, (session, _) in enumerate(sessions):
        report_plan_and_warnings(session, planned=not args.no_auto_plan and n == 0,
                                 usd_warnings=diagnostics.take_warnings())
    settings_path = groups[0][0].render_settings_prim
    targets = [(session, product_writer(session, products, settings_path, args)) for session, products in sessions]
    render_frames(targets, frames, spp, args)
    print_warnings(diagnostics.take_warnings())
    return 0


def product_writer(session, products, settings_path, args):
    """write(frame, written) for render_frames: every product of a session at that frame."""
    def write(frame, written):
        for product in products:
            for pattern in product_outputs(product, args.png):
                path = frame_outputs([pattern], frame)[0]
                session.write_product(path, product, args.exposure, args.colorCorrectionMode,
                                      settings_path=settings_path)
                written.append(path)
    return write


def note_unwritten_products(stage, options):
    """One note when an outputImagePath stands in for a render settings prim's products."""
    from ..render_products import read_products

    path = render_settings_path(stage, options)
    if path:
        products = read_products(stage, path, lambda _: None)
        if products:
            print(f"eyerecord: note: {path}'s {len(products)} product(s) not written: the outputImagePath is "
                  "(omit it to write them)")


def check_outputs(outputs):
    """Fails before rendering if an output has the wrong extension or cannot be written."""
    from ..render_session import check_writable

    for out in outputs:
        check_output_extension(out)
        check_writable(out)


def report_plan_and_warnings(session, planned, usd_warnings=()):
    """Prints the camera light's note, the render plan's summary (when the session plans) and the scene's and
    USD's warnings, each once."""
    from ..camera_light import NOTE

    if session.camera_light:
        print(f"eyerecord: {NOTE}")
    if planned:
        for line in session.plan().summary_lines():
            print(f"eyerecord: {line}")
    print_warnings(list(usd_warnings) + session.scene.warnings)


def render_frames(targets, frames, spp, args):
    """Renders each frame with each target's session and writes its outputs (`write(frame, written)` appends each
    path to `written` once the file is complete), then prints the summary line. A failure part-way keeps the files
    already written (each is complete) and its error line names them."""
    bar = ProgressBar(not args.quiet, args.time_limit)
    total_seconds, total_rays, total_samples, first_pixel, written = 0.0, 0, 0.0, [], []
    warned = {id(session): len(session.scene.warnings) for session, _ in targets}  # printed before rendering
    for n, frame in enumerate(frames):
        bar.label = f"frame {frame:g} ({n + 1}/{len(frames)})" if frame is not None else "render"
        for session, write in targets:
            try:
                # The session was opened at the first frame's time.
                stats = session.render(None if frame is None or n == 0 else frame, spp=spp,
                                       time_limit=args.time_limit, progress=bar)
                bar.finish()
                if not args.quiet and not bar.enabled and len(frames) > 1:  # a log: one line per frame
                    print(f"eyerecord: {bar.label}: {frame_line(stats)}")
                warn_non_finite(stats["non_finite_samples"])
                print_warnings(session.scene.warnings[warned[id(session)]:])  # a later frame may add some
                warned[id(session)] = len(session.scene.warnings)
                write(frame, written)
            except EyeRenderError as e:
                bar.finish()
                where = f"frame {frame:g}: " if frame is not None and len(frames) > 1 else ""
                raise EyeRenderError(partial_failure(f"{where}{e}", written)) from None
            total_seconds, total_rays = total_seconds + stats["seconds"], total_rays + stats["rays"]
            total_samples += stats["samples_per_second"] * stats["seconds"]
            first_pixel.append(stats["time_to_first_pixel"] or 0.0)
    rate = total_rays / total_seconds / 1e6 if total_seconds > 0 else 0.0
    session = targets[0][0]
    blur = f", {session.scene.shutter.describe()}" if session.scene.shutter.blurred else ""
    print(f"eyerecord: {len(frames)} frame(s) {session.width}x{session.height}, {stats['samples_per_pixel']} spp"
          f"{blur}, {total_seconds:.2f} s, {rate:.2f} Mrays/s, first pixel {max(first_pixel):.3f} s, "
          f"{total_samples / total_seconds / 1e6 if total_seconds > 0 else 0.0:.2f} Msamples/s "
          f"-> {describe_written(written)}")


def frame_line(stats):
    """One frame's render, for a log: samples, time, time to first pixel, rate."""
    return (f"{stats['samples_per_pixel']} spp, {stats['seconds']:.2f} s, first pixel "
            f"{stats['time_to_first_pixel'] or 0.0:.3f} s, {stats['samples_per_second'] / 1e6:.2f} Msamples/s")


def main(argv=None):
    return run_command("eyerecord", run, argv, interrupted="interrupted; nothing was written for the unfinished frame")


if __name__ == "__main__":
    sys.exit(main())
