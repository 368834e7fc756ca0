"""What a render is, as both eyerecord paths read it: the local render and the farm (its client and its workers)
build their sessions from the same options with the same functions here.

The command line's pieces (frames, outputs, purposes, render settings overrides, what the render plan may not
decide) become a SessionOptions; `open_session` resolves it against a stage (a UsdRender.Settings prim fills in
what the options leave open) into a RenderSession. pxr is imported on use (the package's __init__ has registered
the EyeAPI schema plugin by then), and nothing here needs Dask.
"""
import dataclasses
import os
from typing import Optional

from .aovs import AOV_NAMES
from .defaults import DEFAULT_SPP, DEFAULT_WIDTH
from .errors import EyeRenderError
from .frames import check_placeholder_precision, has_placeholder, output_path, parse_frames
from .output_files import OUTPUT_EXTENSIONS
from .shutter import parse_shutter_arguments, settings_override

# usdrecord's --complexity names; the level is the Catmull-Clark refinement (Storm's mapping).
COMPLEXITY_REFINE_LEVELS = {"low": 0, "medium": 1, "high": 2, "veryhigh": 3}
PURPOSES = ("default", "render", "proxy", "guide")  # UsdGeom's
CHAMBER_ESTIMATORS = ("path", "cache", "controlVariate")  # RenderSettings.chamber_estimator's values
DEFAULT_TIME = float("nan")  # Usd.TimeCode.Default().GetValue(): usdrecord's --defaultTime


@dataclasses.dataclass(frozen=True)
class SessionOptions:
    """Everything a RenderSession is made from but the stage and the time, as plain data (hashable, picklable).

    width, height: pixels (width None: the render settings prim's, else DEFAULT_WIDTH; height None: the camera's
    aperture ratio); camera: a prim path or name (None: RenderSession's default); aovs: names from AOV_NAMES;
    render_settings_prim: a UsdRender.Settings prim path whose resolution, camera and first product's AOVs fill in
    what the options leave open; purposes: UsdGeom purposes besides "default" (None: the render settings prim's
    authored includedPurposes, else proxy, usdrecord's default); refine_level: Catmull-Clark levels;
    cornea_model: "ellipsoidCone"/"paraboloid" for every eye (None: as authored); settings: RenderSettings
    overrides as (name, value) pairs; plan: what the render plan may not decide (plan_options: e.g.
    (("mnee", False),)); () plans everything, None renders with no plan (the settings as given);
    render_pass_prim: a UsdRender.Pass whose renderSource names the settings prim (usdrecord's -rp); with neither,
    the stage's renderSettingsPrimPath metadata names it; camera_light: light a stage without lights from the
    camera (usdrecord's default; --disableCameraLight); strict: a texture that cannot be read is an EyeRenderError
    (False: a warning, and its fallback renders); shutter: (open, close) frames relative to the frame that
    override every shutter the stage authors (--shutter; (0, 0): sharp), None: the render camera's, with the
    render settings prim's disableMotionBlur / instantaneousShutter (shutter.py).
    """
    width: Optional[int] = None
    height: Optional[int] = None
    camera: Optional[str] = None
    aovs: tuple[str, ...] = ()
    render_settings_prim: Optional[str] = None
    purposes: Optional[tuple[str, ...]] = ("default", "proxy")
    refine_level: int = 2
    cornea_model: Optional[str] = None
    settings: tuple[tuple[str, object], ...] = ()
    plan: Optional[tuple[tuple[str, object], ...]] = ()
    render_pass_prim: Optional[str] = None
    camera_light: bool = True
    strict: bool = False
    shutter: Optional[tuple[float, float]] = None
    pixel_aspect: Optional[float] = None  # a pixel's width over its height (None: the render settings prim's, or 1)

    def __post_init__(self):
        for name, value in self.normalised().items():
            object.__setattr__(self, name, value)

    def normalised(self):
        """The fields that have one canonical form, in it: sequences as tuples, settings sorted by name."""
        return {"aovs": tuple(self.aovs), "purposes": None if self.purposes is None else tuple(self.purposes),
                "settings": tuple(sorted(dict(self.settings).items())),
                "shutter": None if self.shutter is None else tuple(float(v) for v in self.shutter)}

    def as_dict(self):
        """The SessionOptions fields (of a subclass too: a RenderJob's session) by name."""
        return {field.name: getattr(self, field.name) for field in dataclasses.fields(SessionOptions)}


