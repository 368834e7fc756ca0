"""Writing a render product (render_products.RenderProductSpec) from a render's AOV images: exactly the channels
its vars name, each float or half, in one part or one part per var, cropped to its data window, with the render
plan and the UsdRender prims that made it in the header. Atomic, as every output (output_files.py)."""
import os

import numpy as np

from .cryptomatte import TYPES as CRYPTO_TYPES
from .cryptomatte import header_attributes
from .errors import EyeRenderError
from .render_products import data_window_pixels

PRODUCT_ATTRIBUTE = "eyerender:renderProduct"  # the UsdRender.Product prim a file was written for
SETTINGS_ATTRIBUTE = "eyerender:renderSettings"  # and its UsdRender.Settings prim


def product_parts(product, images, window=None):
    """[(part name, [(channel, float32 (rows, columns), 'half' | 'float')])] of `product` from AOV images
    ({aov: float32 (height, width, components)}), cropped to `window` (x0, y0, x1, y1 inclusive; None: all).
    One part named "" unless the product is multi-part (then one per var, named as the var)."""
    parts = []
    for var in product.vars:
        pixels = images[var.aov]
        if window is not None:
            x0, y0, x1, y1 = window
            pixels = pixels[y0:y1 + 1, x0:x1 + 1]
        kind = "half" if var.half else "float"
        planes = [(channel, np.ascontiguousarray(pixels[:, :, var.first + c], dtype=np.float32), kind)
                  for c, channel in enumerate(var.channels)]
        if product.multipart:
            parts.append((var.name, planes))
        elif parts:
            parts[0][1].extend(planes)
        else:
            parts.append(("", planes))
    return parts


def write_product_exr(path, product, images, attributes=None, settings_path=None, manifests=None):
    """Writes `product` as the EXR `path` from AOV images as product_parts lays them out: exactly its vars'
    channels, the header attributes {name: string}, the product's and settings' prim paths, and each cryptomatte
    var's metadata, named as the var, with its manifest from `manifests` ({layer: {name: id bits}}). Atomic."""
    from ._hdeye import write_exr_parts
    from .output_files import remove_stale_temp_files

    height, width = images["color"].shape[:2]
    window = data_window_pixels(product.data_window, width, height) if product.data_window else None
    header = {**(attributes or {}), PRODUCT_ATTRIBUTE: product.path}
    if settings_path:
        header[SETTINGS_ATTRIBUTE] = settings_path
    for var in product.vars:
        if var.aov in CRYPTO_TYPES:
            header.update(header_attributes(var.name, (manifests or {}).get(var.aov, {})))
    remove_stale_temp_files(path)
    try:
        write_exr_parts(path, width, height, product_parts(product, images, window), sorted(header.items()),
                        window or (0, 0, -1, -1), product.multipart)
    except (RuntimeError, ValueError) as e:
        raise EyeRenderError(str(e)) from None


def product_outputs(product, png):
    """The output patterns of a product: its name, and with `png` a .png preview beside an .exr."""
    name = product.name
    return (name, name[:-4] + ".png") if png and name.lower().endswith(".exr") else (name,)


def product_summary(product):
    """One line naming a product's file and channels, for the render's start."""
    channels = [c for v in product.vars for c in v.channels]
    where = f" ({'multi-part, ' if product.multipart else ''}{len(channels)} channels: {' '.join(channels)})"
    return f"product {os.path.basename(product.name)}{where}"


__all__ = ["PRODUCT_ATTRIBUTE", "SETTINGS_ATTRIBUTE", "product_parts", "write_product_exr", "product_outputs",
           "product_summary"]
