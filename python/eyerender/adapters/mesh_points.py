"""A mesh's points for the mesh adapter: authored, skinned (UsdSkel, skinning.py) or at eye:restTime, each sent as
samples over the shutter where it spans time and they move within it (motion.py)."""
import numpy as np
from pxr import Usd, UsdGeom, UsdSkel

from .. import eyes, motion
from ..errors import EyeRenderError
from ..skinning import SkinningError
from ..usd_values import to_float_array as _array


def _array_of_points(values, what):
    return _array(values, 3, what)


def _has_skel_binding(prim):
    """Whether prim has joint influences or blend shapes authored (UsdSkel.BindingAPI)."""
    if not prim.HasAPI(UsdSkel.BindingAPI):
        return False
    api = UsdSkel.BindingAPI(prim)
    return api.GetJointIndicesPrimvar().HasAuthoredValue() or bool(api.GetBlendShapeTargetsRel().GetTargets())


class MeshPoints:
    """Sends meshes' points to the delegate's store; `counts` keeps each mesh's point count (its topology's)."""

    def __init__(self, delegate):
        self.delegate = delegate
        self.counts = {}  # mesh id -> number of points its topology was built for

    def skinned_prim(self, prim, prim_id):
        """The SkinnedPrim deforming this mesh's points, or None (also for instanced copies: not skinned, one
        warning; a native instance's prototype prims, which no SkelRoot populate reaches, warn on their joint
        influences)."""
        d = self.delegate
        skinned = d.skinning.get(prim)
        if prim_id != prim.GetPath().pathString:
            if (skinned is not None and skinned.deforms_points) or (prim.IsInPrototype() and _has_skel_binding(prim)):
                warning = f"{prim.GetPath()}: instanced copies of a skinned mesh render unskinned"
                if warning not in d.warnings:
                    d.warnings.append(warning)
            return None
        if skinned is None or not skinned.deforms_points:
            return None
        return skinned

    def skinned(self, skinned, time, fallback, normals_id=None):
        """A skinned mesh's points at `time` (and, with normals_id, its skinned normals sent to that prim); after
        bad skel data (one warning) its authored points, unskinned."""
        d = self.delegate
        if d.skinning.get(skinned.prim) is skinned:
            try:
                cache = d.xform_cache if time == d.time else UsdGeom.XformCache(time)
                points, normals = skinned.deform(time, cache, with_normals=normals_id is not None)
                if normals is not None:
                    d.store.set_primvar(normals_id, "normals", str(skinned.normals_interpolation()), normals)
                return points
            except SkinningError as e:
                d.skinning.drop(skinned, e)
        if fallback is not None:
            return fallback
        return _array(skinned.rest_points(time), 3, f"{skinned.prim.GetPath()}: points")

    def push(self, prim, prim_id):
        """Sends a mesh's points at the current time: their samples over the shutter (velocities and accelerations
        applied) when it spans time and they move within it, else the authored points (a sample that cannot be
        used: one warning, sharp)."""
        d = self.delegate
        path = prim.GetPath()
        sampler = d.motion_sampler
        if sampler.blurred:
            try:
                samples = motion.points_samples(sampler, prim, self.counts.get(prim_id), _array_of_points)
                if not samples.static:
                    d.store.set_points_samples(prim_id, samples.times, samples.values)
                    return
            except EyeRenderError as e:
                sampler.warn(path, "points", f"{e}: rendered without motion blur")
        d.store.set_points(prim_id, _array(UsdGeom.PointBased(prim).GetPointsAttr().Get(d.time), 3,
                                           f"{path}: points"))

    def push_skinned(self, skinned, prim_id, normals_id):
        """A skinned mesh's points (and skinned normals at the frame) at the current time, as samples over the
        shutter when it spans time and they move within it."""
        d = self.delegate
        points = self.skinned(skinned, d.time, None, normals_id=normals_id)
        sampler = d.motion_sampler
        if sampler.blurred and d.skinning.get(skinned.prim) is skinned:
            try:
                samples = motion.skinned_points_samples(sampler, skinned, lambda t, cache: _array_of_points(
                    skinned.points(Usd.TimeCode(t), cache), f"{skinned.prim.GetPath()}: skinned points at time {t:g}"))
                if not samples.static:
                    d.store.set_points_samples(prim_id, samples.times, samples.values)
                    return
            except (EyeRenderError, SkinningError) as e:
                sampler.warn(skinned.prim.GetPath(), "points", f"{e}: rendered without motion blur")
        d.store.set_points(prim_id, points)

    def push_rest_time_points(self, prim, prim_id, mesh, count, skinned=None):
        """An eye mesh with eye:restTime and no rest/Pref primvar: its points (skinned, for a skinned mesh) at that
        time code are its rest pose (sent as the vertex primvar "rest"). A skinned eye mesh without eye:restTime
        rests in its bind pose (its authored points). Nothing for other meshes."""
        d = self.delegate
        if not eyes.is_eye(prim):
            return
        attr = prim.GetAttribute("eye:restTime")
        rest_time = attr.Get() if attr and attr.HasAuthoredValue() else None
        if rest_time is None:
            if skinned is not None:
                bind = skinned.rest_points(d.time)
                d.store.set_primvar(prim_id, "rest", "vertex", _array(bind, 3, f"{prim.GetPath()}: bind points"))
            return
        if not np.isfinite(rest_time):
            raise EyeRenderError(f"{prim.GetPath()}: eye:restTime = {rest_time} is outside its valid range: a finite "
                                 "time code")
        if skinned is not None:
            rest = self.skinned(skinned, Usd.TimeCode(rest_time), None)
        else:
            rest = mesh.GetPointsAttr().Get(Usd.TimeCode(rest_time))
        if rest is None or len(rest) != count:
            raise EyeRenderError(f"{prim.GetPath()}: eye:restTime = {rest_time:g} has "
                                 f"{0 if rest is None else len(rest)} points, the mesh has {count}")
        d.store.set_primvar(prim_id, "rest", "vertex", _array(rest, 3, f"{prim.GetPath()}: points at eye:restTime"))
