"""Reading the EyeAPI schema (schemas/schema.usda) off a prim into the delegate's EyeParams.

Every value is checked here, by attribute name and prim path, so a user learns which attribute on which prim
is wrong; nothing is clamped. The fallbacks repeat the schema's, so a stage whose EyeAPI plugin was not loaded
(the attributes then carry no fallback) still renders the paper's eye.
"""
import math

import numpy as np
from pxr import Gf, Usd

from ._hdeye import CorneaModel, EyeParams
from .errors import EyeRenderError
from .textures import TextureWarning, resolve_texture
from .validation import as_float, as_vector

EYE_API = "EyeAPI"
IRIS_DIAMETER_MM = 15.08  # the ellipsoid-cone cornea's rim chord; ratios and the iris texture refer to it

FALLBACKS = {
    "eye:corneaModel": "ellipsoidCone",
    "eye:corneaIor": 1.376,
    "eye:irisDepth": 3.735,  # mm below the corneal apex
    "eye:limbusInnerRatio": 0.772,  # over the 15.08 mm iris diameter
    "eye:limbusOuterRatio": 0.855,
    "eye:pupilDiameter": 4.0,  # mm
    "eye:irisColor": (0.35, 0.2, 0.1),  # linear albedo
    "eye:scleraColor": (0.8, 0.78, 0.75),
    "eye:modelTransform": Gf.Matrix4d(1.0),  # canonical frame (mm) to the prim's local space
    "eye:limbalArc": True,
    "eye:scleraMeanFreePath": (1.0, 0.8, 0.6),  # mm per RGB channel
}
# mm. Beyond a metre the sclera is transparent for any purpose, and the walk's steps would leave the scene.
MAX_MEAN_FREE_PATH_MM = 1000.0
CORNEA_MODELS = {"ellipsoidCone": CorneaModel.ellipsoidCone, "paraboloid": CorneaModel.paraboloid}


def is_eye(prim):
    """Whether the EyeAPI is applied. Read from the composed apiSchemas metadata, not GetAppliedSchemas(): that
    lists only registered schemas, and an eye must stay an eye even where the EyeAPI plugin is not loaded (its
    attributes then fall back to FALLBACKS above)."""
    schemas = prim.GetMetadata("apiSchemas")
    return bool(schemas) and EYE_API in schemas.ApplyOperations([])


def _get(prim, name, time):
    attr = prim.GetAttribute(name)
    value = attr.Get(time) if attr else None
    return FALLBACKS[name] if value is None else value


def eye_attributes_vary(prim):
    """Whether any eye:* attribute may change over time (pupils dilate)."""
    return any(prim.GetAttribute(n).ValueMightBeTimeVarying() for n in FALLBACKS if prim.GetAttribute(n))


def _format(value):
    """A value as the one-line messages print it: %g numbers, (a, b, c) vectors."""
    if isinstance(value, tuple):
        return "(" + ", ".join(_format(v) for v in value) + ")"
    return f"{value:g}"


def _in_range(path, name, value, ok, valid, unit=""):
    """`value` if ok(value) holds for it (for every channel of a vector), else raises the one line naming the
    attribute, its value and its valid range. `ok` must be False for NaN (comparisons with NaN are)."""
    values = value if isinstance(value, tuple) else (value,)
    if not all(ok(v) for v in values):
        raise EyeRenderError(f"{path}: {name} = {_format(value)}{unit} is outside its valid range {valid}")
    return value


def _number(prim, name, time, ok, valid, unit=""):
    """A float attribute checked against its range (NaN and infinities fail it, named with the range)."""
    value = as_float(prim.GetPath(), name, _get(prim, name, time), finite=False)
    return _in_range(prim.GetPath(), name, value, lambda v: math.isfinite(v) and ok(v), valid, unit)


def _vector(prim, name, time, ok, valid, unit=""):
    """A 3-vector attribute checked channel by channel against its range."""
    value = as_vector(prim.GetPath(), name, _get(prim, name, time), finite=False)
    return _in_range(prim.GetPath(), name, value, lambda v: math.isfinite(v) and ok(v), valid, unit)


def _is_albedo(value):
    return 0 <= value <= 1


