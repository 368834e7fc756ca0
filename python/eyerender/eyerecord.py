"""eyerecord: render a USD stage to images, like usdrecord, with the eye renderer.

    eyerecord [options] usdFilePath outputImagePath

.exr outputs hold linear float AOVs (color in R, G, B, A; others as named channels); .png outputs are the colour,
tone-mapped to sRGB. Bad input ends with a one-line error and exit status 1 (2 for bad command-line syntax);
outputs are written atomically, so a failed or interrupted render never leaves a half-written image.
"""
import argparse
import os
import sys

from .errors import EyeRenderError, run_command
from .frames import has_placeholder, output_path, parse_frames

# usdrecord's --complexity names; the level is the Catmull-Clark refinement (Storm's mapping).
COMPLEXITY_REFINE_LEVELS = {"low": 0, "medium": 1, "high": 2, "veryhigh": 3}
AOV_NAMES = ("color", "albedo", "normal", "depth", "primId", "irisMnee", "limbalArc")


def build_parser():
    p = argparse.ArgumentParser(prog="eyerecord", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("usdFilePath", help="the USD file to render")
    p.add_argument("outputImagePath", help="image to write (.exr or .png); '#' placeholders take the frame number")
    p.add_argument("--camera", "-cam", help="camera prim path or name (default: main_cam, else the first camera, "
                   "else a 50 mm camera framing the stage)")
    p.add_argument("--frames", "-f", help="frames to render: F, start:end, start:endxstride, comma-separated")
    p.add_argument("--imageWidth", "-w", type=int, help="width in pixels (default: the render settings', else 960)")
    p.add_argument("--imageHeight", type=int, help="height in pixels (default: from the camera's aperture ratio)")
    p.add_argument("--complexity", "-c", choices=COMPLEXITY_REFINE_LEVELS, default="high",
                   help="subdivision refinement: low 0, medium 1, high 2, veryhigh 3 levels (default high)")
    p.add_argument("--purposes", action="append", default=None,
                   help="extra UsdGeom purposes to render besides 'default' (comma-separated or repeated; "
                   "default: proxy)")
    p.add_argument("--renderSettingsPrimPath", "-rs", help="a UsdRender.Settings prim: its resolution, camera and "
                   "the AOVs its first product names")
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
    p.add_argument("--cornea-model", choices=("ellipsoidCone", "paraboloid"), help="A/B: override every eye's model")
    p.add_argument("--no-mnee", action="store_true",
                   help="A/B: iris direct light by path tracing through the cornea instead of MNEE")
    p.add_argument("--mnee-all-solutions", action="store_true", help="search every refraction path (caustic folds)")
    p.add_argument("--mnee", action="store_true", help="MNEE on for every eye, whatever the render plan finds")
    p.add_argument("--plan", action="store_true", help="print the render plan (JSON) on stdout and exit: nothing is "
                   "rendered or written (docs/render_plan.md)")
    p.add_argument("--no-auto-plan", action="store_true", help="no render plan: MNEE, sclera scattering etc. as the "
                   "flags and the renderer's defaults say")
    p.add_argument("--strict", action="store_true", help="a texture that cannot be read is an error (default: a "
                   "warning, and its fallback renders)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    farm = p.add_argument_group("render farm (Dask; docs/farm.md)")
    farm.add_argument("--scheduler", metavar="ADDRESS", help="render on the Dask cluster of this scheduler "
                      "(e.g. tcp://127.0.0.1:8786); the stage and outputs must be reachable from its workers")
    farm.add_argument("--workers", type=int, metavar="N", help="render on a local cluster of N worker processes")
    farm.add_argument("--split", metavar="K", help="sample ranges per frame, merged exactly (default auto: "
                      "enough to give every worker work)")
    farm.add_argument("--overwrite", action="store_true",
                      help="re-render frames whose outputs exist (by default a farm job skips them)")
    farm.add_argument("--scheduler-timeout", type=float, default=10.0, metavar="SECONDS",
                      help="how long to try to reach --scheduler (default 10)")
    return p


class ProgressBar:
    """A one-line progress bar on a terminal's stderr; silent elsewhere (logs, CI)."""

    def __init__(self, enabled):
        self.enabled = enabled and sys.stderr.isatty()
        self.label = ""

    def __call__(self, done, total, seconds):
        if not self.enabled:
            return
        width = 30
        filled = int(width * done / max(total, 1))
        eta = seconds / done * (total - done) if done else 0.0
        sys.stderr.write(f"\r{self.label} [{'#' * filled}{'.' * (width - filled)}] {done}/{total} spp "
                         f"{seconds:6.1f} s  eta {eta:5.1f} s ")
        sys.stderr.flush()

    def finish(self):
        if self.enabled:
            sys.stderr.write("\n")


def _open_stage(path):
    from pxr import Tf, Usd

    if not os.path.isfile(path):
        raise EyeRenderError(f"{path}: no such file")
    try:
        stage = Usd.Stage.Open(path)
    except Tf.ErrorException as e:
        first = next((line.strip() for line in str(e).splitlines() if line.strip()), "unreadable")
        raise EyeRenderError(f"{path}: cannot open stage: {first}") from None
    if not stage:
        raise EyeRenderError(f"{path}: cannot open stage")
    return stage


def _render_settings(stage, path):
    """(width, height, camera path, AOV names) from a UsdRender.Settings prim."""
    from pxr import UsdRender

    settings = UsdRender.Settings(stage.GetPrimAtPath(path))
    if not settings:
        raise EyeRenderError(f"--renderSettingsPrimPath {path}: no RenderSettings prim there")
    resolution = settings.GetResolutionAttr().Get()
    cameras = settings.GetCameraRel().GetTargets()
    aovs = []
    products = settings.GetProductsRel().GetTargets()
    if products:
        product = UsdRender.Product(stage.GetPrimAtPath(products[0]))
        for var_path in product.GetOrderedVarsRel().GetTargets() if product else []:
            source = UsdRender.Var(stage.GetPrimAtPath(var_path)).GetSourceNameAttr().Get()
            if source in AOV_NAMES:
                aovs.append(source)
    return resolution[0], resolution[1], str(cameras[0]) if cameras else None, aovs


def plan_options(args):
    """What the command line fixes for the render plan, as plain data (a farm job carries it to its workers);
    None with --no-auto-plan."""
    if args.mnee and args.no_mnee:
        raise EyeRenderError("--mnee and --no-mnee contradict each other")
    if args.no_auto_plan:
        return None
    return tuple((name, value) for name, value in (("mnee", False if args.no_mnee else True if args.mnee else None),
                                                   ("mnee_all_solutions", True if args.mnee_all_solutions else None))
                 if value is not None)


def plan_overrides(options, stage, refine_level):
    """PlanOverrides from plan_options(), the --complexity refinement level (the plan's subdivision ceiling) and
    what the stage authors on its eyes: all three win over the planner. None for options None (no plan)."""
    from .plan import authored_eye_values, make_overrides

    if options is None:
        return None
    return make_overrides(**dict(options), refine_level_ceiling=refine_level, authored=authored_eye_values(stage))


def run(argv=None):
    args = build_parser().parse_args(argv)
    import eyerender  # registers the EyeAPI plugin before pxr loads stages

    from .render_session import RenderSession, check_writable

    if args.spp is not None and args.spp < 1:
        raise EyeRenderError("--spp must be at least 1")
    if args.time_limit < 0 or (args.imageWidth or 1) < 1 or args.threads < 0 or args.max_depth < 1:
        raise EyeRenderError("--time-limit, --imageWidth, --threads and --max-depth must be positive")
    spp = args.spp or (1 << 20 if args.time_limit else 32)
    if (args.scheduler or args.workers is not None) and not args.plan:  # --plan never renders
        from .farm_cli import run_farm

        return run_farm(args, spp, COMPLEXITY_REFINE_LEVELS)
    stage = _open_stage(args.usdFilePath)
    frames = parse_frames(args.frames) if args.frames else [None]
    if len(frames) > 1 and not has_placeholder(args.outputImagePath):
        raise EyeRenderError(f"{len(frames)} frames need a '#' placeholder in the output name "
                             f"({args.outputImagePath})")
    outputs = [args.outputImagePath]
    if args.png and args.outputImagePath.lower().endswith(".exr"):
        outputs.append(args.outputImagePath[:-4] + ".png")
    for out in outputs if not args.plan else []:  # --plan writes nothing
        if os.path.splitext(out)[1].lower() not in (".exr", ".png"):
            raise EyeRenderError(f"output {out}: extension must be .exr or .png")
        check_writable(out)

    width, height, camera, aovs = args.imageWidth or 960, args.imageHeight, args.camera, list(args.aov or [])
    if args.renderSettingsPrimPath:
        rs_width, rs_height, rs_camera, rs_aovs = _render_settings(stage, args.renderSettingsPrimPath)
        if not args.imageWidth:  # like usdrecord, an explicit width wins (and the height follows the camera)
            width, height = rs_width, height or rs_height
        camera, aovs = camera or rs_camera, aovs or rs_aovs
    purposes = [p for group in (args.purposes or ["proxy"]) for p in group.split(",") if p]
    from pxr import Usd

    first_time = Usd.TimeCode(frames[0]) if frames[0] is not None else Usd.TimeCode.EarliestTime()
    session = RenderSession(
        stage, width=width, height=height, camera=camera, aovs=aovs, purposes=purposes,
        refine_level=COMPLEXITY_REFINE_LEVELS[args.complexity], cornea_model=args.cornea_model, time=first_time,
        settings={"seed": args.seed, "threads": args.threads, "max_depth": args.max_depth,
                  "mnee": not args.no_mnee, "mnee_all_solutions": args.mnee_all_solutions},
        plan_overrides=plan_overrides(plan_options(args), stage, COMPLEXITY_REFINE_LEVELS[args.complexity]),
        strict=args.strict)
    if args.plan:
        print(session.plan().to_json())
        return 0
    if not args.no_auto_plan:
        for line in session.plan().summary_lines():
            print(f"eyerecord: {line}")
    for warning in dict.fromkeys(session.scene.warnings):
        print(f"eyerecord: warning: {warning}", file=sys.stderr)

    bar = ProgressBar(not args.quiet)
    total_seconds, total_rays, written = 0.0, 0, []
    for n, frame in enumerate(frames):
        bar.label = f"frame {frame:g} ({n + 1}/{len(frames)})" if frame is not None else "render"
        stats = session.render(None if frame is None or n == 0 else frame, spp=spp, time_limit=args.time_limit,
                               progress=bar)
        bar.finish()
        if stats["non_finite_samples"]:
            print(f"eyerecord: warning: {stats['non_finite_samples']} NaN/Inf samples were dropped (a renderer bug)",
                  file=sys.stderr)
        for out in outputs:
            path = output_path(out, frame) if frame is not None else out
            session.write(path, args.exposure)
            written.append(path)
        total_seconds, total_rays = total_seconds + stats["seconds"], total_rays + stats["rays"]
    rate = total_rays / total_seconds / 1e6 if total_seconds > 0 else 0.0
    shown = written[0] if len(written) == 1 else f"{written[0]} .. {written[-1]} ({len(written)} files)"
    print(f"eyerecord: {len(frames)} frame(s) {session.width}x{session.height}, {stats['samples_per_pixel']} spp, "
          f"{total_seconds:.1f} s, {rate:.2f} Mrays/s -> {shown}")
    return 0


def main(argv=None):
    return run_command("eyerecord", run, argv, interrupted="interrupted; nothing was written for the unfinished frame")


if __name__ == "__main__":
    sys.exit(main())
