"""Motion samples over a frame's shutter, as plain numpy data for the store's *_samples calls (UsdImaging's
SampleTransform / SamplePrimvar role): for every prim that moves, its values at the time codes of the interval
[frame + open, frame + close] (shutter.py), with times relative to the frame.

The sample times of a prim are the interval's two end points (so motion between authored samples is
interpolated as USD interpolates it) and every authored time sample strictly inside it of what the prim's value
depends on: its and its ancestors' xform ops (UsdGeom.Xformable.GetTimeSamplesInInterval), its points, its
skeleton's animation and skinning inputs (UsdSkel), a PointInstancer's instance attributes. Values at each time
come from USD itself: UsdGeom.XformCache (one per time, shared by every prim of the frame),
UsdGeom.PointBased.ComputePointsAtTimes (velocities and accelerations applied about the frame's own sample, as
USD documents for motion blur), UsdGeom.PointInstancer's instance transforms with the frame as base time, and
skinning.py's UsdSkel evaluation. Where velocities only are authored, motion is linear over the shutter and the
end points are exact; accelerations or angular velocities bend it: CURVED_MOTION_SAMPLES uniform times. Then,
for transforms and points (skinned or accelerated), more times where the renderer's interpolation between two
samples would leave USD's motion (refined, INTERPOLATION_TOLERANCE): a child of a turning parent moves on an arc
that the renderer's straight interpolation of its translation would cut across (the bias of docs/motion_blur.md).

A prim whose values are equal at every time of the interval is one sample (static); more than
MAX_SAMPLES_PER_PRIM times are resampled uniformly over the interval, with one warning naming the prim.
A sample that cannot be used (NaN, a singular transform, a point count that changes within the shutter) makes
the prim sharp (its frame value) with one warning naming it.
"""
import dataclasses

import numpy as np
from pxr import Gf, Usd, UsdGeom

from .errors import EyeRenderError

# Time steps one prim may carry over a shutter (Embree allows 129; each costs a copy of the prim's BVH data, and a
# film shutter of half a frame rarely holds more than a few authored samples).
MAX_SAMPLES_PER_PRIM = 16
# Uniform time steps for motion that is not piecewise linear between samples (accelerations, angular velocities):
# a quadratic over the shutter sampled at 5 points leaves a chord error of 1/64 of its bend.
CURVED_MOTION_SAMPLES = 5
# Frames: an authored time sample this close to a shutter end is that end (frame + open is rounded: 1.1 + 0.1 is
# not 1.2), so a key on the end is read exactly, not interpolated a rounding error past it.
TIME_EPSILON = 1e-9
# Between two samples the renderer interpolates (points linearly; transforms rigidly, params/motion.h: translation
# and stretch linearly, rotation by slerp). Where USD's own value halfway between two samples is farther from that
# interpolation than this fraction of the prim's whole path over the shutter (an orbit or a head turn carrying a
# child along an arc, a skinned lid turning about the eye, Euler angles turning about two axes), the segment is
# split in two, a round at a time, up to MAX_SAMPLES_PER_PRIM samples. An arc of angle a misses its chord by about
# a^2 / 8 of its radius: 1 % of the path takes a 60 degree orbit to 5 samples (4 arcs of 15 degrees).
INTERPOLATION_TOLERANCE = 0.01
# The scene delegate's updater kinds whose pushes follow the shutter (re-run when it or the prims change).
MOTION_KINDS = ("transform", "skinned transform", "points", "skinned points", "instancer")


@dataclasses.dataclass
class Samples:
    """One prim's values over the shutter: times (float32 (n,), frames relative to the frame, ascending) and one
    value per time (numpy arrays); one sample is a static prim."""
    times: np.ndarray
    values: list

    @property
    def static(self):
        return len(self.times) == 1


