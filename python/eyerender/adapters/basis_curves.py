"""UsdGeom.BasisCurves as tubes or ribbons (HdBasisCurves; the geometry is read by eyerender.curves)."""
from pxr import UsdGeom

from .. import curves
from ..usd_values import to_matrix as _matrix
from ..usd_values import varies as _varies
from .base import PrimAdapter


class BasisCurvesAdapter(PrimAdapter):
    add = staticmethod(curves.add_basis_curves)  # store, prim, id, world, material id, time, warn -> animated attrs

    @staticmethod
    def handles(prim):
        return prim.IsA(UsdGeom.BasisCurves)

    def populate(self, prim):
        self._add_curves_or_points(prim)
        return False

    def populate_instanced(self, prim, prim_id, transform, instancer_id, binding):
        self._add_curves_or_points(prim, prim_id, transform, binding)  # copied per instance: never under an instancer
        return True

    def _add_curves_or_points(self, prim, prim_id=None, world=None, binding=None):
        """Bad data raises EyeRenderError (the prim is skipped). prim_id, world, binding: an instance's copy of a
        prototype's prim (see UsdSceneDelegate.add_instanced_prim)."""
        d = self.delegate
        own = prim_id is None
        prim_id = prim.GetPath().pathString if own else prim_id
        material_id, _ = d.adapters.material.bind(binding or prim)
        d.rprims[prim_id] = prim.GetPath()
        warn = lambda message: d.warn_once([message])  # noqa: E731
        world = d.world_of(prim) if world is None else world
        animated = self.add(d.store, prim, prim_id, _matrix(world), material_id, d.time, warn)
        d.own_top_level(prim, prim_id)
        if own:
            d.track_transform(prim)
        d.track_visibility(prim, prim_id)
        if _varies(animated):
            d.add_updater("points", lambda t: curves.update(d.store, prim, prim_id, t, warn))
