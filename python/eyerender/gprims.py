"""Implicit UsdGeom gprims as polygon meshes, so the delegate (which renders meshes) can draw them.

The delegate shades a polygon mesh with smooth vertex normals (the average of the faces around each point), so
the tessellation decides the shading, as GeomUtil's mesh generators do for Storm: a hard edge (a cap's rim, a
cube's edges) is two rings of points at one place, one for each side; a smooth surface shares its points.

Sphere, Capsule and Capsule_1: latitude-longitude meshes of 48 segments and 24 rings pole to pole (silhouettes
within 1 - cos(pi / 48) = 0.21 % of the radius). Cylinder, Cylinder_1 and Cone: 48 segments, flat caps. Cube: 6
quads of their own corners (flat, as Storm's bilinear cube). Plane: one quad. Sizes are in the stage's units;
`axis` (X, Y or Z) is the spine (the Plane's normal).
"""
import math

import numpy as np
from pxr import UsdGeom

from .errors import EyeRenderError

SEGMENTS = 48  # around the spine
RINGS_PER_TURN = 24  # of latitude, pole to pole, on spherical parts


def _positive(prim, name, value, allow_zero=False):
    value = float(value)
    if not (math.isfinite(value) and (value >= 0 if allow_zero else value > 0)):
        bound = "non-negative" if allow_zero else "positive"
        raise EyeRenderError(f"{prim.GetPath()}: {prim.GetTypeName()} {name} {value:g} must be {bound} and finite")
    return value


def _revolve(sections):
    """A surface of revolution about the spine. `sections` is a list of (profile, apex): a profile is a list of
    (rho, z) points from bottom to top, and consecutive sections meet at a hard edge (their shared profile point
    is two rings). A profile point with rho 0 is a pole: one point where the profile crosses the spine, or (apex)
    one point per side face where it ends there on a slope, so each face keeps its own normal at the tip."""
    points, counts, indices = [], [], []
    for profile, apex in sections:
        rings, tips = [], set()  # per profile point: SEGMENTS point indices; which of them are apex tips
        for rho, z in profile:
            first = len(points)
            if rho == 0.0 and not apex:
                points.append((0.0, 0.0, z))
                rings.append([first] * SEGMENTS)
                continue
            points += [(rho * math.cos(phi), rho * math.sin(phi), z)
                       for phi in (2.0 * math.pi * seg / SEGMENTS for seg in range(SEGMENTS))]
            rings.append(list(range(first, first + SEGMENTS)))
            if rho == 0.0:
                tips.add(len(rings) - 1)
        for r in range(len(rings) - 1):
            below, above = rings[r], rings[r + 1]
            for seg in range(SEGMENTS):  # counter-clockwise seen from outside
                nxt = (seg + 1) % SEGMENTS
                if r + 1 in tips:
                    face = [below[seg], below[nxt], above[seg]]
                elif r in tips:
                    face = [below[seg], above[nxt], above[seg]]
                else:  # a pole's quads are triangles
                    face = list(dict.fromkeys([below[seg], below[nxt], above[nxt], above[seg]]))
                counts.append(len(face))
                indices += face
    return counts, indices, points


def _arc(radius, z_center, start, end):
    """Profile points of a circle of `radius` about (0, z_center) from latitude `start` to `end` (radians; a pole
    is exactly +-pi/2), at the spherical parts' ring spacing."""
    steps = max(1, round(abs(end - start) / math.pi * RINGS_PER_TURN))
    lats = [start + (end - start) * i / steps for i in range(steps)] + [end]
    return [(0.0 if abs(lat) == math.pi / 2 else radius * math.cos(lat), z_center + radius * math.sin(lat))
            for lat in lats]


def _capsule(bottom_radius, top_radius, height):
    """The convex hull of two spheres on the spine, `height` apart (a sphere when height is 0): each cap meets
    the cone between them where it is tangent to it, at latitude asin((bottom - top) / height)."""
    if height <= abs(bottom_radius - top_radius):  # one sphere holds the other
        radius, center = (bottom_radius, -height / 2) if bottom_radius >= top_radius else (top_radius, height / 2)
        return _revolve([(_arc(radius, center, -math.pi / 2, math.pi / 2), False)])
    tangent = math.asin((bottom_radius - top_radius) / height)
    profile = _arc(bottom_radius, -height / 2, -math.pi / 2, tangent) + _arc(top_radius, height / 2, tangent,
                                                                                math.pi / 2)[1:]
    return _revolve([(profile, False)])