def session_options(args):
    """SessionOptions from eyerecord's parsed command line."""
    return SessionOptions(
        width=args.imageWidth, height=args.imageHeight, camera=args.camera, aovs=tuple(args.aov or ()),
        render_settings_prim=args.renderSettingsPrimPath, render_pass_prim=args.renderPassPrimPath,
        camera_light=not args.disableCameraLight,
        purposes=None if args.purposes is None else parse_purposes(args.purposes),
        refine_level=COMPLEXITY_REFINE_LEVELS[args.complexity], cornea_model=args.cornea_model,
        settings=(("seed", args.seed), ("threads", args.threads), ("max_depth", args.max_depth),
                  ("mnee", not args.no_mnee), ("mnee_all_solutions", args.mnee_all_solutions),
                  ("dome_light_camera_visibility", args.enableDomeLightVisibility), ("sampler", args.sampler),
                  ("iris_light_splits", args.iris_light_splits), ("chamber_splits", args.chamber_splits),
                  *((("chamber_estimator", args.chamber_estimator),) if args.chamber_estimator else ()),
                  *((("catchlight_samples", args.catchlight_samples),) if args.catchlight_samples else ())),
        plan=plan_options(args), strict=args.strict,
        shutter=parse_shutter_arguments(args.shutter, args.disableMotionBlur))


def parse_purposes(groups):
    """--purposes values (each a list separated by commas and/or spaces, as usdrecord splits it; None: the
    default, proxy) as one tuple of purpose names; an unknown purpose is an EyeRenderError."""
    purposes = tuple(p for group in (groups or ["proxy"]) for p in group.replace(",", " ").split())
    unknown = [p for p in purposes if p not in PURPOSES]
    if unknown:
        raise EyeRenderError(f"--purposes: '{unknown[0]}' is not a UsdGeom purpose ({', '.join(PURPOSES)})")
    return purposes


def output_patterns(image_path, png):
    """The output names a render writes: image_path, and with `png` a .png preview beside an .exr."""
    outputs = [image_path]
    if png and image_path.lower().endswith(".exr"):
        outputs.append(image_path[:-4] + ".png")
    return tuple(outputs)


def frame_outputs(patterns, frame):
    """The files frame `frame` of a render writing `patterns` writes (None: the single unanimated render, whose
    names are the patterns as given)."""
    return [pattern if frame is None else output_path(pattern, frame) for pattern in patterns]


def check_output_extension(path):
    if os.path.splitext(path)[1].lower() not in OUTPUT_EXTENSIONS:
        raise EyeRenderError(f"output {path}: extension must be .exr or .png")


def frames_to_render(spec, image_path, default_time=False):
    """The frames of a --frames spec, with usdrecord's rules: with --frames the output name needs a '#'
    placeholder whose decimals can tell the frames apart (1:2x0.5 needs '#.#'); without, it must have none, and
    the single render is at the stage's start time code ([None]; open_session resolves it) or, with
    `default_time`, at the default time ([DEFAULT_TIME])."""
    if not spec:
        if has_placeholder(image_path):
            raise EyeRenderError(f"output {image_path}: a '#' frame placeholder needs --frames")
        return [DEFAULT_TIME] if default_time else [None]
    if default_time:
        raise EyeRenderError("--defaultTime and --frames contradict each other")
    frames = parse_frames(spec)
    if not has_placeholder(image_path):
        raise EyeRenderError(f"--frames needs a '#' frame placeholder in the output name ({image_path})")
    check_placeholder_precision(image_path, spec)
    return frames


def plan_options(args):
    """What the command line fixes for the render plan, as plain data (a farm job carries it to its workers);
    None with --no-auto-plan."""
    if args.mnee and args.no_mnee:
        raise EyeRenderError("--mnee and --no-mnee contradict each other")
    if args.no_auto_plan:
        return None
    mnee = False if args.no_mnee else True if args.mnee else None
    all_solutions = True if args.mnee_all_solutions else None
    return tuple((name, value) for name, value in (("mnee", mnee), ("mnee_all_solutions", all_solutions))
                 if value is not None)


