"""UsdShade materials to the delegate's MaterialParams: UsdPreviewSurface and its UsdUVTexture networks.

Inputs are followed through connections (material interface inputs, node graphs) to the attribute that
produces their value. diffuseColor, emissiveColor, roughness, metallic, opacity, ior, specularColor (with
useSpecularWorkflow), clearcoat, clearcoatRoughness and normal (a tangent-space normal map) may come from a
UsdUVTexture output (rgb, r, g, b or a), with its file, wrapS/wrapT, scale, bias,
fallback and sourceColorSpace; its st from a UsdPrimvarReader_float2 (the primvar its varname names), optionally
through a UsdTransform2d (rotation, scale, translation); without a file, its fallback (with one line in `ignored`).
opacityThreshold makes opacity a cut-out mask.

diffuseColor may also come from a UsdPrimvarReader_float3 of displayColor (the prim's colour, or its instancer's per
instance, with the reader's fallback where the prim has none), as Storm renders it.

What is not rendered is listed once in `ignored`: inputs fed by other nodes, displacement. occlusion is not used,
as the specification expects of path tracers (the renderer computes occlusion itself). A material whose universal
surface is not a UsdPreviewSurface (MaterialX, or another shader network) renders its UsdPreviewSurface output for
another render context if it has one, else the defaults, with one warning.
"""
import math

from pxr import UsdShade

from ._hdeye import MaterialParams, TextureColorSpace, TextureInput, TextureWrap
from .errors import EyeRenderError
from .textures import TextureWarning, resolve_texture

# The material purposes bindings are resolved for, in order ("" the all-purpose binding) where the stage's render
# settings name none: "preview" first, as Storm asks for a UsdPreviewSurface renderer.
DEFAULT_BINDING_PURPOSES = ("preview", "")


def bound_material(prim, purposes=DEFAULT_BINDING_PURPOSES):
    """The UsdShade.Material bound to prim for the first of `purposes` (UsdRender's materialBindingPurposes: an
    ordered list, "" the all-purpose binding) that binds one, by UsdShade's resolution; an invalid Material where
    none does."""
    api = UsdShade.MaterialBindingAPI(prim)
    for purpose in purposes:
        material, relationship = api.ComputeBoundMaterial(purpose or UsdShade.Tokens.allPurpose)
        if material and _binding_purpose(relationship) == purpose:
            return material
    return UsdShade.Material()


def _binding_purpose(relationship):
    """The material purpose of a binding relationship ("" for the all-purpose ones): material:binding[:purpose] or
    material:binding:collection[:purpose]:name."""
    parts = relationship.GetName().split(":") if relationship else []
    if parts[2:3] == ["collection"]:
        return parts[3] if len(parts) == 5 else ""
    return parts[2] if len(parts) == 3 else ""


# UsdPreviewSurface's defaults (its specification), for inputs with no authored value.
DEFAULTS = {
    "diffuseColor": (0.18, 0.18, 0.18),
    "emissiveColor": (0.0, 0.0, 0.0),
    "roughness": 0.5,
    "metallic": 0.0,
    "opacity": 1.0,
    "opacityThreshold": 0.0,
    "ior": 1.5,
    "specularColor": (0.0, 0.0, 0.0),
    "clearcoat": 0.0,
    "clearcoatRoughness": 0.01,
}
RANGES = {"roughness": (0, 1), "metallic": (0, 1), "opacity": (0, 1), "opacityThreshold": (0, 1), "ior": (1, math.inf),
          "clearcoat": (0, 1), "clearcoatRoughness": (0, 1)}
TEXTURED = ("diffuseColor", "emissiveColor", "roughness", "metallic", "opacity", "ior", "normal", "specularColor",
            "clearcoat", "clearcoatRoughness")
COLOR_INPUTS = ("diffuseColor", "emissiveColor", "normal", "specularColor")
# Inputs the renderer does not model, with the value at which ignoring them changes nothing.
NOT_RENDERED = {"displacement": 0.0}
CHANNELS = {"rgb": -1, "rgba": -1, "r": 0, "g": 1, "b": 2, "a": 3}
WRAPS = {"useMetadata": TextureWrap.useMetadata, "black": TextureWrap.black, "clamp": TextureWrap.clamp,
         "repeat": TextureWrap.repeat, "mirror": TextureWrap.mirror}
COLOR_SPACES = {"auto": TextureColorSpace.auto, "raw": TextureColorSpace.raw, "sRGB": TextureColorSpace.sRGB}


def _shader_id(shader):
    return shader.GetIdAttr().Get() if shader else None


def _producer(shader_input):
    """The attribute that produces an input's value: a shader output, or an attribute holding a value."""
    attrs = shader_input.GetValueProducingAttributes() if shader_input else []
    return attrs[0] if attrs else None


def _is_output(attr):
    return attr is not None and UsdShade.Utils.GetType(attr.GetName()) == UsdShade.AttributeType.Output


