"""A denoised preview of the beauty for look-dev: Intel Open Image Denoise (the `pyoidn` wheel, its CPU device)
on the colour with the albedo and normal AOVs as guides. Written beside the raw beauty, never over it: EXR
channels denoised.R/G/B and a `<name>.denoised.png` preview (docs/denoise.md measures what it does to error,
and where it smears the iris caustic).
"""
import os

import numpy as np

from .errors import EyeRenderError

# The AOVs OIDN is guided by; a denoised render renders them too.
GUIDE_AOVS = ("albedo", "normal")
DENOISED_CHANNELS = ("denoised.R", "denoised.G", "denoised.B")


def denoise_beauty(color, albedo, normal):
    """The denoised RGB (float32 (h, w, 3)) of a linear HDR beauty `color` (h, w, 3 or 4), guided by `albedo`
    (h, w, 3; [0, 1]) and `normal` (h, w, 3; unit, any space). Raises EyeRenderError when pyoidn is missing."""
    try:
        import pyoidn
    except ImportError:
        raise EyeRenderError("--denoise needs Intel Open Image Denoise: pip install pyoidn") from None
    rgb = np.ascontiguousarray(np.nan_to_num(color[:, :, :3], nan=0.0, posinf=0.0), dtype=np.float32)
    guide_albedo = np.ascontiguousarray(np.clip(albedo[:, :, :3], 0.0, 1.0), dtype=np.float32)
    guide_normal = np.ascontiguousarray(normal[:, :, :3], dtype=np.float32)
    try:
        out = pyoidn.denoise(rgb, guide_albedo, guide_normal, hdr=True)
    except (RuntimeError, ValueError, TypeError) as e:
        raise EyeRenderError(f"denoise: {str(e).splitlines()[0][:160]}") from None
    return np.ascontiguousarray(out, dtype=np.float32)


def denoised_png_path(path):
    """Where the denoised preview of output `path` goes: out/shot.0001.png -> out/shot.0001.denoised.png."""
    root, _ = os.path.splitext(path)
    return root + ".denoised.png"


__all__ = ["GUIDE_AOVS", "DENOISED_CHANNELS", "denoise_beauty", "denoised_png_path"]
