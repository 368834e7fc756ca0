"""Eyes (the EyeAPI): an Xformable with it is an analytic eye (HdEye's analytic rprim); a mesh with it is an eye
mesh, added by the mesh adapter with the EyeParams read here, its iris projection (eye:irisProjection's target, a
frame relative to the eye) resolved."""
import numpy as np
from pxr import UsdGeom

from .. import eyes
from ..errors import EyeRenderError
from ..stage_notices import EYE
from ..usd_values import to_matrix as _matrix
from .base import PrimAdapter


class EyeAdapter(PrimAdapter):

    @staticmethod
    def handles(prim):
        return eyes.is_eye(prim) and prim.IsA(UsdGeom.Xformable)

    def populate(self, prim):
        self._add_analytic_eye(prim)
        return False

    def populate_instanced(self, prim, prim_id, transform, instancer_id, binding):
        self._add_analytic_eye(prim, prim_id, transform)
        return True

    def _add_analytic_eye(self, prim, prim_id=None, world=None):
        d = self.delegate
        own = prim_id is None
        prim_id = prim.GetPath().pathString if own else prim_id
        d.rprims[prim_id] = prim.GetPath()
        world = d.world_of(prim) if world is None else world
        d.store.add_analytic_eye(prim_id, eyes.read_eye_params(prim, d.time, d.cornea_model, d.warnings),
                                 _matrix(world))
        d.eyes.append(prim_id)
        d.own_top_level(prim, prim_id)
        if own:
            d.track_transform(prim)
        self.track_eye(prim, prim_id)

    def track_eye(self, prim, prim_id, mesh=False):
        """Registers the eye's params updater where they vary (an eye mesh's iris projection varies with its
        target's or its own transform)."""
        d = self.delegate
        if not mesh:
            if eyes.eye_attributes_vary(prim):
                d.add_updater("eye", lambda t: d.store.set_eye_params(
                    prim_id, eyes.read_eye_params(prim, t, d.cornea_model)))
            return
        # Eye meshes also carry the iris projection: it varies when its target's or the eye's transform does.
        target = self.iris_projection_target(prim)
        if eyes.eye_attributes_vary(prim) or (target is not None and (d.transform_varies(target) or
                                                                      d.transform_varies(prim))):
            d.add_updater("eye", lambda t: d.store.set_eye_params(prim_id, self.mesh_params(prim, t)))

    def mesh_params(self, prim, time, warnings=None):
        """An eye mesh's EyeParams at `time`, with its iris projection (eye:irisProjection) resolved."""
        eye = eyes.read_eye_params(prim, time, self.delegate.cornea_model, warnings)
        projection = self.iris_projection(prim, time)
        if projection is not None:
            eye.iris_projection = projection
        return eye

    def iris_projection_target(self, prim):
        """The Xformable prim eye:irisProjection names, or None when the relationship has no target."""
        rel = prim.GetRelationship("eye:irisProjection")
        targets = rel.GetForwardedTargets() if rel else []
        if not targets:
            return None
        if len(targets) > 1:
            raise EyeRenderError(f"{prim.GetPath()}: eye:irisProjection has {len(targets)} targets (needs one)")
        target = self.delegate.stage.GetPrimAtPath(targets[0])
        if not target or not target.IsValid():
            raise EyeRenderError(f"{prim.GetPath()}: eye:irisProjection target {targets[0]} does not exist")
        if not target.IsA(UsdGeom.Xformable):
            raise EyeRenderError(f"{prim.GetPath()}: eye:irisProjection target {targets[0]} is a "
                                 f"{target.GetTypeName() or 'typeless prim'}, not an Xform or Camera")
        return target

    def iris_projection(self, prim, time):
        """eye:irisProjection's target frame relative to the eye prim's local space at `time` (USD's row-vector
        layout: target-to-world x inverse eye-to-world), as the 4x4 float64 array EyeParams.iris_projection takes;
        None without a target. Its [-1, 1]^2 xy square is the iris texture square (docs/deformed_eyes.md)."""
        target = self.iris_projection_target(prim)
        if target is None:
            return None
        cache = UsdGeom.XformCache(time)
        relative = cache.GetLocalToWorldTransform(target) * cache.GetLocalToWorldTransform(prim).GetInverse()
        m = _matrix(relative)
        if not np.isfinite(m).all() or abs(relative.GetDeterminant3()) < 1e-300:
            raise EyeRenderError(f"{prim.GetPath()}: eye:irisProjection target {target.GetPath()} has a singular "
                                 f"transform relative to the eye")
        return m

    def push_params(self, prim, prim_id):
        """Re-sends an eye's (analytic or mesh) params at the current time."""
        d = self.delegate
        d.store.set_eye_params(prim_id, self.mesh_params(prim, d.time) if prim.IsA(UsdGeom.Mesh)
                               else eyes.read_eye_params(prim, d.time, d.cornea_model))

    def refresh_iris_projections(self):
        """Eye meshes' iris projections are transforms relative to the eye: any moved prim may be a target."""
        d = self.delegate
        for eye_id in d.eyes:
            prim = d.stage.GetPrimAtPath(eye_id)
            if prim and prim.IsA(UsdGeom.Mesh) and self.iris_projection_target(prim) is not None:
                d.store.set_eye_params(eye_id, self.mesh_params(prim, d.time))

    def process_property_change(self, prim, prim_id, kind):
        if kind == EYE and eyes.is_eye(prim):
            self.push_params(prim, prim_id)
            return True
        return super().process_property_change(prim, prim_id, kind)
