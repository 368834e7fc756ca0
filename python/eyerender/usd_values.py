"""USD values as the delegate takes them: Gf matrices as 4x4 float64 arrays, Vt arrays as checked float32 (n, k)
arrays, and whether attributes vary in time."""
import numpy as np
from pxr import Gf

from .errors import EyeRenderError

_GF_VECTORS = (Gf.Vec2f, Gf.Vec2d, Gf.Vec2h, Gf.Vec3f, Gf.Vec3d, Gf.Vec3h)


def scalar_as_array(values):
    """A Gf vector where an array of them is meant (a color3f primvar for color3f[]) as one element, as Storm reads
    it; anything else as given."""
    return [values] if isinstance(values, _GF_VECTORS) else values


def to_matrix(m):
    """A Gf.Matrix4d as the 4x4 float64 array the delegate takes (same layout: no transpose)."""
    return np.array(m, dtype=np.float64).reshape(4, 4)


def to_float_array(values, components, what):
    """A Vt array (or sequence) as a C-contiguous float32 (n, components) view, copied only if its layout needs it."""
    try:
        a = np.asarray(values, dtype=np.float32)
    except (TypeError, ValueError):
        raise EyeRenderError(f"{what} is a {type(values).__name__}, not an array of numbers") from None
    if a.ndim != 2 or a.shape[1] != components:  # a flat float[] is not a point3f[], whatever its length
        raise EyeRenderError(f"{what} does not hold {components}-component values")
    if not np.isfinite(a).all():
        raise EyeRenderError(f"{what} holds NaN or infinite values")
    return np.ascontiguousarray(a)


def varies(attrs):
    """Whether any of attrs (None entries allowed) may change with time."""
    return any(a and a.ValueMightBeTimeVarying() for a in attrs)