class MotionSampler:
    """One frame's shutter interval: its sample times (`times`), an XformCache per time (`cache`), and the
    warnings given once per prim and kind (`warn`)."""

    def __init__(self, frame, shutter, warnings=None, warned=None):
        """frame: the frame's Usd.TimeCode; shutter: a shutter.Shutter; warnings: list the warnings go to;
        warned: set of (prim path, kind) already warned (shared across frames so a warning is given once)."""
        self.frame = frame
        self.shutter = shutter
        self.blurred = shutter.blurred and not frame.IsDefault()
        self.first, self.last = shutter.interval(frame.GetValue()) if self.blurred else (None, None)
        self.warnings = [] if warnings is None else warnings
        self._warned = set() if warned is None else warned
        self._caches = {}

    def interval(self):
        """The shutter's time codes as a closed Gf.Interval, widened by TIME_EPSILON (to meet keys on its ends)."""
        return Gf.Interval(self.first - TIME_EPSILON, self.last + TIME_EPSILON)

    def cache(self, time):
        """The UsdGeom.XformCache at time code `time` (a float), made once per frame."""
        if time not in self._caches:
            self._caches[time] = UsdGeom.XformCache(Usd.TimeCode(time))
        return self._caches[time]

    def warn(self, path, kind, message):
        """Appends `message` once per (prim path, kind) over the sampler's frames."""
        if (str(path), kind) not in self._warned:
            self._warned.add((str(path), kind))
            self.warnings.append(message)

    def times(self, authored, path, uniform=False):
        """The sample times (time codes, ascending) of a prim whose values have time samples at `authored` in the
        interval: its end points and the authored times strictly inside; with `uniform`, CURVED_MOTION_SAMPLES
        evenly spaced times. More than MAX_SAMPLES_PER_PRIM: resampled evenly, with one warning naming `path`."""
        if uniform:
            return list(np.linspace(self.first, self.last, CURVED_MOTION_SAMPLES))
        first, last = self.first, self.last
        for t in authored:  # keys on the ends
            first = float(t) if abs(t - self.first) <= TIME_EPSILON else first
            last = float(t) if abs(t - self.last) <= TIME_EPSILON else last
        inside = sorted({float(t) for t in authored if first < t < last})
        times = [first] + inside + [last]
        if len(times) > MAX_SAMPLES_PER_PRIM:
            self.warn(path, "cap", f"{path}: {len(times)} time samples within the shutter, more than "
                      f"{MAX_SAMPLES_PER_PRIM}: resampled at {MAX_SAMPLES_PER_PRIM} even times")
            times = list(np.linspace(self.first, self.last, MAX_SAMPLES_PER_PRIM))
        return times

    def relative(self, times):
        """Time codes as float32 frames relative to the frame."""
        return np.asarray([t - self.frame.GetValue() for t in times], dtype=np.float32)

    def samples(self, times, values):
        """Samples of `values` at `times` (time codes), one sample when every value equals the first."""
        if all(np.array_equal(values[0], v) for v in values[1:]):
            return Samples(self.relative(times[:1]), values[:1])
        return Samples(self.relative(times), values)


# -- what a prim's values depend on ----------------------------------------------------------------------------

def xform_times(prim, interval):
    """Authored xform-op time samples in `interval` (Gf.Interval) of prim and its ancestors."""
    times = set()
    p = prim
    while p and not p.IsPseudoRoot():
        xformable = UsdGeom.Xformable(p)
        if xformable:
            times.update(xformable.GetTimeSamplesInInterval(interval))
        p = p.GetParent()
    return times


def attribute_times(attrs, interval):
    """Authored time samples in `interval` of attributes (None entries allowed)."""
    times = set()
    for attr in attrs:
        if attr and attr.HasAuthoredValue():
            times.update(attr.GetTimeSamplesInInterval(interval))
    return times


def skinning_times(skinned, interval):
    """Authored time samples in `interval` of what a skinning.SkinnedPrim's points or transform read: its
    skeleton's animation (joint transforms, blend shape weights), its skinning inputs, its and the skeleton's
    xform ops, and its points."""
    times = set(skinned.query.GetTimeSamplesInInterval(interval))
    anim = skinned.skel_query.GetAnimQuery()
    if anim:
        times.update(anim.GetJointTransformTimeSamplesInInterval(interval))
        times.update(anim.GetBlendShapeWeightTimeSamplesInInterval(interval))
    times |= xform_times(skinned.skeleton, interval) | xform_times(skinned.prim, interval)
    if skinned.point_based:
        times |= attribute_times([UsdGeom.PointBased(skinned.prim).GetPointsAttr()], interval)
    return times


def _has_value(attr):
    return bool(attr) and attr.HasAuthoredValue()


# -- where the renderer's interpolation misses USD's motion ------------------------------------------------------

def refined(times, values, value_at, miss, step):
    """(times, values) with the midpoint of a segment inserted where the renderer's interpolation from its sample a
    to b misses USD's value halfway (value_at(time)) by more than INTERPOLATION_TOLERANCE of the prim's path over
    the shutter: miss(a, b, halfway) and step(a, b) are those distances in scene units (the path is the sum of the
    steps). Splits are made a round at a time (an evenly moving prim keeps even times) until none is needed or the
    next round would pass MAX_SAMPLES_PER_PRIM samples."""
    times, values = list(times), list(values)
    unsettled = set(range(len(times) - 1))  # segments not yet found close enough
    while unsettled:
        path = sum(step(values[k], values[k + 1]) for k in range(len(times) - 1))
        halves = {k: value_at(0.5 * (times[k] + times[k + 1])) for k in sorted(unsettled)}
        split = [k for k, half in halves.items()
                 if miss(values[k], values[k + 1], half) > INTERPOLATION_TOLERANCE * path]
        if not split or len(times) + len(split) > MAX_SAMPLES_PER_PRIM:
            break
        for k in reversed(split):
            times.insert(k + 1, 0.5 * (times[k] + times[k + 1]))
            values.insert(k + 1, halves[k])
        unsettled = {k + i + j for i, k in enumerate(split) for j in (0, 1)}  # the two halves of each split
    return times, values