def _cylinder(bottom_radius, top_radius, height):
    """A cylinder or cone frustum with flat caps; a radius of 0 is an apex."""
    bottom, top = (bottom_radius, -height / 2), (top_radius, height / 2)
    sections = [([(0.0, bottom[1]), bottom], False)] if bottom_radius > 0 else []
    sections.append(([bottom, top], True))
    if top_radius > 0:
        sections.append(([top, (0.0, top[1])], False))
    return _revolve(sections)


def _cube(size):
    h = size / 2
    corners = [(x, y, z) for z in (-h, h) for y in (-h, h) for x in (-h, h)]
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    return [4] * 6, list(range(24)), [corners[i] for q in quads for i in q]  # each face its own corners


def _plane(width, length):
    w, h = width / 2, length / 2
    return [4], [0, 1, 2, 3], [(-w, -h, 0.0), (w, -h, 0.0), (w, h, 0.0), (-w, h, 0.0)]


# The built shapes' spine (a Plane's normal) is z; these map their (x, y, z) to the stage's axes for each `axis`:
# cyclic permutations for the round shapes; for the Plane, its schema's width and length axes, with y negated
# where that alone keeps the map a rotation (so windings stay counter-clockwise seen from outside).
_AXES = {"Z": ((0, 1, 2), 1), "X": ((1, 2, 0), 1), "Y": ((2, 0, 1), 1)}
_PLANE_AXES = {"Z": ((0, 1, 2), 1), "X": ((2, 1, 0), -1), "Y": ((0, 2, 1), -1)}


def _on_axis(points, axis, axes):
    order, y_sign = axes[axis]
    built = np.asarray(points, dtype=np.float64) * (1.0, y_sign, 1.0)
    out = np.zeros_like(built)
    out[:, list(order)] = built
    return out


def _shape(prim, time):
    """(builder arguments and builder, axis table) for a supported gprim, else None."""
    get = lambda name: prim.GetAttribute(name).Get(time)  # noqa: E731 (schema attributes all have fallbacks)
    if prim.IsA(UsdGeom.Sphere):
        return (_capsule, (_positive(prim, "radius", get("radius")),) * 2 + (0.0,)), None
    if prim.IsA(UsdGeom.Cube):
        return (_cube, (_positive(prim, "size", get("size")),)), None
    if prim.IsA(UsdGeom.Plane):
        return (_plane, (_positive(prim, "width", get("width")), _positive(prim, "length", get("length")))), \
            _PLANE_AXES
    if prim.IsA(UsdGeom.Capsule) or prim.IsA(UsdGeom.Cylinder) or prim.IsA(UsdGeom.Cone):
        radius = _positive(prim, "radius", get("radius"))
        build = _capsule if prim.IsA(UsdGeom.Capsule) else _cylinder
        top = 0.0 if prim.IsA(UsdGeom.Cone) else radius
        height = _positive(prim, "height", get("height"), allow_zero=build is _capsule)
        return (build, (radius, top, height)), _AXES
    if prim.IsA(UsdGeom.Capsule_1) or prim.IsA(UsdGeom.Cylinder_1):
        build = _capsule if prim.IsA(UsdGeom.Capsule_1) else _cylinder
        bottom = _positive(prim, "radiusBottom", get("radiusBottom"), allow_zero=build is _cylinder)
        top = _positive(prim, "radiusTop", get("radiusTop"), allow_zero=build is _cylinder)
        if bottom == top == 0.0:
            raise EyeRenderError(f"{prim.GetPath()}: {prim.GetTypeName()} radiusTop and radiusBottom are both 0")
        height = _positive(prim, "height", get("height"), allow_zero=build is _capsule)
        return (build, (bottom, top, height)), _AXES
    return None


def tessellate_gprim(prim, time):
    """(counts, indices, points) arrays for an implicit gprim (Sphere, Cube, Plane, Capsule, Cylinder, Cone and
    their _1 forms) at `time`, or None for other gprims. A bad size or axis raises EyeRenderError."""
    shape = _shape(prim, time)
    if shape is None:
        return None
    (build, args), axes = shape
    counts, indices, points = build(*args)
    if axes is not None:
        axis = prim.GetAttribute("axis").Get(time)
        if axis not in axes:
            raise EyeRenderError(f"{prim.GetPath()}: {prim.GetTypeName()} axis '{axis}' must be X, Y or Z")
        points = _on_axis(points, axis, axes)
    return (np.asarray(counts, dtype=np.int32), np.asarray(indices, dtype=np.int32),
            np.asarray(points, dtype=np.float32))
