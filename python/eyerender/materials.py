"""UsdShade materials to the delegate's MaterialParams: the UsdPreviewSurface subset it renders.

Inputs are followed through connections (material interface inputs, node graphs) to the attribute that
produces their value. diffuseColor may come from a UsdUVTexture (its file, looked up by the st primvar the
texture's UsdPrimvarReader_float2 names); other texture connections fall back to the input's own value, or the
UsdPreviewSurface default, and are listed in `ignored` so the front end can say so once.
"""
import math

from pxr import Sdf, UsdShade

from ._hdeye import MaterialParams
from .errors import EyeRenderError

# UsdPreviewSurface's defaults (its specification), for inputs with no authored value.
DEFAULTS = {
    "diffuseColor": (0.18, 0.18, 0.18),
    "emissiveColor": (0.0, 0.0, 0.0),
    "roughness": 0.5,
    "metallic": 0.0,
    "opacity": 1.0,
    "ior": 1.5,
}
RANGES = {"roughness": (0, 1), "metallic": (0, 1), "opacity": (0, 1), "ior": (1, math.inf)}


def _shader_id(shader):
    return shader.GetIdAttr().Get() if shader else None


def _producer(shader_input):
    """The attribute that produces an input's value: a shader output, or an attribute holding a value."""
    attrs = shader_input.GetValueProducingAttributes()
    return attrs[0] if attrs else None


def _texture_of(attr):
    """(file path, st primvar name) if attr is a UsdUVTexture output, else None."""
    if UsdShade.Utils.GetType(attr.GetName()) != UsdShade.AttributeType.Output:
        return None
    shader = UsdShade.Shader(attr.GetPrim())
    if _shader_id(shader) != "UsdUVTexture":
        return None
    file_input = shader.GetInput("file")
    asset = file_input.Get() if file_input else None
    if not isinstance(asset, Sdf.AssetPath) or not asset.path:
        return None
    if not asset.resolvedPath:
        raise EyeRenderError(f"{shader.GetPath()}: inputs:file '{asset.path}' cannot be resolved")
    st_name = "st"
    st_input = shader.GetInput("st")
    reader_attr = _producer(st_input) if st_input else None
    if reader_attr is not None and UsdShade.Utils.GetType(reader_attr.GetName()) == UsdShade.AttributeType.Output:
        reader = UsdShade.Shader(reader_attr.GetPrim())
        varname = reader.GetInput("varname")
        if varname and varname.Get():
            st_name = str(varname.Get())
    return asset.resolvedPath, st_name


def read_material(material, time):
    """(MaterialParams, st primvar name, ignored connections) for a UsdShade.Material.

    Raises EyeRenderError (naming the shader and input) for out-of-range values; a material whose surface is not
    a UsdPreviewSurface renders with the defaults and is reported through `ignored`.
    """
    params, st_name, ignored = MaterialParams(), "st", []
    shader = material.ComputeSurfaceSource()[0]
    if _shader_id(shader) != "UsdPreviewSurface":
        ignored.append(f"{material.GetPath()}: surface is not a UsdPreviewSurface")
        return params, st_name, ignored
    for name, default in DEFAULTS.items():
        value = default
        shader_input = shader.GetInput(name)
        attr = _producer(shader_input) if shader_input else None
        if attr is not None:
            texture = _texture_of(attr)
            if texture and name == "diffuseColor":
                params.diffuse_texture, st_name = texture
            elif UsdShade.Utils.GetType(attr.GetName()) == UsdShade.AttributeType.Output:
                ignored.append(f"{shader.GetPath()}: inputs:{name} comes from a node this renderer does not run")
            elif attr.Get(time) is not None:
                value = attr.Get(time)
        if isinstance(default, tuple):
            value = tuple(float(c) for c in value)
            bad = not all(math.isfinite(c) and c >= 0 for c in value)
        else:
            value = float(value)
            lo, hi = RANGES[name]
            bad = not (math.isfinite(value) and lo <= value <= hi) if hi != math.inf else \
                not (value >= lo and math.isfinite(value))
        if bad:
            raise EyeRenderError(f"{shader.GetPath()}: inputs:{name} = {value} is out of range")
        setattr(params, _snake(name), value)
    return params, st_name, ignored


def _snake(name):
    return "".join("_" + c.lower() if c.isupper() else c for c in name)
