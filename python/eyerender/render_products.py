"""UsdRender as the specification of a render's outputs: the products of a UsdRender.Settings prim, each an image
file of the render vars it orders, with its own camera, resolution and data window (UsdRender.Product overrides
the settings' values), read into plain data that the local and the farm render paths write alike.

A render var names what to write by sourceName and sourceType; the subset the renderer honours (VAR_SOURCES):
raw AOVs (every AOV of aovs.py: color, albedo, normal, depth, primId, irisMnee and the eye AOVs nonEye,
glint, iris, sclera, limbalArc; and alpha, the colour's A), the beauty as
the LPE `C.*`, and the cryptomatte layers CryptoObject, CryptoMaterial and CryptoAsset (cryptomatte.py: channels
`{name}00.R` ..., float32 whatever the dataType). Anything else (a primvar, another LPE, an unknown name, a
dataType whose components the source lacks) is one warning naming the var, and no channel: an empty channel is
never written. dataType sets the components and the channel type (half types: 16-bit half channels, else 32-bit
float; ints are written as floats, exact to 2^24).

Channel names: the var's `driver:parameters:aov:name`, else its prim name, then `.R .G .B .A` (colour and
4-component types) or `.X .Y .Z` (normals, vectors, points, float3); a scalar is the name alone. The product's
first beauty var is plain R, G, B (A), so any viewer shows it. A product with `bool eyerender:multiPart = true`
is a multi-part EXR, one part per var named as the var.
"""
import dataclasses
import math
import re
from typing import Optional

from .aovs import AOV_CHANNELS, AOV_NAMES
from .cryptomatte import TYPES as CRYPTO_TYPES
from .cryptomatte import layer_channels
from .errors import EyeRenderError

# sourceName (raw) -> (AOV, first component): every AOV of the registry under its own name, and common aliases.
RAW_SOURCES = {
    **{name: (name, 0) for name in AOV_NAMES},
    "Ci": ("color", 0), "C": ("color", 0), "beauty": ("color", 0),
    "alpha": ("color", 3), "a": ("color", 3),
    "N": ("normal", 0),
}
LPE_SOURCES = {"C.*": ("color", 0)}  # light path expressions the renderer can produce: the whole beauty
AOV_COMPONENTS = {name: len(channels) for name, channels in AOV_CHANNELS.items()}
_VECTOR_SUFFIXES, _COLOR_SUFFIXES = ("X", "Y", "Z"), ("R", "G", "B", "A")
# UsdRender dataType -> (components, channel suffixes, half); UsdRender's fallback is color3f.
DATA_TYPES = {
    **{t: (1, (), t == "half") for t in ("float", "half", "int", "uint", "double")},
    **{t: (3, _COLOR_SUFFIXES[:3], t.endswith("h")) for t in ("color3f", "color3h", "color3d")},
    **{t: (4, _COLOR_SUFFIXES, t.endswith("h")) for t in ("color4f", "color4h", "color4d", "float4", "half4")},
    **{t: (3, _VECTOR_SUFFIXES, t.endswith("h") or t == "half3")
       for t in ("float3", "half3", "double3", "normal3f", "normal3h", "vector3f", "vector3h", "point3f", "point3h")},
}
DEFAULT_DATA_TYPE = "color3f"
MULTIPART_ATTRIBUTE = "eyerender:multiPart"
AOV_NAME_ATTRIBUTE = "driver:parameters:aov:name"
_HOUDINI_FRAME = re.compile(r"\$F(\d*)")  # husk's $F / $F4 frame tokens, as '#' runs


@dataclasses.dataclass(frozen=True)
class RenderVarSpec:
    """One render var as written: `aov` (a RenderSession AOV), its components [first, first + len(channels)),
    `channels` (EXR names), `half` (16-bit channels), `name` (the part name in a multi-part file), `path`."""
    path: str
    name: str
    aov: str
    first: int
    channels: tuple[str, ...]
    half: bool = False


@dataclasses.dataclass(frozen=True)
class RenderProductSpec:
    """One product: `name` (the file, '#' frame placeholders), `path` (its prim), `camera` (prim path or None),
    `width`/`height` (pixels; None: the session's), `data_window` (NDC xmin, ymin, xmax, ymax; None: all),
    `multipart`, `pixel_aspect` (a pixel's width over its height), and its `vars` in order."""
    path: str
    name: str
    vars: tuple[RenderVarSpec, ...]
    camera: Optional[str] = None
    width: Optional[int] = None
    height: Optional[int] = None
    data_window: Optional[tuple[float, float, float, float]] = None
    multipart: bool = False
    pixel_aspect: float = 1.0

    @property
    def aovs(self):
        return tuple(dict.fromkeys(v.aov for v in self.vars))