def _value(shader, name, time, default=None):
    """An input's value, followed through connections to the attribute that holds it."""
    attr = _producer(shader.GetInput(name))
    value = attr.Get(time) if attr is not None and not _is_output(attr) else None
    return default if value is None else value


def _st_source(shader, time, texture_input):
    """The st primvar name of a UsdUVTexture's st input, with any UsdTransform2d on the way (into texture_input)."""
    attr = _producer(shader.GetInput("st"))
    if not _is_output(attr):
        return "st"
    source = UsdShade.Shader(attr.GetPrim())
    if _shader_id(source) == "UsdTransform2d":
        texture_input.scale = tuple(float(c) for c in _value(source, "scale", time, (1.0, 1.0)))
        texture_input.rotation = float(_value(source, "rotation", time, 0.0))
        texture_input.translation = tuple(float(c) for c in _value(source, "translation", time, (0.0, 0.0)))
        transform = (*texture_input.scale, texture_input.rotation, *texture_input.translation)
        if not all(math.isfinite(c) for c in transform):
            raise EyeRenderError(f"{source.GetPath()}: rotation, scale and translation must be finite")
        attr = _producer(source.GetInput("in"))
        if not _is_output(attr):
            return "st"
        source = UsdShade.Shader(attr.GetPrim())
    if _shader_id(source) and _shader_id(source).startswith("UsdPrimvarReader"):
        return str(_value(source, "varname", time, "st")) or "st"
    return "st"


def read_uv_texture(attr, time):
    """(TextureInput, st primvar name, TextureWarning or None) if attr is a UsdUVTexture output, else None."""
    if not _is_output(attr):
        return None
    shader = UsdShade.Shader(attr.GetPrim())
    if _shader_id(shader) != "UsdUVTexture":
        return None
    texture_input = TextureInput()
    texture_input.channel = CHANNELS.get(UsdShade.Utils.GetBaseNameAndType(attr.GetName())[0], 0)
    params = texture_input.texture
    file_attr = _producer(shader.GetInput("file"))
    params.file, problem = resolve_texture(file_attr, time, f"{shader.GetPath()}: inputs:file")
    if not params.file and problem is None:
        return None  # no file authored: the input keeps its constant value
    for name in ("wrapS", "wrapT"):
        token = str(_value(shader, name, time, "useMetadata"))
        if token not in WRAPS:
            raise EyeRenderError(f"{shader.GetPath()}: inputs:{name} = '{token}' is not one of {', '.join(WRAPS)}")
        setattr(params, "wrap_s" if name == "wrapS" else "wrap_t", WRAPS[token])
    space = str(_value(shader, "sourceColorSpace", time, "auto"))
    if space not in COLOR_SPACES:
        raise EyeRenderError(f"{shader.GetPath()}: inputs:sourceColorSpace = '{space}' is not one of "
                             f"{', '.join(COLOR_SPACES)}")
    params.color_space = COLOR_SPACES[space]
    for name in ("scale", "bias", "fallback"):
        value = _value(shader, name, time)
        if value is None:
            continue  # scale 1, bias 0; fallback: the delegate's visible magenta
        value = tuple(float(c) for c in value)
        if len(value) != 4 or not all(math.isfinite(c) for c in value):
            raise EyeRenderError(f"{shader.GetPath()}: inputs:{name} = {value} must be 4 finite numbers")
        setattr(params, name, value)
    st_name = _st_source(shader, time, texture_input)
    if problem:
        problem = TextureWarning(f"{problem}; its fallback {tuple(round(c, 3) for c in params.fallback)} is rendered")
    return texture_input, st_name, problem


def _color_reader(attr):
    """The UsdPrimvarReader_float3 whose output attr is, else None."""
    reader = UsdShade.Shader(attr.GetPrim()) if _is_output(attr) else None
    return reader if _shader_id(reader) == "UsdPrimvarReader_float3" else None


def _read_display_color(shader, reader, time, params, ignored):
    """diffuseColor from a UsdPrimvarReader_float3: displayColor's is rendered (the reader's fallback where the prim has
    none); another primvar's is not (one line in `ignored`)."""
    varname = str(_value(reader, "varname", time, ""))
    if varname != "displayColor":
        ignored.append(f"{shader.GetPath()}: inputs:diffuseColor reads primvar '{varname}' ({reader.GetPath()}); only "
                       f"displayColor is read this way, so its constant is rendered")
        return
    fallback = tuple(float(c) for c in _value(reader, "fallback", time, (0.0, 0.0, 0.0)))
    if len(fallback) != 3 or not all(math.isfinite(c) and c >= 0 for c in fallback):
        raise EyeRenderError(f"{reader.GetPath()}: inputs:fallback = {fallback} must be 3 finite numbers >= 0")
    params.diffuse_from_display_color = True
    params.diffuse_color = fallback