def plan_overrides(options, stage, refine_level):
    """PlanOverrides from plan_options(), the --complexity refinement level (the plan's subdivision ceiling) and
    what the stage authors on its eyes: all three win over the planner. None for options None (no plan)."""
    from .plan import authored_eye_values, make_overrides

    if options is None:
        return None
    return make_overrides(**dict(options), refine_level_ceiling=refine_level, authored=authored_eye_values(stage))


def open_stage(path, session_layer=None, mask=None):
    """The USD stage at `path` as usdrecord opens it: with the layer at `session_layer` as its session layer (else
    an anonymous one), a resolver context for the asset, and with `mask` (prim paths separated by commas and/or
    spaces) only those prims, their ancestors and descendants. A missing or unreadable file is an EyeRenderError
    naming it, with USD's own reason summarised."""
    from pxr import Ar, Sdf, Tf, Usd

    from .usd_diagnostics import summarise_tf_error

    for what, file in (("", path), ("--sessionLayer ", session_layer)):
        if file is not None and not os.path.isfile(file):
            raise EyeRenderError(f"{what}{file}: no such file")
    try:
        root = Sdf.Layer.FindOrOpen(path)
        session = Sdf.Layer.FindOrOpen(session_layer) if session_layer else Sdf.Layer.CreateAnonymous()
        if not root or not session:
            raise EyeRenderError(f"{path if not root else session_layer}: cannot open layer")
        context = Ar.GetResolver().CreateDefaultContextForAsset(path)
        if mask:
            population = Usd.StagePopulationMask()
            for prim_path in mask.replace(",", " ").split():
                if not Sdf.Path.IsValidPathString(prim_path):
                    raise EyeRenderError(f"--mask: '{prim_path}' is not a prim path")
                population.Add(Sdf.Path(prim_path))
            stage = Usd.Stage.OpenMasked(root, session, context, population)
        else:
            stage = Usd.Stage.Open(root, session, context)
    except Tf.ErrorException as e:
        raise EyeRenderError(f"{path}: cannot open stage: {summarise_tf_error(e)}") from None
    if not stage:
        raise EyeRenderError(f"{path}: cannot open stage")
    return stage


def render_settings_path(stage, options):
    """The UsdRender.Settings prim path a render reads, by usdrecord's precedence: the options' settings prim, else
    the renderSource of their render pass prim, else the stage's renderSettingsPrimPath metadata; None for none."""
    from pxr import UsdRender

    if options.render_settings_prim and options.render_pass_prim:
        raise EyeRenderError("--renderSettingsPrimPath and --renderPassPrimPath contradict each other")
    if options.render_pass_prim:
        render_pass = UsdRender.Pass(stage.GetPrimAtPath(options.render_pass_prim)) \
            if stage.GetPrimAtPath(options.render_pass_prim) else None
        if not render_pass:
            raise EyeRenderError(f"--renderPassPrimPath {options.render_pass_prim}: no RenderPass prim there")
        targets = render_pass.GetRenderSourceRel().GetTargets()
        if not targets:
            raise EyeRenderError(f"--renderPassPrimPath {options.render_pass_prim}: renderSource is not authored")
        return str(targets[0])
    return options.render_settings_prim or stage.GetMetadata("renderSettingsPrimPath") or None


def read_render_settings(stage, path):
    """(width, height, camera path or None, AOV names) from the UsdRender.Settings prim at `path`."""
    from pxr import UsdRender

    settings = UsdRender.Settings(stage.GetPrimAtPath(path)) if stage.GetPrimAtPath(path) else None
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


def image_options(stage, options):
    """(width, height, camera, AOV names) of `options`, the render settings prim's where they leave them open.
    Like usdrecord, an explicit width wins over the prim's resolution (and the height then follows the camera)."""
    width, height, camera, aovs = options.width or DEFAULT_WIDTH, options.height, options.camera, list(options.aovs)
    settings_path = render_settings_path(stage, options)
    if settings_path:
        rs_width, rs_height, rs_camera, rs_aovs = read_render_settings(stage, settings_path)
        if not options.width:
            width, height = rs_width, height or rs_height
        camera, aovs = camera or rs_camera, aovs or rs_aovs
    return width, height, camera, aovs