def product_name_pattern(name):
    """A productName as an output pattern: husk's `$F4` / `$F` frame tokens become '#' runs (4 / 1 wide)."""
    return _HOUDINI_FRAME.sub(lambda m: "#" * int(m.group(1) or 1), name)


def _authored(attr):
    return attr.Get() if attr and attr.HasAuthoredValue() else None


def _var_source(var, warn):
    """(AOV, first component) of a UsdRender.Var, or None after one warning naming it."""
    path = var.GetPath()
    source = str(var.GetSourceNameAttr().Get() or "")
    source_type = str(var.GetSourceTypeAttr().Get() or "raw")
    if source_type == "raw" and source.startswith("lpe:"):  # Hydra's spelling of an LPE as a raw AOV name
        source_type, source = "lpe", source[4:]
    table = {"raw": RAW_SOURCES, "lpe": LPE_SOURCES}.get(source_type)
    if table is None:
        warn(f"{path}: render var sourceType '{source_type}' ({source}) is not supported: not written")
        return None
    if source not in table:
        known = ", ".join(table)
        what = "LPE" if source_type == "lpe" else "sourceName"
        warn(f"{path}: render var {what} '{source}' is not supported ({known}): not written")
        return None
    return table[source]


def read_var(var, warn):
    """A RenderVarSpec of a UsdRender.Var (channel names without the beauty's plain R, G, B), or None after one
    warning naming it when the renderer cannot produce it."""
    source = _var_source(var, warn)
    if source is None:
        return None
    aov, first = source
    name = str(_authored(var.GetPrim().GetAttribute(AOV_NAME_ATTRIBUTE)) or var.GetPrim().GetName())
    if aov in CRYPTO_TYPES:  # its own layout; ids are float32 bits whatever the dataType
        return RenderVarSpec(str(var.GetPath()), name, aov, 0, layer_channels(name), False)
    data_type = str(var.GetDataTypeAttr().Get() or DEFAULT_DATA_TYPE)
    if data_type not in DATA_TYPES:
        warn(f"{var.GetPath()}: render var dataType '{data_type}' is not supported: not written")
        return None
    components, suffixes, half = DATA_TYPES[data_type]
    if first + components > AOV_COMPONENTS[aov]:
        warn(f"{var.GetPath()}: render var dataType {data_type} has {components} components, "
             f"{var.GetSourceNameAttr().Get()} {AOV_COMPONENTS[aov] - first}: not written")
        return None
    channels = tuple(f"{name}.{s}" for s in suffixes) if suffixes else (name,)
    return RenderVarSpec(str(var.GetPath()), name, aov, first, channels, half)


def _with_plain_beauty(specs):
    """The product's first colour var from component 0 writes plain R, G, B (A)."""
    for i, spec in enumerate(specs):
        if spec.aov == "color" and spec.first == 0 and len(spec.channels) >= 3:
            plain = _COLOR_SUFFIXES[:len(spec.channels)]
            return specs[:i] + [dataclasses.replace(spec, channels=plain)] + specs[i + 1:]
    return specs


def read_product_vars(stage, product, warn):
    """The RenderVarSpecs of a product's orderedVars that can be written, each channel once."""
    from pxr import UsdRender

    specs, channels = [], set()
    for target in product.GetOrderedVarsRel().GetTargets():
        var = UsdRender.Var(stage.GetPrimAtPath(target))
        if not var:
            warn(f"{product.GetPath()}: orderedVars target {target} is not a RenderVar: not written")
            continue
        spec = read_var(var, warn)
        if spec is not None:
            specs.append(spec)
    written = []
    for spec in _with_plain_beauty(specs):
        if channels & set(spec.channels) or any(spec.name == w.name for w in written):
            warn(f"{spec.path}: render var repeats the name '{spec.name}' of another var: not written")
            continue
        channels |= set(spec.channels)
        written.append(spec)
    return tuple(written)


def _data_window(base):
    """dataWindowNDC (xmin, ymin, xmax, ymax), None when it is the whole image; an empty one is an error."""
    window = base.GetDataWindowNDCAttr().Get()
    if window is None:
        return None
    window = tuple(float(v) for v in window)
    if window == (0.0, 0.0, 1.0, 1.0):
        return None
    if not window[0] < window[2] or not window[1] < window[3]:
        raise EyeRenderError(f"{base.GetPath()}: dataWindowNDC {window} is empty")
    return window


def _camera(base):
    targets = base.GetCameraRel().GetTargets()
    return str(targets[0]) if targets else None


