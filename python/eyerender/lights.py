"""UsdLux lights to the delegate's light prims (sphere, distant, rect, disk, cylinder, dome).

The attributes go to the delegate as authored; the delegate applies UsdLux's formulas (RenderLight::FromParams:
radiance = color x blackbody(colorTemperature) x intensity x 2^exposure / sizeFactor with normalize, a distant
light's intensity the radiance of its disc, treatAsPoint, treatAsLine, ShapingAPI's cone and focus, the dome's
poleAxis).
Dome and rect light textures are read through eyerender.textures (any OpenImageIO format, .usdz).
IES profiles (ShapingAPI's shaping:ies:file) are read through Ar by eyerender.ies_profiles and handed over parsed.
Light and shadow linking: the collections' membership over the rendered prims, handed over as the rprim ids each
light does not light / is not shadowed by (link_excludes). What the renderer does not do (PortalLight) is
reported once per prim (docs/lights.md).
"""
import math

from pxr import Usd, UsdGeom, UsdLux

from ._hdeye import LightParams
from .errors import EyeRenderError
from .ies_profiles import read_ies_profile
from .textures import TextureWarning, resolve_texture
from .validation import as_float, as_vector

# Prim type to the delegate's sprim type.
LIGHT_TYPES = {
    "SphereLight": "sphereLight",
    "DistantLight": "distantLight",
    "RectLight": "rectLight",
    "DiskLight": "diskLight",
    "CylinderLight": "cylinderLight",
    "DomeLight": "domeLight",
    "DomeLight_1": "domeLight",
}

# UsdLux lights the renderer skips, with why (one warning each).
SKIPPED_LIGHTS = {
    "PortalLight": "PortalLight is not rendered (the dome is sampled without portals)",
}


def light_type(prim):
    return LIGHT_TYPES.get(prim.GetTypeName())


def skipped_light(prim):
    """One warning line for a UsdLux light prim the renderer skips, else None."""
    why = SKIPPED_LIGHTS.get(prim.GetTypeName())
    return f"{prim.GetPath()}: {why}; skipped" if why else None


def _finite(path, **values):
    for name, v in values.items():
        if not math.isfinite(v):
            raise EyeRenderError(f"{path}: {name} = {v:g} must be finite")


def _read_shaping(prim, time, p, warnings):
    """ShapingAPI's cone, focus and IES profile into p.shaping (a profile that cannot be read is a ProfileWarning
    appended to `warnings`, a list, if given)."""
    if not prim.HasAPI(UsdLux.ShapingAPI):
        return
    api = UsdLux.ShapingAPI(prim)
    s = p.shaping
    s.enabled = True
    s.cone_angle = float(api.GetShapingConeAngleAttr().Get(time))
    s.cone_softness = float(api.GetShapingConeSoftnessAttr().Get(time))
    s.focus = float(api.GetShapingFocusAttr().Get(time))
    s.focus_tint = tuple(float(c) for c in api.GetShapingFocusTintAttr().Get(time))
    s.ies_angle_scale = float(api.GetShapingIesAngleScaleAttr().Get(time))
    s.ies_normalize = bool(api.GetShapingIesNormalizeAttr().Get(time))
    _finite(prim.GetPath(), **{"inputs:shaping:cone:angle": s.cone_angle, "inputs:shaping:cone:softness":
                               s.cone_softness, "inputs:shaping:focus": s.focus,
                               "inputs:shaping:ies:angleScale": s.ies_angle_scale})
    if prim.GetTypeName() not in ("DistantLight", "DomeLight", "DomeLight_1"):
        profile, problem = read_ies_profile(api.GetShapingIesFileAttr(), time,
                                            f"{prim.GetPath()}: inputs:shaping:ies:file")
        if profile is not None:
            s.ies = profile
        if problem and warnings is not None:
            warnings.append(problem)
    p.shaping = s


def _dome_pole_z(prim):
    """Whether the dome's top pole is +z: DomeLight_1's poleAxis Z, or scene on a Z-up stage."""
    if prim.GetTypeName() != "DomeLight_1":
        return False
    axis = UsdLux.DomeLight_1(prim).GetPoleAxisAttr().Get()
    return axis == "Z" or (axis == "scene" and UsdGeom.GetStageUpAxis(prim.GetStage()) == UsdGeom.Tokens.z)


