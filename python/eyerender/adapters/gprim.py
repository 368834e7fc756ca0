"""Implicit gprims (Sphere, Cube, Plane, Cylinder, Cone, Capsule and the _1 forms) as tessellated delegate meshes
(gprims.py tessellates); displayColor is their one primvar. Other Gprim types are skipped with one warning."""
from pxr import UsdGeom

from ..gprims import tessellate_gprim
from ..usd_values import to_matrix as _matrix
from .mesh import MeshAdapter


class GprimAdapter(MeshAdapter):
    """A mesh adapter for the tessellation of an implicit surface (its primvars are checked as a mesh's)."""

    @staticmethod
    def handles(prim):
        return prim.IsA(UsdGeom.Gprim)

    def populate(self, prim):
        self._add_gprim(prim)
        return False

    def populate_instanced(self, prim, prim_id, transform, instancer_id, binding):
        return self._add_gprim(prim, prim_id, transform, instancer_id, binding)

    def _add_gprim(self, prim, prim_id=None, world=None, instancer_id="", binding=None):
        d = self.delegate
        tessellated = tessellate_gprim(prim, d.time)
        if tessellated is None:
            d.warnings.append(f"{prim.GetPath()}: {prim.GetTypeName()} is not rendered (not supported)")
            return False
        counts, indices, points = tessellated
        material_id, _ = d.adapters.material.bind(binding or prim)
        own = prim_id is None
        prim_id = prim.GetPath().pathString if own else prim_id
        d.rprims[prim_id] = prim.GetPath()
        world = d.world_of(prim) if world is None else world
        d.store.add_mesh(prim_id, counts, indices, points, _matrix(world), material_id, 0, False,
                         instancer_id=instancer_id)
        d.own_top_level(prim, prim_id)
        self.count_elements(prim_id, counts, indices, points)
        self.push_primvar(prim, prim_id, "displayColor", "displayColor", d.time)
        if own:
            d.track_transform(prim)
        d.track_visibility(prim, prim_id)
        return True