def session_material_purposes(stage, options):
    """The material binding purposes a session resolves, in order: the render settings prim's authored
    materialBindingPurposes, else "preview" then all-purpose (materials.DEFAULT_BINDING_PURPOSES)."""
    from .materials import DEFAULT_BINDING_PURPOSES
    from .render_products import material_binding_purposes

    return material_binding_purposes(stage, render_settings_path(stage, options)) or DEFAULT_BINDING_PURPOSES


def session_purposes(stage, options):
    """The UsdGeom purposes a session renders: the options', else the render settings prim's authored
    includedPurposes, else proxy (usdrecord's --purposes default)."""
    from .render_products import included_purposes

    if options.purposes is not None:
        return options.purposes
    return included_purposes(stage, render_settings_path(stage, options)) or ("proxy",)


def product_sessions(stage, options, warn):
    """The render settings prim's products grouped by what a session renders: [(SessionOptions, [products])],
    one group per (camera, width, height), whose AOVs are those its products' vars need. The options' camera and
    size win over the products' (an explicit width with the height following the camera, as usdrecord).
    `warn(line)` takes one line per var or product that cannot be written; none at all is an EyeRenderError."""
    from .render_products import read_products

    settings_path = render_settings_path(stage, options)
    if not settings_path:
        raise EyeRenderError("no outputImagePath and no render settings prim (-rs, -rp or the stage's "
                             "renderSettingsPrimPath) whose products say what to write")
    products = read_products(stage, settings_path, warn)
    if not products:
        raise EyeRenderError(f"{settings_path}: no render product to write (give an outputImagePath)")
    groups = {}
    for product in products:
        camera = options.camera or product.camera
        width, height = (options.width, options.height) if options.width else \
            (product.width, options.height or product.height)
        groups.setdefault((camera, width, height, product.pixel_aspect), []).append(product)
    return [(dataclasses.replace(options, camera=camera, width=width, height=height, pixel_aspect=aspect,
                                 aovs=tuple(dict.fromkeys(a for p in group for a in p.aovs)),
                                 render_settings_prim=settings_path, render_pass_prim=None), group)
            for (camera, width, height, aspect), group in groups.items()]


def open_session(stage, options, time=None):
    """A RenderSession of `stage` made from SessionOptions, at frame `time` (None: the stage's start time code,
    usdrecord's time without --frames; DEFAULT_TIME: the default time)."""
    from pxr import Usd

    from .render_products import pixel_aspect_ratio
    from .render_session import RenderSession

    width, height, camera, aovs = image_options(stage, options)
    shutter = settings_override(stage, render_settings_path(stage, options), options.shutter)
    aspect = options.pixel_aspect or pixel_aspect_ratio(stage, render_settings_path(stage, options))
    return RenderSession(stage, width=width, height=height, camera=camera, aovs=aovs,
                         purposes=session_purposes(stage, options),
                         material_purposes=session_material_purposes(stage, options),
                         refine_level=options.refine_level, cornea_model=options.cornea_model,
                         time=Usd.TimeCode(time) if time is not None else Usd.TimeCode(stage.GetStartTimeCode()),
                         camera_light=options.camera_light,
                         settings={**dict(options.settings), "pixel_aspect_ratio": aspect},
                         plan_overrides=plan_overrides(options.plan, stage, options.refine_level),
                         strict=options.strict, shutter=shutter)


__all__ = ["AOV_NAMES", "CHAMBER_ESTIMATORS", "COMPLEXITY_REFINE_LEVELS", "DEFAULT_SPP", "DEFAULT_WIDTH", "PURPOSES",
           "DEFAULT_TIME", "SessionOptions", "session_options", "parse_purposes", "output_patterns", "frame_outputs",
           "check_output_extension", "frames_to_render", "plan_options", "plan_overrides", "open_stage",
           "render_settings_path", "read_render_settings", "image_options", "session_purposes",
           "session_material_purposes", "product_sessions", "open_session"]
