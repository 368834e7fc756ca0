"""The render's shutter: the interval, in frames relative to the frame being rendered, over which one frame's
exposure integrates (UsdGeomCamera's shutter:open and shutter:close, in UsdTimeCode units; negative opens before
the frame's time code). An interval of zero width is a sharp render at the frame's time, today's render exactly.

Precedence, as Hydra resolves it for usdrecord (hdsi's render settings filtering scene index; UsdRender's schema):
1. `eyerecord --shutter OPEN CLOSE` (or `--shutter 0`, `--disableMotionBlur`: sharp) wins over everything;
2. the UsdRender.Settings prim the render reads, or its first RenderProduct (a product's own authored value wins
   over the settings'), with `disableMotionBlur = true`: [0, 0]; with the deprecated `instantaneousShutter = true`:
   close = open;
3. the render camera's shutter:open / shutter:close at the frame (both default 0: sharp).

UsdRender authors no interval of its own, only those two switches. A stage's shutter that is not finite, closes
before it opens or reaches beyond MAX_SHUTTER_FRAMES is one warning naming the camera and a sharp render; the same
on the command line is an error (ShutterOverride.check).
"""
import dataclasses
import math
from typing import Optional

from .errors import EyeRenderError

# Frames either side of the frame a shutter may reach: beyond this an exposure is a trail over many frames, not a
# film shutter (and would pull in every time sample of a shot).
MAX_SHUTTER_FRAMES = 10.0


@dataclasses.dataclass(frozen=True)
class Shutter:
    """A resolved shutter: open and close in frames relative to the frame, and where it came from (for messages)."""
    open: float = 0.0
    close: float = 0.0
    source: str = "sharp"

    @property
    def blurred(self):
        """Whether the exposure spans time (open < close); a zero-width shutter is the sharp render."""
        return self.close > self.open

    def interval(self, frame):
        """(first, last) time code the exposure of frame `frame` (a float time code) spans."""
        return frame + self.open, frame + self.close

    def describe(self):
        """'shutter [-0.25, 0.25] frames (camera /World/Camera)', for the render's summary line."""
        return f"shutter [{self.open:g}, {self.close:g}] frames ({self.source})"


SHARP = Shutter()


def interval_problem(open_, close):
    """Why (open, close) frames cannot be a shutter, or None when they can."""
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in (open_, close)):
        return f"({open_!r}, {close!r}) is not a pair of numbers"
    if not (math.isfinite(open_) and math.isfinite(close)):
        return f"[{open_:g}, {close:g}] is not finite"
    if close < open_:
        return f"[{open_:g}, {close:g}] closes before it opens"
    if max(abs(open_), abs(close)) > MAX_SHUTTER_FRAMES:
        return f"[{open_:g}, {close:g}] reaches beyond {MAX_SHUTTER_FRAMES:g} frames from the frame"
    return None


@dataclasses.dataclass(frozen=True)
class ShutterOverride:
    """What may override the camera's shutter (plain data: a farm job carries it). interval: (open, close) frames
    from the command line, None for none; disable_motion_blur / instantaneous: the render settings' switches;
    source: what set them, for messages."""
    interval: Optional[tuple[float, float]] = None
    disable_motion_blur: bool = False
    instantaneous: bool = False
    source: str = ""

    def check(self):
        """Raises EyeRenderError (one line) for a command-line interval that cannot be a shutter."""
        if self.interval is not None:
            problem = interval_problem(*self.interval)
            if problem:
                raise EyeRenderError(f"--shutter {problem}")
        return self


