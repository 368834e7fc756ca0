"""UsdGeom BasisCurves and Points for the delegate (HdBasisCurves / HdPoints): curves as Embree tubes (ribbons where
normals are authored), points as spheres; widths are diameters in the prim's space (1 where unauthored). One width
(or normal) where the interpolation wants one per vertex is a constant, as Storm reads it.

Each reader returns a callable that pushes the prim's geometry at a time code, so `set_time` can re-push what is
animated. Bad data (counts, sizes, NaN) is raised as EyeRenderError naming the prim; the scene delegate then skips
the prim with that warning. Curves too short for their kind are left out with one warning (Storm draws the rest),
and so is a displayColor that does not fit.
"""
import numpy as np
from pxr import UsdGeom

from .errors import EyeRenderError
from .usd_values import scalar_as_array

INTERPOLATIONS = ("constant", "uniform", "vertex", "varying")


def is_curves_or_points(prim):
    return prim.IsA(UsdGeom.BasisCurves) or prim.IsA(UsdGeom.Points)


def _points(prim, time):
    points = UsdGeom.PointBased(prim).GetPointsAttr().Get(time)
    if points is None or len(points) == 0:
        raise EyeRenderError(f"{prim.GetPath()}: no points")
    a = np.asarray(points, dtype=np.float32).reshape(-1, 3)
    if not np.isfinite(a).all():
        raise EyeRenderError(f"{prim.GetPath()}: points hold NaN or infinite values")
    return np.ascontiguousarray(a)


def _primvar(prim, name, attr, interpolation, components, time):
    """(interpolation, values (n, components) float32) of primvars:name, else of the schema attribute; None when
    neither is authored."""
    primvar = UsdGeom.PrimvarsAPI(prim).FindPrimvarWithInheritance(name)  # constant ones are inherited
    if primvar and primvar.HasValue():
        values, interpolation = primvar.ComputeFlattened(time), primvar.GetInterpolation()
    elif attr and attr.HasValue():
        values = attr.Get(time)
    else:
        return None
    values = scalar_as_array(values)
    if values is None or len(values) == 0:
        return None
    if str(interpolation) not in INTERPOLATIONS:
        raise EyeRenderError(f"{prim.GetPath()}: {name} interpolation '{interpolation}' is not one of "
                             f"{', '.join(INTERPOLATIONS)}")
    a = np.asarray(values, dtype=np.float32).reshape(-1, components)
    if not np.isfinite(a).all():
        raise EyeRenderError(f"{prim.GetPath()}: {name} holds NaN or infinite values")
    return str(interpolation), np.ascontiguousarray(a)


def _varying_count(n, curve_type, basis, wrap):
    """Varying values of a curve of n vertices (UsdGeomBasisCurves: its segments, plus one unless periodic)."""
    if curve_type == "linear":
        return n
    periodic = wrap == "periodic"
    if basis == "bezier":
        segments = n // 3 if periodic else (n - 1) // 3
    else:
        segments = n if periodic else n - 1 if wrap == "pinned" else n - 3
    return max(segments, 0) + (0 if periodic else 1)  # a curve too short to draw still takes one


def _check_size(prim, name, primvar, expected):
    interpolation, values = primvar
    if interpolation in expected and len(values) != expected[interpolation]:
        raise EyeRenderError(f"{prim.GetPath()}: {name} has {len(values)} values, {interpolation} needs "
                             f"{expected[interpolation]}")


def _read_primvars(prim, schema, time, normals, warn):
    """[(name, (interpolation, values))] of widths (and normals for curves) and displayColor, checked against the
    prim's counts: bad widths or normals raise EyeRenderError; a displayColor that does not fit is left out with
    `warn(message)` (the prim renders grey, as a mesh does)."""
    expected = _expected_sizes(prim, time)
    widths = _primvar(prim, "widths", schema.GetWidthsAttr(), schema.GetWidthsInterpolation(), 1, time)
    n = _primvar(prim, "normals", schema.GetNormalsAttr(), schema.GetNormalsInterpolation(), 3, time) \
        if normals else None
    color = _primvar(prim, "displayColor", None, None, 3, time)
    # One value where there should be one per vertex is a constant, as Storm reads it (widths = [w] is common).
    read = [(name, ("constant", primvar[1]) if primvar[0] in ("vertex", "varying") and len(primvar[1]) == 1
             else primvar) for name, primvar in (("widths", widths), ("normals", n), ("displayColor", color))
            if primvar]
    for name, primvar in list(read):
        try:
            _check_size(prim, name, primvar, expected)
        except EyeRenderError as e:
            if name != "displayColor":
                raise
            warn(f"{e}: ignored")
            read.remove((name, primvar))
    widths = dict(read).get("widths")
    if widths and (widths[1] < 0).any():
        raise EyeRenderError(f"{prim.GetPath()}: widths holds a negative width")
    return read


def _push(store, prim_id, primvars):
    for name, (interpolation, values) in primvars:
        store.set_primvar(prim_id, name, interpolation, values)


def _expected_sizes(prim, time):
    """Element counts by interpolation for the primvars of a BasisCurves or Points prim."""
    point_count = len(UsdGeom.PointBased(prim).GetPointsAttr().Get(time) or [])
    if not prim.IsA(UsdGeom.BasisCurves):
        return {"constant": 1, "vertex": point_count, "varying": point_count}
    curves = UsdGeom.BasisCurves(prim)
    counts = curves.GetCurveVertexCountsAttr().Get(time) or []
    tokens = [str(a.Get(time)) for a in (curves.GetTypeAttr(), curves.GetBasisAttr(), curves.GetWrapAttr())]
    return {"constant": 1, "uniform": len(counts), "vertex": point_count,
            "varying": sum(_varying_count(int(c), *tokens) for c in counts)}