def _largest_distance(a, b):
    """The largest distance between matching rows of (n, 3) arrays, less their precision (a few units in the last
    place of the largest coordinate), so rounding is no miss."""
    if len(a) == 0:
        return 0.0
    precision = 8 * np.finfo(a.dtype).eps * float(max(np.max(np.abs(a)), np.max(np.abs(b))))
    return max(0.0, float(np.max(np.linalg.norm(a - b, axis=1))) - precision)


def points_miss(a, b, halfway):
    """How far points `halfway` ((n, 3)) are from the straight line from a to b the renderer takes (0 for a count
    that changes: the caller refuses it)."""
    return _largest_distance(halfway, 0.5 * (a + b)) if a.shape == b.shape == halfway.shape else 0.0


def points_step(a, b):
    return _largest_distance(a, b) if a.shape == b.shape else 0.0


def _rigid_parts(m):
    """A USD matrix (numpy (4, 4), row vectors) as params/motion.h's T R U: (rotation as a Gf.Quatd, U (3, 3) upper
    triangular, translation (3,)), for column vectors."""
    q, u = np.linalg.qr(m[:3, :3].T)
    signs = np.where(np.diag(u) < 0, -1.0, 1.0)  # Gram-Schmidt's positive diagonal
    q, u = q * signs, signs[:, None] * u
    if np.linalg.det(q) < 0:  # a mirror goes into the last scale, as DecomposeTransform puts it
        q[:, 2], u[2, :] = -q[:, 2], -u[2, :]
    return Gf.Matrix3d(*q.T.flatten()).ExtractRotation().GetQuat(), u, m[3, :3]


def rigid_halfway(m0, m1):
    """The transform the renderer interpolates halfway from m0 to m1 (numpy (4, 4), USD's row vectors): translation
    and U averaged, rotation slerped along the shorter arc (InterpolateParts at u = 0.5)."""
    (q0, u0, t0), (q1, u1, t1) = _rigid_parts(m0), _rigid_parts(m1)
    rotation = np.array(Gf.Matrix3d().SetRotate(Gf.Slerp(0.5, q0, q1))).T  # column vectors
    out = np.eye(4)
    out[:3, :3] = (rotation @ (0.5 * (u0 + u1))).T
    out[3, :3] = 0.5 * (t0 + t1)
    return out


def transform_measures(probes):
    """(miss, step) for refined() over transforms (numpy (4, 4)), measured on the local points `probes` ((k, 3):
    the prim's origin and bound corners): where USD's halfway transform and the renderer's rigid interpolation put
    them, and how far they move."""
    local = np.hstack([probes, np.ones((len(probes), 1))])

    def miss(m0, m1, halfway):
        return _largest_distance((local @ halfway)[:, :3], (local @ rigid_halfway(m0, m1))[:, :3])

    def step(m0, m1):
        return _largest_distance((local @ m0)[:, :3], (local @ m1)[:, :3])
    return miss, step


def probe_points(prim, time):
    """Local points whose motion stands for a prim's: its origin and the corners of its extent (a Boundable's, from
    USD's extent plugins), or of the unit cube where it has none (an Xform, a camera, a light)."""
    extent = None
    if prim.IsA(UsdGeom.Boundable):
        extent = UsdGeom.Boundable.ComputeExtentFromPlugins(UsdGeom.Boundable(prim), time)
    lo, hi = (np.array(extent[0]), np.array(extent[1])) if extent else (-np.ones(3), np.ones(3))
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
        lo, hi = -np.ones(3), np.ones(3)
    corners = [[(lo, hi)[(i >> axis) & 1][axis] for axis in range(3)] for i in range(8)]
    return np.array([[0.0, 0.0, 0.0]] + corners)


# -- samples -------------------------------------------------------------------------------------------------

def transform_samples(sampler, prim, world_at, extra_times=()):
    """Samples of prim's local-to-world transform: world_at(time, xform_cache) gives it (a Gf.Matrix4d, checked by
    the caller) at a time code; extra_times: other authored times it depends on (a rigid skinning anchor's). Where
    the renderer's rigid interpolation would leave USD's path (an arc about a parent's pivot), more times
    (refined)."""
    times = sampler.times(xform_times(prim, sampler.interval()) | set(extra_times), prim.GetPath())

    def value_at(t):
        return np.array(world_at(t, sampler.cache(t)), dtype=np.float64).reshape(4, 4)
    values = [value_at(t) for t in times]
    if not sampler.samples(times, values).static:
        times, values = refined(times, values, value_at, *transform_measures(probe_points(prim, sampler.frame)))
    return sampler.samples(times, values)


