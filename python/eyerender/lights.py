"""UsdLux lights to the delegate's light prims (sphere, distant, rect, disk, dome).

Radiance = color * intensity * 2^exposure, as UsdLux defines it. With inputs:normalize the intensity is divided
by the light's world-space area (sphere, disk, rect), so resizing a light keeps its power. Dome and rect light
textures are read through eyerender.textures (any OpenImageIO format, .usdz); colorTemperature is not rendered yet
and the front end reports it.
"""
import math

from pxr import UsdLux

from ._hdeye import LightParams
from .errors import EyeRenderError
from .textures import TextureWarning, resolve_texture
from .validation import as_float, as_vector

# Prim type to the delegate's sprim type.
LIGHT_TYPES = {
    "SphereLight": "sphereLight",
    "DistantLight": "distantLight",
    "RectLight": "rectLight",
    "DiskLight": "diskLight",
    "DomeLight": "domeLight",
}


def light_type(prim):
    return LIGHT_TYPES.get(prim.GetTypeName())


def _scale(world):
    """The geometric-mean scale of a transform's linear part (lights are sized by it)."""
    return abs(world.GetDeterminant3()) ** (1.0 / 3.0)


def read_light(prim, world, time, warnings=None):
    """LightParams for a UsdLux light prim with local-to-world `world` (Gf.Matrix4d) at `time`. A dome texture that
    cannot be read is a TextureWarning appended to `warnings` (a list, if given)."""
    api = UsdLux.LightAPI(prim)
    path = prim.GetPath()
    p = LightParams()
    p.color = as_vector(path, "inputs:color", api.GetColorAttr().Get(time))
    p.intensity = as_float(path, "inputs:intensity", api.GetIntensityAttr().Get(time))
    p.exposure = as_float(path, "inputs:exposure", api.GetExposureAttr().Get(time))
    if not all(math.isfinite(v) for v in (*p.color, p.intensity, p.exposure)) or min(p.color) < 0 or p.intensity < 0:
        raise EyeRenderError(f"{path}: light color, intensity and exposure must be finite and non-negative")
    kind = prim.GetTypeName()
    scale = _scale(world)
    area = None
    if kind == "SphereLight":
        light = UsdLux.SphereLight(prim)
        # treatAsPoint is a hint renderers with area lights may disregard (UsdLux): the sphere keeps its radius,
        # and with it its power (UsdLux intensity is radiance: a zero-radius sphere would emit nothing).
        p.radius = as_float(path, "inputs:radius", light.GetRadiusAttr().Get(time))
        area = 4 * math.pi * (p.radius * scale) ** 2
    elif kind == "DiskLight":
        p.radius = as_float(path, "inputs:radius", UsdLux.DiskLight(prim).GetRadiusAttr().Get(time))
        area = math.pi * (p.radius * scale) ** 2
    elif kind == "RectLight":
        light = UsdLux.RectLight(prim)
        p.width = as_float(path, "inputs:width", light.GetWidthAttr().Get(time))
        p.height = as_float(path, "inputs:height", light.GetHeightAttr().Get(time))
        p.texture_file, problem = resolve_texture(light.GetTextureFileAttr(), time, f"{path}: inputs:texture:file")
        if problem and warnings is not None:
            warnings.append(TextureWarning(f"{problem}; the light emits magenta"))
        area = p.width * p.height * scale * scale
    elif kind == "DistantLight":
        p.angle = as_float(path, "inputs:angle", UsdLux.DistantLight(prim).GetAngleAttr().Get(time))
        if not 0 <= p.angle < 180:
            raise EyeRenderError(f"{path}: inputs:angle = {p.angle:g} degrees must be in [0, 180)")
    elif kind == "DomeLight":
        dome = UsdLux.DomeLight(prim)
        p.texture_file, problem = resolve_texture(dome.GetTextureFileAttr(), time, f"{path}: inputs:texture:file")
        if p.texture_file:
            fmt = dome.GetTextureFormatAttr().Get(time)
            if fmt not in ("automatic", "latlong"):
                raise EyeRenderError(f"{path}: inputs:texture:format '{fmt}' is not supported (latlong only)")
        if problem and warnings is not None:
            warnings.append(TextureWarning(f"{problem}; the dome renders magenta"))
    for name in ("radius", "width", "height"):
        if not (getattr(p, name) >= 0 and math.isfinite(getattr(p, name))):
            raise EyeRenderError(f"{path}: inputs:{name} = {getattr(p, name):g} must be finite and non-negative")
    if api.GetNormalizeAttr().Get(time) and area:
        p.intensity /= area
        if not math.isfinite(p.intensity):  # the delegate's intensity is a float
            raise EyeRenderError(f"{path}: normalized intensity overflows: the light's area {area:g} is too small")
    return p


def unsupported_light_features(prim, time):
    """Authored light features the renderer ignores, for a one-time warning."""
    api = UsdLux.LightAPI(prim)
    notes = []
    if api.GetEnableColorTemperatureAttr().Get(time):
        notes.append(f"{prim.GetPath()}: colorTemperature is ignored")
    if prim.GetTypeName() in ("SphereLight", "DiskLight") and not prim.GetAttribute("inputs:radius").Get(time):
        notes.append(f"{prim.GetPath()}: radius 0 emits nothing (intensity is radiance)")
    intensity, exposure = api.GetIntensityAttr().Get(time), api.GetExposureAttr().Get(time)
    if intensity and exposure and math.isfinite(exposure) and math.log2(abs(intensity)) + exposure > 1000:
        notes.append(f"{prim.GetPath()}: intensity x 2^exposure overflows: the light is off")
    return notes