def _check_counts(prim, counts, point_count, curve_type, basis, wrap):
    """The indices of the curves the delegate would reject (hdeye's curveSegments.h: too few vertices, or a bezier
    count not 3 k (+ 1)); counts that do not add up to the points, or no curve left, raise EyeRenderError."""
    path = prim.GetPath()
    if int(counts.sum()) != point_count:
        raise EyeRenderError(f"{path}: curveVertexCounts add up to {int(counts.sum())}, there are {point_count} points")
    cubic, periodic = curve_type == "cubic", wrap == "periodic"
    minimum = 2 if not cubic else 3 if periodic else 2 if wrap == "pinned" and basis != "bezier" else 4
    bad = counts < minimum
    if cubic and basis == "bezier":
        bad |= (counts % 3 != 0) if periodic else ((counts - 1) % 3 != 0)
    if bad.all():
        if (counts < minimum).any():
            raise EyeRenderError(f"{path}: a curve has {int(counts.min())} vertices, {curve_type} {basis} {wrap} "
                                 f"curves need {minimum}")
        raise EyeRenderError(f"{path}: bezier curves need 3 k{'' if periodic else ' + 1'} vertices each")
    return np.flatnonzero(bad)


def _without_curves(dropped, counts, tokens, points, primvars):
    """counts, points and primvars with the curves `dropped` (indices) left out, each primvar by its interpolation."""
    keep = np.ones(len(counts), dtype=bool)
    keep[dropped] = False
    varying = np.array([_varying_count(int(c), *tokens) for c in counts])

    def rows(sizes):  # the elements of the kept curves, curve by curve
        return np.repeat(keep, sizes)

    per = {"uniform": keep, "vertex": rows(counts), "varying": rows(varying)}
    kept_primvars = [(name, (interp, values if interp == "constant" else values[per[interp]]))
                     for name, (interp, values) in primvars]
    return counts[keep], np.ascontiguousarray(points[rows(counts)]), kept_primvars


def _curves_data(prim, time, warn):
    """(counts, tokens, points, primvars) of a BasisCurves prim as the delegate takes them: curves it would reject
    left out with one warning (Storm draws the others), anything else bad raised as EyeRenderError."""
    curves = UsdGeom.BasisCurves(prim)
    counts = np.asarray(curves.GetCurveVertexCountsAttr().Get(time) or [], dtype=np.int32)
    if len(counts) == 0:
        raise EyeRenderError(f"{prim.GetPath()}: curveVertexCounts is empty")
    tokens = [str(a.Get(time)) for a in (curves.GetTypeAttr(), curves.GetBasisAttr(), curves.GetWrapAttr())]
    choices = (("linear", "cubic"), ("bezier", "bspline", "catmullRom"), ("nonperiodic", "periodic", "pinned"))
    for name, token, allowed in zip(("type", "basis", "wrap"), tokens, choices):
        if token not in allowed:
            raise EyeRenderError(f"{prim.GetPath()}: {name} '{token}' is not one of {', '.join(allowed)}")
    points = _points(prim, time)
    dropped = _check_counts(prim, counts, len(points), *tokens)
    primvars = _read_primvars(prim, curves, time, normals=True, warn=warn)
    if len(dropped):
        listed = ", ".join(str(int(i)) for i in dropped[:5]) + (", ..." if len(dropped) > 5 else "")
        warn(f"{prim.GetPath()}: {len(dropped)} of {len(counts)} curves ({listed}) have a vertex count "
             f"{' '.join(tokens)} curves cannot take: left out")
        counts, points, primvars = _without_curves(dropped, counts, tokens, points, primvars)
    return counts, tokens, points, primvars


def add_basis_curves(store, prim, prim_id, world, material_id, time, warn):
    """Adds a BasisCurves prim; returns the attributes whose animation needs a re-push (set_time). warn(message):
    a primvar or curves left out."""
    counts, tokens, points, primvars = _curves_data(prim, time, warn)
    store.add_basis_curves(prim_id, counts, points, *tokens, world, material_id)
    _push(store, prim_id, primvars)
    curves = UsdGeom.BasisCurves(prim)
    return [curves.GetPointsAttr(), curves.GetWidthsAttr(), curves.GetNormalsAttr()]


def add_points(store, prim, prim_id, world, material_id, time, warn):
    """Adds a Points prim as spheres; returns the attributes whose animation needs a re-push (set_time). warn(message):
    a primvar left out."""
    points = UsdGeom.Points(prim)
    primvars = _read_primvars(prim, points, time, normals=False, warn=warn)
    store.add_points(prim_id, _points(prim, time), world, material_id)
    _push(store, prim_id, primvars)
    return [points.GetPointsAttr(), points.GetWidthsAttr()]


def update(store, prim, prim_id, time, warn):
    """Re-pushes animated points and widths (and curve normals): the prim's geometry is re-built at next sync."""
    if prim.IsA(UsdGeom.BasisCurves):
        _, _, points, primvars = _curves_data(prim, time, warn)
    else:
        points, primvars = _points(prim, time), _read_primvars(prim, UsdGeom.Points(prim), time, False, warn)
    store.set_points(prim_id, points)
    _push(store, prim_id, primvars)
