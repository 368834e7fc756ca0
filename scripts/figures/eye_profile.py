"""The anterior-surface profiles z = f(r) of Chiang and Burley 2018, written again in Python from the paper's
formulas (mm, corneal apex at the origin, gaze +z, r = sqrt(x^2 + y^2)), independently of eyelib's C++, so the
figures can check the renderer's model instead of repeating it.

- ellipsoid, 2r < 10.02:  0.75 z^2 + 15.6 z + r^2 = 0, the root through the apex;
- cone, 10.02 <= 2r <= 15.08: z = f(5.01) - (r - 5.01) tan 38deg. The paper prints z - r tan 38 = 0, which has
  no offset and is not continuous with the ellipsoid; with the offset f(7.54) = -3.734 mm, the paper's 3.735 mm;
- paraboloid approximation: 14.5 z + r^2 = 0.
"""
import math

import numpy as np

ELLIPSOID_Z2, ELLIPSOID_Z1 = 0.75, 15.6  # 0.75 z^2 + 15.6 z + r^2 = 0
PARABOLOID_Z1 = 14.5  # 14.5 z + r^2 = 0
JUNCTION_CHORD = 10.02  # mm, ellipsoid -> cone
RIM_CHORD = 15.08  # mm, the cone's end and the iris diameter
CONE_ANGLE_DEG = 38.0  # from the xy-plane
ANATOMICAL_IRIS_DEPTH = 3.735  # mm below the apex, at the 15.08 mm chord (Kojima et al. 2013)
LIMBUS_INNER_CHORD, LIMBUS_OUTER_CHORD = 11.64, 12.89  # mm (Iskander 2006)
CORNEA_IOR = 1.376
PUPIL_DIAMETER = 4.0  # mm, the EyeAPI default (not from the paper)

TAN_CONE = math.tan(math.radians(CONE_ANGLE_DEG))
JUNCTION_R = JUNCTION_CHORD / 2
RIM_R = RIM_CHORD / 2


def ellipsoid_sag(r):
    """Root of 0.75 z^2 + 15.6 z + r^2 = 0 through the apex, mm (valid for r^2 <= 15.6^2 / 3)."""
    r = np.asarray(r, dtype=float)
    return (-ELLIPSOID_Z1 + np.sqrt(ELLIPSOID_Z1 ** 2 - 4 * ELLIPSOID_Z2 * r * r)) / (2 * ELLIPSOID_Z2)


def ellipsoid_cone_sag(r):
    """The paper's surface with the cone offset that makes it continuous, mm."""
    r = np.asarray(r, dtype=float)
    cone = ellipsoid_sag(JUNCTION_R) - (r - JUNCTION_R) * TAN_CONE
    return np.where(r < JUNCTION_R, ellipsoid_sag(np.minimum(r, JUNCTION_R)), cone)


def paraboloid_sag(r):
    r = np.asarray(r, dtype=float)
    return -r * r / PARABOLOID_Z1


def ellipsoid_cone_slope(r):
    """df/dr: implicit differentiation on the ellipsoid, -tan 38deg on the cone."""
    r = np.asarray(r, dtype=float)
    f = ellipsoid_sag(np.minimum(r, JUNCTION_R))
    return np.where(r < JUNCTION_R, -2 * r / (2 * ELLIPSOID_Z2 * f + ELLIPSOID_Z1), -TAN_CONE)


def paraboloid_slope(r):
    return -2 * np.asarray(r, dtype=float) / PARABOLOID_Z1


SAG = {"ellipsoidCone": ellipsoid_cone_sag, "paraboloid": paraboloid_sag}
SLOPE = {"ellipsoidCone": ellipsoid_cone_slope, "paraboloid": paraboloid_slope}


def inverse_sag(model, depth):
    """The radius (mm) where the surface is `depth` mm below the apex: where an iris plane at that depth meets the
    cornea, i.e. the iris disk's radius (capped at the 7.54 mm rim), found by bisection so it needs no inverse."""
    lo, hi = 0.0, RIM_R
    if -SAG[model](hi) <= depth:
        return RIM_R
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if -SAG[model](mid) < depth else (lo, mid)
    return 0.5 * (lo + hi)


def junction_kink_deg():
    """Angle between the ellipsoid's and the cone's tangents at the 10.02 mm chord, degrees."""
    slope_in = float(-2 * JUNCTION_R / (2 * ELLIPSOID_Z2 * ellipsoid_sag(JUNCTION_R) + ELLIPSOID_Z1))
    return math.degrees(math.atan(TAN_CONE) - math.atan(-slope_in)), slope_in