def _read_fileless_texture(shader, name, attr, time, params, ignored):
    """An input fed by a UsdUVTexture without a file takes the texture's fallback (the specification's "value to be
    used when no texture is connected", (0, 0, 0, 1) unless authored), through the output's channels."""
    texture = UsdShade.Shader(attr.GetPrim())
    fallback = tuple(float(c) for c in _value(texture, "fallback", time, (0.0, 0.0, 0.0, 1.0)))
    if len(fallback) != 4 or not all(math.isfinite(c) for c in fallback):
        raise EyeRenderError(f"{texture.GetPath()}: inputs:fallback = {fallback} must be 4 finite numbers")
    channel = CHANNELS.get(UsdShade.Utils.GetBaseNameAndType(attr.GetName())[0], 0)
    picked = fallback[:3] if channel == -1 else (fallback[channel],) * 3
    value = picked if isinstance(DEFAULTS[name], tuple) else picked[0]
    setattr(params, _snake(name), _checked(shader, name, value))
    ignored.append(f"{shader.GetPath()}: inputs:{name}: its UsdUVTexture {texture.GetPath()} has no file, so its "
                   f"fallback {tuple(round(c, 3) for c in fallback)} is rendered")


def _surface_shader(material, ignored):
    """The UsdPreviewSurface the material renders with: its universal surface, else the first render context's
    surface that is one (warned about), else None (warned about)."""
    universal = material.ComputeSurfaceSource()[0]
    if _shader_id(universal) == "UsdPreviewSurface":
        return universal
    others = []
    for output in material.GetSurfaceOutputs():
        source = output.GetConnectedSources()[0] if output.HasConnectedSource() else []
        shader = UsdShade.Shader(source[0].source.GetPrim()) if source else None
        others.append((output.GetBaseName(), _shader_id(shader)))
        if _shader_id(shader) == "UsdPreviewSurface":
            ignored.append(f"{material.GetPath()}: renders its UsdPreviewSurface ({output.GetAttr().GetName()}); "
                           f"the other surface networks are not run")
            return shader
    what = ", ".join(f"{name} -> {sid or 'nothing'}" for name, sid in others) or "no surface output"
    ignored.append(f"{material.GetPath()}: no UsdPreviewSurface ({what}); renders with the UsdPreviewSurface defaults")
    return None


def read_material(material, time):
    """(MaterialParams, st primvar name, ignored) for a UsdShade.Material; `ignored` holds one line per thing not
    rendered (TextureWarning for textures that cannot be read).

    Raises EyeRenderError (naming the shader and input) for out-of-range values.
    """
    params, st_name, ignored = MaterialParams(), None, []
    shader = _surface_shader(material, ignored)
    if shader is None:
        return params, "st", ignored
    for name in TEXTURED + ("opacityThreshold",):
        attr = _producer(shader.GetInput(name))
        if attr is None:
            continue
        if _is_output(attr):
            reader = _color_reader(attr) if name == "diffuseColor" else None
            if reader is not None:
                _read_display_color(shader, reader, time, params, ignored)
                continue
            texture = read_uv_texture(attr, time) if name in TEXTURED else None
            if texture is None:
                if name in DEFAULTS and _shader_id(UsdShade.Shader(attr.GetPrim())) == "UsdUVTexture":
                    _read_fileless_texture(shader, name, attr, time, params, ignored)
                else:
                    ignored.append(f"{shader.GetPath()}: inputs:{name} comes from a node this renderer does not run")
                continue
            texture_input, texture_st, problem = texture
            if name not in COLOR_INPUTS and texture_input.channel == -1:
                texture_input.channel = 0  # a float input fed by rgb takes r
            params.set_texture(name, texture_input)
            if problem:
                ignored.append(problem)
            if st_name is not None and texture_st != st_name:
                ignored.append(f"{shader.GetPath()}: inputs:{name} reads primvar '{texture_st}'; the material's "
                               f"textures all use '{st_name}'")
            st_name = st_name or texture_st
        elif name in DEFAULTS and attr.Get(time) is not None:
            setattr(params, _snake(name), _checked(shader, name, attr.Get(time)))
    workflow = _value(shader, "useSpecularWorkflow", time, 0)
    if workflow not in (0, 1):
        raise EyeRenderError(f"{shader.GetPath()}: inputs:useSpecularWorkflow = {workflow} must be 0 or 1")
    params.use_specular_workflow = workflow == 1
    for name, neutral in NOT_RENDERED.items():
        if _value(shader, name, time, neutral) != neutral or _is_output(_producer(shader.GetInput(name))):
            ignored.append(f"{shader.GetPath()}: inputs:{name} is not rendered")
    return params, st_name or "st", ignored


def _checked(shader, name, value):
    default = DEFAULTS[name]
    if isinstance(default, tuple):
        value = tuple(float(c) for c in value)
        bad = not all(math.isfinite(c) and c >= 0 for c in value)
    else:
        value = float(value)
        lo, hi = RANGES[name]
        bad = not (math.isfinite(value) and lo <= value <= hi)
    if bad:
        raise EyeRenderError(f"{shader.GetPath()}: inputs:{name} = {value} is out of range")
    return value


def _snake(name):
    return "".join("_" + c.lower() if c.isupper() else c for c in name)