def parse_shutter_arguments(values, disable_motion_blur=False):
    """eyerecord's --shutter values (None, [0], or [OPEN, CLOSE] in frames) and --disableMotionBlur as the
    (open, close) interval they ask for, None when they ask for none; bad values are an EyeRenderError."""
    if disable_motion_blur and values is not None:
        raise EyeRenderError("--shutter and --disableMotionBlur contradict each other")
    if disable_motion_blur:
        return 0.0, 0.0
    if values is None:
        return None
    if len(values) == 1 and values[0] == 0:
        return 0.0, 0.0
    if len(values) != 2:
        raise EyeRenderError("--shutter takes OPEN CLOSE (frames relative to the frame), or 0 for a sharp render")
    ShutterOverride(interval=(float(values[0]), float(values[1]))).check()
    return float(values[0]), float(values[1])


def _authored_flag(prim, name):
    """A UsdRender bool attribute's value where `prim` authors one, else None."""
    attr = prim.GetAttribute(name) if prim else None
    return bool(attr.Get()) if attr and attr.HasAuthoredValue() else None


def settings_override(stage, settings_path, interval=None):
    """The ShutterOverride of a render reading the UsdRender.Settings prim at `settings_path` (None: none) with the
    command line's `interval` (None: none): its first RenderProduct's disableMotionBlur / instantaneousShutter where
    authored, else the settings prim's."""
    if settings_path is None or not stage.GetPrimAtPath(settings_path):
        return ShutterOverride(interval=interval, source="--shutter" if interval is not None else "")
    settings = stage.GetPrimAtPath(settings_path)
    prims = [settings]
    products = settings.GetRelationship("products")
    targets = products.GetForwardedTargets() if products else []
    if targets and stage.GetPrimAtPath(targets[0]):
        prims.insert(0, stage.GetPrimAtPath(targets[0]))
    found = {}
    for name in ("disableMotionBlur", "instantaneousShutter"):
        for prim in prims:  # the product's authored value first
            value = _authored_flag(prim, name)
            if value is not None:
                found[name] = (value, prim.GetPath())
                break
    disable, where = found.get("disableMotionBlur", (False, None))
    instantaneous, where_i = found.get("instantaneousShutter", (False, None))
    source = "--shutter" if interval is not None else \
        f"{where} disableMotionBlur" if disable else f"{where_i} instantaneousShutter" if instantaneous else ""
    return ShutterOverride(interval=interval, disable_motion_blur=disable, instantaneous=instantaneous, source=source)


def camera_shutter(camera_prim, time, warnings):
    """The shutter a UsdGeom.Camera prim authors at `time` (a Usd.TimeCode); a bad one is one warning appended to
    `warnings` (a list) and SHARP."""
    from pxr import UsdGeom

    camera = UsdGeom.Camera(camera_prim)
    open_, close = camera.GetShutterOpenAttr().Get(time), camera.GetShutterCloseAttr().Get(time)
    open_, close = (0.0 if v is None else v for v in (open_, close))
    problem = interval_problem(open_, close)
    if problem:
        warnings.append(f"{camera_prim.GetPath()}: shutter {problem}: rendered sharp (no motion blur)")
        return SHARP
    return Shutter(float(open_), float(close), f"camera {camera_prim.GetPath()}")


def resolve_shutter(camera_prim, time, override=None, warnings=None):
    """The Shutter of a frame at `time` (Usd.TimeCode) seen through `camera_prim` (None: a camera without a prim,
    whose shutter is 0) under a ShutterOverride (None: none), by the precedence of the module doc. A render at the
    default time has no time samples to blur: SHARP."""
    warnings = [] if warnings is None else warnings
    override = override or ShutterOverride()
    if time.IsDefault():
        return SHARP
    if override.interval is not None:
        return Shutter(*override.interval, source="--shutter")
    if override.disable_motion_blur:
        return Shutter(0.0, 0.0, override.source)
    shutter = camera_shutter(camera_prim, time, warnings) if camera_prim else SHARP
    if override.instantaneous:
        return Shutter(shutter.open, shutter.open, override.source)
    return shutter


__all__ = ["MAX_SHUTTER_FRAMES", "Shutter", "SHARP", "ShutterOverride", "interval_problem",
           "parse_shutter_arguments", "settings_override", "camera_shutter", "resolve_shutter"]