def points_samples(sampler, prim, count, to_array):
    """Samples of a UsdGeom.PointBased prim's points (velocities and accelerations applied where authored, about
    the frame's sample); count: the points its topology has; to_array(values, what) checks one time's points
    into float32 (n, 3) (raising EyeRenderError). A count that changes within the shutter raises
    EyeRenderError."""
    point_based = UsdGeom.PointBased(prim)
    path = prim.GetPath()
    velocities = _has_value(point_based.GetVelocitiesAttr())
    curved = velocities and _has_value(point_based.GetAccelerationsAttr())
    authored = set() if velocities else attribute_times([point_based.GetPointsAttr()], sampler.interval())
    times = sampler.times(authored, path, uniform=curved)
    arrays = point_based.ComputePointsAtTimes([Usd.TimeCode(t) for t in times], sampler.frame)
    if arrays is None or len(arrays) != len(times):
        raise EyeRenderError(f"{path}: points cannot be computed over the shutter")
    values = [to_array(points, f"{path}: points at time {t:g}") for t, points in zip(times, arrays)]
    if curved:  # velocities alone move points on straight lines, authored keys are lerped by USD as by us

        def value_at(t):
            return to_array(point_based.ComputePointsAtTime(Usd.TimeCode(t), sampler.frame), f"{path}: points at "
                            f"time {t:g}")
        times, values = refined(times, values, value_at, points_miss, points_step)
    for t, a in zip(times, values):
        if len(a) != count:
            raise EyeRenderError(f"{path}: {len(a)} points at time {t:g} within the shutter, the mesh has {count}")
    return sampler.samples(times, values)


def skinned_points_samples(sampler, skinned, deform):
    """Samples of a skinned prim's points: deform(time, xform_cache) gives them (float32 (n, 3)) at a time code."""
    times = sampler.times(skinning_times(skinned, sampler.interval()), skinned.prim.GetPath())
    values = [deform(t, sampler.cache(t)) for t in times]
    if not sampler.samples(times, values).static and len({len(v) for v in values}) == 1:
        times, values = refined(times, values, lambda t: deform(t, sampler.cache(t)), points_miss, points_step)
    count = len(values[0])
    for t, v in zip(times, values):
        if len(v) != count:
            raise EyeRenderError(f"{skinned.prim.GetPath()}: {len(v)} skinned points at time {t:g}, {count} at the "
                                 f"shutter's open")
    return sampler.samples(times, values)


def instancer_times(instancer_prims, interval):
    """(authored times in `interval` of PointInstancers' instance attributes and xform ops, whether any authors
    accelerations or angular velocities: motion that needs CURVED_MOTION_SAMPLES)."""
    times, curved = set(), False
    for prim in instancer_prims:
        pi = UsdGeom.PointInstancer(prim)
        velocities = _has_value(pi.GetVelocitiesAttr())
        curved |= _has_value(pi.GetAccelerationsAttr()) or _has_value(pi.GetAngularVelocitiesAttr())
        attrs = [pi.GetProtoIndicesAttr(), pi.GetScalesAttr(), pi.GetIdsAttr(), pi.GetInvisibleIdsAttr()]
        if not velocities:  # with velocities, positions and orientations come from the frame's sample
            attrs += [pi.GetPositionsAttr(), pi.GetOrientationsAttr()]
        times |= attribute_times(attrs, interval) | xform_times(prim, interval)
    return times, curved


def instance_samples(sampler, path, times, groups_at):
    """{instancer id: Samples of its (m, 4, 4) instance transforms} of a PointInstancer at `path`:
    groups_at(time, xform_cache) gives {instancer id: (m, 4, 4) float64} at a time code. An instance count that
    changes within the shutter raises EyeRenderError."""
    per_time = [groups_at(t, sampler.cache(t)) for t in times]
    result = {}
    for instancer_id, first in per_time[0].items():
        values = [at.get(instancer_id) for at in per_time]
        if any(v is None or v.shape != first.shape for v in values):
            raise EyeRenderError(f"{path}: the number of instances of {instancer_id} changes within the shutter")
        result[instancer_id] = sampler.samples(times, values)
    return result


__all__ = ["MAX_SAMPLES_PER_PRIM", "CURVED_MOTION_SAMPLES", "TIME_EPSILON", "INTERPOLATION_TOLERANCE", "MOTION_KINDS",
           "Samples", "MotionSampler", "refined", "points_miss", "points_step", "rigid_halfway", "transform_measures",
           "probe_points", "xform_times", "attribute_times", "skinning_times", "transform_samples", "points_samples",
           "skinned_points_samples", "instancer_times", "instance_samples"]