def _matrix(prim, value):
    if not isinstance(value, (Gf.Matrix4d, Gf.Matrix4f)):
        raise EyeRenderError(f"{prim.GetPath()}: eye:modelTransform is a {type(value).__name__}, not a matrix4d")
    flat = [float(value[r][c]) for r in range(4) for c in range(4)]
    if not all(math.isfinite(v) for v in flat):
        raise EyeRenderError(f"{prim.GetPath()}: eye:modelTransform has non-finite entries")
    # Singular relative to its own scale (the volume its axes span against the product of their lengths), so that
    # an eye in a kilometre scene (a 1e-6 scale, determinant 1e-18) is as valid as one in millimetres.
    rows = [math.sqrt(sum(flat[4 * r + c] ** 2 for c in range(3))) for r in range(3)]
    if not abs(Gf.Matrix4d(value).GetDeterminant3()) > 1e-12 * rows[0] * rows[1] * rows[2]:
        raise EyeRenderError(f"{prim.GetPath()}: eye:modelTransform is singular")
    return flat


def read_eye_params(prim, time=Usd.TimeCode.Default(), cornea_model_override=None, warnings=None):
    """EyeParams from prim's eye:* attributes at `time`; raises EyeRenderError naming the attribute and prim. An
    iris texture that cannot be read is a TextureWarning appended to `warnings` (a list, if given)."""
    path = prim.GetPath()
    model = cornea_model_override or str(_get(prim, "eye:corneaModel", time))
    if model not in CORNEA_MODELS:
        raise EyeRenderError(f"{path}: eye:corneaModel = '{model}' is not one of {', '.join(CORNEA_MODELS)}")
    ior = _number(prim, "eye:corneaIor", time, lambda v: v >= 1, "[1, inf)")
    depth = _number(prim, "eye:irisDepth", time, lambda v: v > 0, "(0, inf) mm", " mm")
    pupil = _number(prim, "eye:pupilDiameter", time, lambda v: 0 <= v < IRIS_DIAMETER_MM,
                    f"[0, {IRIS_DIAMETER_MM:g}) mm", " mm")
    outer = _number(prim, "eye:limbusOuterRatio", time, lambda v: 0 < v <= 1, "(0, 1]")
    inner = _number(prim, "eye:limbusInnerRatio", time, lambda v: 0 < v <= 1, "(0, 1]")
    _in_range(path, "eye:limbusInnerRatio", inner, lambda v: v <= outer, f"(0, eye:limbusOuterRatio = {outer:g}]")

    eye = EyeParams()
    eye.cornea_model = CORNEA_MODELS[model]
    eye.cornea_ior, eye.iris_depth, eye.pupil_diameter = ior, depth, pupil
    eye.limbus_inner_ratio, eye.limbus_outer_ratio = inner, outer
    eye.iris_color = _vector(prim, "eye:irisColor", time, _is_albedo, "[0, 1] per channel")
    eye.sclera_color = _vector(prim, "eye:scleraColor", time, _is_albedo, "[0, 1] per channel")
    limbal_arc = _get(prim, "eye:limbalArc", time)
    if not isinstance(limbal_arc, bool):
        raise EyeRenderError(f"{path}: eye:limbalArc is a {type(limbal_arc).__name__}, not a bool")
    eye.limbal_arc = limbal_arc
    eye.sclera_mean_free_path = _vector(prim, "eye:scleraMeanFreePath", time, lambda v: 0 < v <= MAX_MEAN_FREE_PATH_MM,
                                        f"(0, {MAX_MEAN_FREE_PATH_MM:g}] mm per channel", " mm")
    model_transform = _matrix(prim, _get(prim, "eye:modelTransform", time))
    eye.model_transform = np.array(model_transform, dtype=np.float64).reshape(4, 4)
    eye.iris_texture, problem = resolve_texture(prim.GetAttribute("eye:irisTexture"), time, f"{path}: eye:irisTexture")
    if problem and warnings is not None:
        warnings.append(TextureWarning(f"{problem}; the iris renders magenta"))
    problem = eye.validate()  # the C++ model's own check, the last word on what it can render
    if problem:
        raise EyeRenderError(f"{path}: {problem}")
    return eye