def read_product(stage, settings, product, warn):
    """A RenderProductSpec of a UsdRender.Product under UsdRender.Settings `settings` (the product's authored
    camera, resolution and dataWindowNDC over the settings'), or None (one warning) when it has nothing to
    write or is not a raster image."""
    path = product.GetPath()
    product_type = str(product.GetProductTypeAttr().Get() or "raster")
    if product_type != "raster":
        warn(f"{path}: productType '{product_type}' is not supported (raster): not written")
        return None
    name = str(product.GetProductNameAttr().Get() or "")
    if not name:
        warn(f"{path}: productName is not authored: not written")
        return None
    specs = read_product_vars(stage, product, warn)
    if not specs:
        warn(f"{path}: no render var it orders can be written: not written")
        return None
    resolution = _authored(product.GetResolutionAttr()) or settings.GetResolutionAttr().Get()
    window = _data_window(product) if product.GetDataWindowNDCAttr().HasAuthoredValue() else _data_window(settings)
    multipart = product.GetPrim().GetAttribute(MULTIPART_ATTRIBUTE)
    aspect = _pixel_aspect(product, warn) if product.GetPixelAspectRatioAttr().HasAuthoredValue() else \
        _pixel_aspect(settings, warn)
    return RenderProductSpec(str(path), product_name_pattern(name), specs,
                             camera=_camera(product) or _camera(settings),
                             width=int(resolution[0]), height=int(resolution[1]), data_window=window,
                             multipart=bool(multipart and multipart.Get()), pixel_aspect=aspect)


def read_products(stage, settings_path, warn):
    """The RenderProductSpecs of the UsdRender.Settings prim at `settings_path`, in its products' order (the ones
    that cannot be written left out, each with one warning)."""
    from pxr import UsdRender

    settings = UsdRender.Settings(stage.GetPrimAtPath(settings_path)) if stage.GetPrimAtPath(settings_path) else None
    if not settings:
        raise EyeRenderError(f"{settings_path}: no RenderSettings prim there")
    products = []
    for target in settings.GetProductsRel().GetTargets():
        product = UsdRender.Product(stage.GetPrimAtPath(target))
        if not product:
            warn(f"{settings_path}: products target {target} is not a RenderProduct: not written")
            continue
        spec = read_product(stage, settings, product, warn)
        if spec is not None:
            products.append(spec)
    return products


def _pixel_aspect(base, warn=None):
    """A settings or product prim's authored pixelAspectRatio (a pixel's width over its height), 1 when not authored;
    one that is not a positive finite number is one warning and 1."""
    aspect = _authored(base.GetPixelAspectRatioAttr())
    if aspect is None:
        return 1.0
    if not (math.isfinite(float(aspect)) and float(aspect) > 0):
        if warn:
            warn(f"{base.GetPath()}: pixelAspectRatio {float(aspect):g} is not a positive number: square pixels")
        return 1.0
    return float(aspect)


def pixel_aspect_ratio(stage, settings_path, warn=None):
    """The pixelAspectRatio of the UsdRender.Settings prim at `settings_path` (1 without one, or not authored)."""
    from pxr import UsdRender

    prim = stage.GetPrimAtPath(settings_path) if settings_path else None
    settings = UsdRender.Settings(prim) if prim else None
    return _pixel_aspect(settings, warn) if settings else 1.0


def included_purposes(stage, settings_path):
    """The settings prim's authored includedPurposes (UsdGeom purposes), or None when not authored."""
    from pxr import UsdRender

    prim = stage.GetPrimAtPath(settings_path) if settings_path else None
    settings = UsdRender.Settings(prim) if prim else None
    value = _authored(settings.GetIncludedPurposesAttr()) if settings else None
    return None if value is None else tuple(str(p) for p in value)


def material_binding_purposes(stage, settings_path):
    """The settings prim's authored materialBindingPurposes (material purposes in order, "" all-purpose), or None
    when not authored (the renderer's own order then: materials.DEFAULT_BINDING_PURPOSES)."""
    from pxr import UsdRender

    prim = stage.GetPrimAtPath(settings_path) if settings_path else None
    settings = UsdRender.Settings(prim) if prim else None
    value = _authored(settings.GetMaterialBindingPurposesAttr()) if settings else None
    return None if value is None else tuple(str(p) for p in value)


def data_window_pixels(window, width, height):
    """NDC (xmin, ymin, xmax, ymax), y up, as pixel bounds (x0, y0, x1, y1) inclusive, rows top down (EXR's): the
    pixels whose centres lie inside it (UsdRender's dataWindowNDC), at least one."""
    def span(lo, hi, size):
        first = min(max(math.ceil(lo * size - 0.5), 0), size - 1)
        return first, min(max(math.floor(hi * size - 0.5), first), size - 1)

    x0, x1 = span(window[0], window[2], width)
    y0, y1 = span(1.0 - window[3], 1.0 - window[1], height)
    return x0, y0, x1, y1


__all__ = ["RenderVarSpec", "RenderProductSpec", "RAW_SOURCES", "LPE_SOURCES", "DATA_TYPES", "MULTIPART_ATTRIBUTE",
           "AOV_NAME_ATTRIBUTE", "product_name_pattern", "read_var", "read_product_vars", "read_product",
           "read_products", "included_purposes", "data_window_pixels"]