def read_light(prim, time, warnings=None):
    """LightParams for a UsdLux light prim at `time` (its size in the world comes from its transform, in the
    delegate). A dome or rect texture or an IES profile that cannot be read is a TextureWarning appended to
    `warnings` (a list, if given)."""
    api = UsdLux.LightAPI(prim)
    path = prim.GetPath()
    p = LightParams()
    p.color = as_vector(path, "inputs:color", api.GetColorAttr().Get(time))
    p.intensity = as_float(path, "inputs:intensity", api.GetIntensityAttr().Get(time))
    p.exposure = as_float(path, "inputs:exposure", api.GetExposureAttr().Get(time))
    if not all(math.isfinite(v) for v in (*p.color, p.intensity, p.exposure)) or min(p.color) < 0 or p.intensity < 0:
        raise EyeRenderError(f"{path}: light color, intensity and exposure must be finite and non-negative")
    p.normalize = bool(api.GetNormalizeAttr().Get(time))
    p.enable_color_temperature = bool(api.GetEnableColorTemperatureAttr().Get(time))
    p.color_temperature = float(api.GetColorTemperatureAttr().Get(time))
    if p.enable_color_temperature and not 1000 <= p.color_temperature <= 40000:
        raise EyeRenderError(f"{path}: inputs:colorTemperature = {p.color_temperature:g} K must be in "
                             "[1000, 40000] (UsdLux: 1000-10000)")
    kind = prim.GetTypeName()
    _read_shaping(prim, time, p, warnings)
    if kind == "SphereLight":
        light = UsdLux.SphereLight(prim)
        p.radius = as_float(path, "inputs:radius", light.GetRadiusAttr().Get(time))
        p.treat_as_point = bool(light.GetTreatAsPointAttr().Get(time))
    elif kind == "DiskLight":
        p.radius = as_float(path, "inputs:radius", UsdLux.DiskLight(prim).GetRadiusAttr().Get(time))
    elif kind == "CylinderLight":
        light = UsdLux.CylinderLight(prim)
        p.radius = as_float(path, "inputs:radius", light.GetRadiusAttr().Get(time))
        p.length = as_float(path, "inputs:length", light.GetLengthAttr().Get(time))
        p.treat_as_line = bool(light.GetTreatAsLineAttr().Get(time))
    elif kind == "RectLight":
        light = UsdLux.RectLight(prim)
        p.width = as_float(path, "inputs:width", light.GetWidthAttr().Get(time))
        p.height = as_float(path, "inputs:height", light.GetHeightAttr().Get(time))
        p.texture_file, problem = resolve_texture(light.GetTextureFileAttr(), time, f"{path}: inputs:texture:file")
        if problem and warnings is not None:
            warnings.append(TextureWarning(f"{problem}; the light emits magenta"))
    elif kind == "DistantLight":
        p.angle = as_float(path, "inputs:angle", UsdLux.DistantLight(prim).GetAngleAttr().Get(time))
        if not 0 <= p.angle < 180:
            raise EyeRenderError(f"{path}: inputs:angle = {p.angle:g} degrees must be in [0, 180)")
    elif kind in ("DomeLight", "DomeLight_1"):
        p.dome_pole_z = _dome_pole_z(prim)
        dome = UsdLux.DomeLight(prim) if kind == "DomeLight" else UsdLux.DomeLight_1(prim)
        p.texture_file, problem = resolve_texture(dome.GetTextureFileAttr(), time, f"{path}: inputs:texture:file")
        if p.texture_file:
            fmt = dome.GetTextureFormatAttr().Get(time)
            if fmt not in ("automatic", "latlong"):
                raise EyeRenderError(f"{path}: inputs:texture:format '{fmt}' is not supported (latlong only)")
        if problem and warnings is not None:
            warnings.append(TextureWarning(f"{problem}; the dome renders magenta"))
    for name in ("radius", "width", "height", "length"):
        if not (getattr(p, name) >= 0 and math.isfinite(getattr(p, name))):
            raise EyeRenderError(f"{path}: inputs:{name} = {getattr(p, name):g} must be finite and non-negative")
    return p


def unsupported_light_features(prim, time):
    """Authored light features the renderer ignores, for a one-time warning."""
    api = UsdLux.LightAPI(prim)
    notes = []
    path = prim.GetPath()
    kind = prim.GetTypeName()
    point = (kind == "SphereLight" and UsdLux.SphereLight(prim).GetTreatAsPointAttr().Get(time)) or \
        (kind == "CylinderLight" and UsdLux.CylinderLight(prim).GetTreatAsLineAttr().Get(time))
    if kind in ("SphereLight", "DiskLight", "CylinderLight") and not prim.GetAttribute("inputs:radius").Get(time) and \
            not (point and api.GetNormalizeAttr().Get(time)):
        notes.append(f"{path}: radius 0 emits nothing (intensity is radiance)")
    if prim.HasAPI(UsdLux.ShapingAPI) and kind in ("DistantLight", "DomeLight", "DomeLight_1"):
        notes.append(f"{path}: ShapingAPI is ignored on a {kind}")
    intensity, exposure = api.GetIntensityAttr().Get(time), api.GetExposureAttr().Get(time)
    if intensity and exposure and math.isfinite(exposure) and math.log2(abs(intensity)) + exposure > 1000:
        notes.append(f"{path}: intensity x 2^exposure overflows: the light is off")
    return notes


def link_excludes(prim, rprims):
    """(rprim ids the light does not illuminate, rprim ids that cast no shadow for it): the membership of its
    collection:lightLink and collection:shadowLink (Usd.CollectionAPI.ComputeMembershipQuery: includeRoot,
    includes, excludes, expansion rules) over `rprims`, {rprim id: the prim path it came from}."""
    out = []
    for name in ("lightLink", "shadowLink"):
        query = Usd.CollectionAPI(prim, name).ComputeMembershipQuery()
        out.append([rprim for rprim, path in rprims.items() if not query.IsPathIncluded(path)])
    return tuple(out)


def with_links(params, excludes):
    """`params` with the (light, shadow) link excludes of link_excludes set (None: unchanged)."""
    if excludes:
        params.light_link_excludes, params.shadow_link_excludes = list(excludes[0]), list(excludes[1])
    return params

