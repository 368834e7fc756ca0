"""Implicit UsdGeom gprims as polygon meshes, so the delegate (which renders meshes) can draw them.

Sphere: a latitude-longitude mesh of 48 x 24 faces (the delegate's smooth normals shade it round; silhouettes are
within 0.2 % of the radius). Cube: its 6 quads. Other gprims are not supported yet (the caller warns).
"""
import math

import numpy as np
from pxr import UsdGeom

from .errors import EyeRenderError

SPHERE_SEGMENTS, SPHERE_RINGS = 48, 24


def _sphere(radius):
    points = [(0.0, -radius, 0.0)]
    for ring in range(1, SPHERE_RINGS):
        theta = math.pi * ring / SPHERE_RINGS
        y, r = -radius * math.cos(theta), radius * math.sin(theta)
        for seg in range(SPHERE_SEGMENTS):
            phi = 2 * math.pi * seg / SPHERE_SEGMENTS
            points.append((r * math.cos(phi), y, -r * math.sin(phi)))
    points.append((0.0, radius, 0.0))
    top = len(points) - 1

    def ring_point(ring, seg):
        return 1 + (ring - 1) * SPHERE_SEGMENTS + seg % SPHERE_SEGMENTS

    counts, indices = [], []
    for seg in range(SPHERE_SEGMENTS):  # bottom fan, counter-clockwise seen from outside
        counts.append(3)
        indices += [0, ring_point(1, seg + 1), ring_point(1, seg)]
    for ring in range(1, SPHERE_RINGS - 1):
        for seg in range(SPHERE_SEGMENTS):
            counts.append(4)
            indices += [ring_point(ring, seg), ring_point(ring, seg + 1), ring_point(ring + 1, seg + 1),
                        ring_point(ring + 1, seg)]
    for seg in range(SPHERE_SEGMENTS):
        counts.append(3)
        indices += [top, ring_point(SPHERE_RINGS - 1, seg), ring_point(SPHERE_RINGS - 1, seg + 1)]
    return counts, indices, points


def _cube(size):
    h = size / 2
    points = [(x, y, z) for z in (-h, h) for y in (-h, h) for x in (-h, h)]
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    return [4] * 6, [i for q in quads for i in q], points


def tessellate_gprim(prim, time):
    """(counts, indices, points) arrays for a Sphere or Cube prim at `time`, or None for other gprims."""
    if prim.IsA(UsdGeom.Sphere):
        size, build = UsdGeom.Sphere(prim).GetRadiusAttr().Get(time), _sphere
    elif prim.IsA(UsdGeom.Cube):
        size, build = UsdGeom.Cube(prim).GetSizeAttr().Get(time), _cube
    else:
        return None
    if not (math.isfinite(size) and size > 0):
        raise EyeRenderError(f"{prim.GetPath()}: {prim.GetTypeName()} size {size} must be positive and finite")
    counts, indices, points = build(float(size))
    return (np.asarray(counts, dtype=np.int32), np.asarray(indices, dtype=np.int32),
            np.asarray(points, dtype=np.float32))
