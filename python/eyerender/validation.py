"""Checks on what the front end reads from USD before it reaches the delegate: transforms, typed attribute values,
and one guard that turns whatever reading a prim raises (USD's own errors, a value of the wrong type) into an
EyeRenderError naming the prim, so the scene delegate can skip that prim with one warning.

No value is clamped or guessed: a check passes the value through unchanged or raises.
"""
import contextlib
import math
import numbers

from .errors import EyeRenderError
from .usd_diagnostics import summarise_tf_error

# Scene units. Beyond this a float32 coordinate keeps no useful precision for any scene (its spacing is 1e8
# units), and ray origins there reach Embree as garbage.
MAX_COORDINATE = 1e15
# |det| of a transform's 3x3 part over its largest axis scale cubed: below this the transform squashes space
# onto a plane or a line (scale 0), and its inverse (which rays and normals need) does not exist.
MIN_RELATIVE_DETERMINANT = 1e-12


def check_transform(path, matrix, what="transform"):
    """`matrix` (a Gf.Matrix4d, row-vector layout) if it is a usable local-to-world transform; raises
    EyeRenderError naming `path` for non-finite entries, coordinates beyond MAX_COORDINATE, a singular linear
    part or a projective column. Returns the matrix unchanged."""
    entries = [float(matrix[r][c]) for r in range(4) for c in range(4)]
    if not all(math.isfinite(v) for v in entries):
        raise EyeRenderError(f"{path}: {what} has NaN or infinite entries")
    if max(abs(v) for v in entries) > MAX_COORDINATE:
        raise EyeRenderError(f"{path}: {what} has entries beyond {MAX_COORDINATE:g} scene units")
    if any(abs(matrix[r][3]) > 1e-9 for r in range(3)) or abs(matrix[3][3] - 1) > 1e-9:
        raise EyeRenderError(f"{path}: {what} is projective (last column not (0, 0, 0, 1))")
    scale = max(math.sqrt(sum(matrix[r][c] ** 2 for c in range(3))) for r in range(3))
    if scale == 0 or abs(matrix.GetDeterminant3()) < MIN_RELATIVE_DETERMINANT * scale ** 3:
        raise EyeRenderError(f"{path}: {what} is singular (a scale of 0 along some axis)")
    return matrix


def as_float(path, name, value, finite=True):
    """value as a finite float; raises EyeRenderError naming the attribute for another type or NaN/Inf (finite:
    False passes NaN/Inf through, for a range check that names the valid range)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise EyeRenderError(f"{path}: {name} is a {type(value).__name__}, not a number")
    if finite and not math.isfinite(value):
        raise EyeRenderError(f"{path}: {name} = {value} is not finite")
    return float(value)


def as_vector(path, name, value, size=3, finite=True):
    """value (a Gf vector or sequence) as a tuple of `size` finite floats (any floats, finite: False); raises
    EyeRenderError otherwise."""
    try:
        items = tuple(value)
    except TypeError:
        raise EyeRenderError(f"{path}: {name} is a {type(value).__name__}, not a {size}-vector") from None
    if len(items) != size:
        raise EyeRenderError(f"{path}: {name} has {len(items)} components, not {size}")
    return tuple(as_float(path, name, v, finite) for v in items)


@contextlib.contextmanager
def reading(path):
    """Runs a block that reads prim `path`; USD errors (Tf.ErrorException), values of unexpected types
    (TypeError, ValueError from a conversion) and undecodable text become one EyeRenderError naming the prim."""
    try:
        yield
    except EyeRenderError:
        raise
    except (TypeError, ValueError, OverflowError, IndexError) as e:
        # UnicodeDecodeError is a ValueError; a bad value's text may itself be undecodable.
        raise EyeRenderError(f"{path}: unreadable value ({type(e).__name__}: {summarise_tf_error(e)})") from None
    except Exception as e:
        if type(e).__name__ != "ErrorException":  # Tf.ErrorException, without importing pxr here
            raise
        raise EyeRenderError(f"{path}: {summarise_tf_error(e)}") from None


__all__ = ["MAX_COORDINATE", "MIN_RELATIVE_DETERMINANT", "check_transform", "as_float", "as_vector", "reading"]
