"""UsdGeom.Mesh as a delegate mesh (HdMesh), or an eye mesh where it has the EyeAPI: topology, subdivision scheme,
tags and holes (mesh_topology.py), materialBind GeomSubsets, orientation, primvars (st, displayColor, normals, rest
or Pref; eye meshes: else their points at eye:restTime), UsdSkel skinning (skinning.py) and points that move within
the shutter (motion.py)."""
import numpy as np
from pxr import UsdGeom

from .. import eyes, mesh_topology
from ..errors import EyeRenderError
from ..stage_notices import EYE, POINTS
from ..usd_values import scalar_as_array
from ..usd_values import to_float_array as _array
from ..usd_values import to_matrix as _matrix
from ..usd_values import varies as _varies
from ..validation import check_transform
from .base import PrimAdapter
from .mesh_points import MeshPoints

PRIMVARS = ("displayColor", "normals", "rest")


class MeshAdapter(PrimAdapter):

    def __init__(self, delegate):
        super().__init__(delegate)
        self.points = MeshPoints(delegate)  # points, skinned points and rest points, over the shutter
        self.element_counts = {}  # rprim id -> {interpolation: elements a primvar of it needs} (push_primvar)

    @staticmethod
    def handles(prim):
        return prim.IsA(UsdGeom.Mesh)

    def populate(self, prim):
        d = self.delegate
        self._add_mesh(prim, prim.GetPath().pathString, d.world_of(prim))
        d.track_transform(prim)
        return False

    def populate_instanced(self, prim, prim_id, transform, instancer_id, binding):
        self._add_mesh(prim, prim_id, transform, instancer_id, binding)
        return True

    def forget(self, prim_id):
        self.points.counts.pop(prim_id, None)
        self.element_counts.pop(prim_id, None)

    def process_property_change(self, prim, prim_id, kind):
        if kind == POINTS and not self.delegate.skinning.get(prim):
            points = UsdGeom.Mesh(prim).GetPointsAttr().Get(self.delegate.time)
            if points is None or len(points) != self.points.counts.get(prim_id):
                return False  # a new point count needs new topology
            self.points.push(prim, prim_id)
            return True
        if kind == EYE and eyes.is_eye(prim):
            self.delegate.adapters.eye.push_params(prim, prim_id)
            return True
        return super().process_property_change(prim, prim_id, kind)

    @staticmethod
    def _topology(prim, mesh, time):
        path = prim.GetPath()
        counts = np.asarray(mesh.GetFaceVertexCountsAttr().Get(time) or [], dtype=np.int32)
        indices = np.asarray(mesh.GetFaceVertexIndicesAttr().Get(time) or [], dtype=np.int32)
        points = mesh.GetPointsAttr().Get(time)
        if points is None or len(counts) == 0:
            raise EyeRenderError(f"{path}: mesh has no points or no faces")
        points = _array(points, 3, f"{path}: points")
        if len(points) == 0:
            raise EyeRenderError(f"{path}: mesh has no points")
        if counts.min() < 3:
            raise EyeRenderError(f"{path}: faceVertexCounts holds a face with fewer than 3 vertices")
        if int(counts.sum()) != len(indices):
            raise EyeRenderError(f"{path}: faceVertexIndices has {len(indices)} entries, faceVertexCounts sums "
                                 f"to {int(counts.sum())}")
        if indices.min() < 0 or indices.max() >= len(points):
            raise EyeRenderError(f"{path}: faceVertexIndices refers to points outside [0, {len(points)})")
        return counts, indices, points

    def _add_mesh(self, prim, prim_id, world, instancer_id="", binding=None):
        d = self.delegate
        d.rprims[prim_id] = prim.GetPath()
        mesh = UsdGeom.Mesh(prim)
        check_transform(prim_id, world)  # an instance's transform composes the instancer's
        counts, indices, points = self._topology(prim, mesh, d.time)
        skinned = self.points.skinned_prim(prim, prim_id)
        if skinned is not None:
            points = self.points.skinned(skinned, d.time, points)
            if d.skinning.get(prim) is None and skinned.moves_frame:  # dropped: its bind frame, unskinned
                world = check_transform(prim_id, d.xform_cache.GetLocalToWorldTransform(prim))
        subdivision = mesh_topology.Subdivision(mesh, counts, indices, len(points), d.time)
        d.warn_once(subdivision.warnings)
        level = d.refine_level if subdivision.refines else 0
        self.points.counts[prim_id] = len(points)
        self.count_elements(prim_id, counts, indices, points)
        left = mesh.GetOrientationAttr().Get() == UsdGeom.Tokens.leftHanded
        material_id, st_name = d.adapters.material.bind(binding or prim)
        if eyes.is_eye(prim):
            eye = d.adapters.eye.mesh_params(prim, d.time, d.warnings)
            d.store.add_eye_mesh(prim_id, counts, indices, points, eye, _matrix(world), material_id, level, left)
            d.eyes.append(prim_id)
            d.own_top_level(prim, prim_id)
            d.adapters.eye.track_eye(prim, prim_id, mesh=True)
        else:
            d.store.add_mesh(prim_id, counts, indices, points, _matrix(world), material_id, level, left,
                             instancer_id=instancer_id)
            d.own_top_level(prim, prim_id)
        self._push_mesh_tags(prim, prim_id, subdivision, len(counts))
        names, skin_normals = self._push_primvars(prim, prim_id, st_name, skinned, level, points)
        d.track_visibility(prim, prim_id)
        self._track_variability(prim, prim_id, skinned, skin_normals, names, level, left)

    def _push_primvars(self, prim, prim_id, st_name, skinned, level, points):
        """Sends a mesh's primvars at the current time; returns ({store name: primvar name or None}, the id its
        skinned normals go to or None)."""
        d = self.delegate
        names = {"st": st_name, **{n: n for n in PRIMVARS}}
        names["rest"] = self._rest_source(prim)
        # Authored normals shade polygon meshes only (refined ones use limit normals). A skinned polygon mesh's
        # normals are skinned with its points; ones that cannot be would be stale: smooth normals instead.
        skin_normals = None
        authored_normals = any(a.HasAuthoredValue() for a in self.primvar_attrs(prim, "normals"))
        if skinned is not None and level == 0 and authored_normals:
            names["normals"] = None
            if skinned.skinnable_normals():
                skin_normals = prim_id
            else:
                d.warnings.append(f"{prim.GetPath()}: {skinned.normals_interpolation()} normals cannot follow "
                                  f"per-vertex skinning (rendered with smooth normals)")
        for name, source in names.items():
            self.push_primvar(prim, prim_id, name, source, d.time)
        if skin_normals:
            self.points.skinned(skinned, d.time, points, normals_id=skin_normals)
        if names["rest"] is None:
            self.points.push_rest_time_points(prim, prim_id, UsdGeom.Mesh(prim), len(points), skinned)
        return names, skin_normals

    def _track_variability(self, prim, prim_id, skinned, skin_normals, names, level, left):
        """Registers the updaters of what varies in a mesh: topology, else skinned or authored points; primvars."""
        d = self.delegate
        mesh = UsdGeom.Mesh(prim)
        points_attr = mesh.GetPointsAttr()
        if _varies([mesh.GetFaceVertexCountsAttr(), mesh.GetFaceVertexIndicesAttr()]):
            def update_topology(t):
                c, i, p = self._topology(prim, mesh, t)
                d.store.set_topology(prim_id, c, i, p, level, left)
                self._push_mesh_tags(prim, prim_id, mesh_topology.Subdivision(mesh, c, i, len(p), t), len(c))
                self.points.counts[prim_id] = len(p)
                self.count_elements(prim_id, c, i, p)
            d.add_updater("topology", update_topology)
        elif skinned is not None:
            if skinned.might_vary(d.xforms_vary):
                d.add_updater("skinned points", lambda t: self.points.push_skinned(skinned, prim_id, skin_normals))
        elif _varies([points_attr, mesh.GetVelocitiesAttr(), mesh.GetAccelerationsAttr()]) or \
                mesh.GetVelocitiesAttr().HasAuthoredValue():
            d.add_updater("points", lambda t: self.points.push(prim, prim_id))
        for name, source in names.items():
            if source is not None and _varies(self.primvar_attrs(prim, source)):
                d.add_updater("primvar", lambda t, n=name, s=source: self.push_primvar(prim, prim_id, n, s, t))

    def _push_mesh_tags(self, prim, prim_id, subdivision, face_count):
        """A mesh's subdivision tags and holes, and its materialBind GeomSubsets (per-face materials)."""
        d = self.delegate
        if subdivision.authored():
            subdivision.push(d.store, prim_id)
        subsets, warnings = mesh_topology.material_subsets(prim, face_count, d.time,
                                                           lambda subset: d.adapters.material.bind(subset)[0])
        d.warn_once(warnings)
        if subsets:
            d.store.set_geom_subsets(prim_id, subsets)

    def count_elements(self, prim_id, counts, indices, points):
        """Records how many elements each primvar interpolation of rprim `prim_id` needs (push_primvar checks)."""
        self.element_counts[prim_id] = {"constant": 1, "uniform": len(counts), "vertex": len(points),
                                        "varying": len(points), "faceVarying": len(indices)}

    def push_primvar(self, prim, prim_id, name, source, time):
        """Sends primvar `source` of prim to the store under `name`, indices expanded; skips unauthored ones, and with
        one warning one whose element count does not fit the mesh (the mesh renders without it, as in Storm)."""
        d = self.delegate
        if source is None:
            return
        primvar = UsdGeom.PrimvarsAPI(prim).FindPrimvarWithInheritance(source)  # constant ones are inherited
        if primvar and primvar.HasValue():
            values, interpolation = primvar.ComputeFlattened(time), primvar.GetInterpolation()
        elif name == "normals" and UsdGeom.Mesh(prim).GetNormalsAttr().HasValue():
            mesh = UsdGeom.Mesh(prim)
            values, interpolation = mesh.GetNormalsAttr().Get(time), mesh.GetNormalsInterpolation()
        else:
            return
        if values is None or (hasattr(values, "__len__") and len(values) == 0):
            return
        values = scalar_as_array(values)
        try:
            values = _array(values, {"st": 2}.get(name, 3), f"{prim.GetPath()}: primvars:{source}")
        except EyeRenderError as e:  # the prim renders without it (normals: smooth shading)
            d.warnings.append(f"{e}: ignored")
            return
        needed = self.element_counts.get(prim_id, {}).get(str(interpolation))
        if needed is not None and len(values) != needed:
            d.warn_once([f"{prim.GetPath()}: primvars:{source}: {interpolation} needs {needed} elements, got "
                         f"{len(values)}: ignored"])
            return
        d.store.set_primvar(prim_id, name, str(interpolation), values)

    @staticmethod
    def primvar_attrs(prim, name):
        """The attributes primvar `name` of prim is read from (normals: the schema attribute too)."""
        primvar = UsdGeom.PrimvarsAPI(prim).GetPrimvar(name)
        attrs = [primvar.GetAttr(), primvar.GetIndicesAttr()] if primvar else []
        if name == "normals":
            attrs.append(UsdGeom.Mesh(prim).GetNormalsAttr())
        return attrs

    @staticmethod
    def _rest_source(prim):
        """The primvar holding a mesh's rest positions: primvars:rest, else primvars:Pref (RenderMan's name); None
        for neither."""
        api = UsdGeom.PrimvarsAPI(prim)
        for name in ("rest", "Pref"):
            primvar = api.GetPrimvar(name)
            if primvar and primvar.HasValue():
                return name
        return None
