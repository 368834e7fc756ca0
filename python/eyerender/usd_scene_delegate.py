"""The USD scene delegate (UsdImagingDelegate's role): populates the hdeye render index from a Usd.Stage and keeps
it current as time moves.

Every supported prim becomes one delegate prim with the same path (instance proxies and point-instanced copies
get their own paths: instancing is flattened into separate prims that share nothing yet). `populate` reads the
stage once at the current time; `set_time` re-reads only what may vary in time (attributes with time samples,
transforms under animated xforms) and pushes it through the scene store's Set* calls, which mark exactly the
matching dirty bits. What each `set_time` pushed is counted in `last_update`.

Supported: Xform hierarchies, Mesh (points, topology, subdivisionScheme, orientation, normals, primvars st /
displayColor / rest (or Pref; eye meshes: else their points at eye:restTime)), Sphere and Cube gprims (tessellated),
Camera, UsdLux sphere / distant / rect / disk / dome
lights, UsdShade UsdPreviewSurface materials, the EyeAPI on meshes and xforms (eye meshes: eye:irisProjection's
target resolved relative to the eye), purposes, visibility, instanceable
references and PointInstancers. Anything else is skipped and listed once in `warnings`.
"""
import collections

import numpy as np
from pxr import Usd, UsdGeom, UsdShade

from . import cameras, eyes, lights, materials
from .errors import EyeRenderError
from .gprims import tessellate_gprim
from .validation import check_transform, reading

SUBDIVISION_SCHEMES = ("catmullClark", "none", "loop", "bilinear")
PRIMVARS = ("displayColor", "normals", "rest")


def _matrix(m):
    """A Gf.Matrix4d as the 4x4 float64 array the delegate takes (same layout: no transpose)."""
    return np.array(m, dtype=np.float64).reshape(4, 4)


def _array(values, components, what):
    """A Vt array (or sequence) as a C-contiguous float32 (n, components) view, copied only if its layout needs it."""
    try:
        a = np.asarray(values, dtype=np.float32)
    except (TypeError, ValueError):
        raise EyeRenderError(f"{what} is a {type(values).__name__}, not an array of numbers") from None
    if a.ndim != 2 or a.shape[1] != components:  # a flat float[] is not a point3f[], whatever its length
        raise EyeRenderError(f"{what} does not hold {components}-component values")
    if not np.isfinite(a).all():
        raise EyeRenderError(f"{what} holds NaN or infinite values")
    return np.ascontiguousarray(a)


def _varies(attrs):
    return any(a and a.ValueMightBeTimeVarying() for a in attrs)


class UsdSceneDelegate:
    """Populates a SceneStore from a Usd.Stage (see the module doc)."""

    def __init__(self, stage, store, *, time=Usd.TimeCode.Default(), purposes=("default",), refine_level=2,
                 cornea_model=None):
        """purposes: the UsdGeom purposes to render ("default" is always included); refine_level: Catmull-Clark
        refinement level for subdivision meshes (usdrecord's --complexity); cornea_model: overrides every eye's
        eye:corneaModel ("ellipsoidCone" or "paraboloid") for A/B renders."""
        self.stage, self.store = stage, store
        self.time = Usd.TimeCode(time)
        self.purposes = tuple(dict.fromkeys(("default",) + tuple(purposes)))
        self.refine_level = refine_level
        self.cornea_model = cornea_model
        self.cameras = []        # camera prim paths, in traversal order
        self.eyes = []           # eye prim paths (meshes and analytic)
        self.lights = []         # light prim paths
        self.warnings = []       # one line each: what was skipped or ignored
        self.last_update = collections.Counter()
        self._xforms = UsdGeom.XformCache(self.time)
        self._updaters = []      # (kind, callable(time)) for what varies in time
        self._materials = {}     # material path -> st primvar name
        self._populated = False

    # -- public ------------------------------------------------------------------------------------------------

    def populate(self):
        if self._populated:
            raise RuntimeError("populate() was already called")
        self._populated = True
        it = iter(Usd.PrimRange(self.stage.GetPseudoRoot(), Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)))
        for prim in it:
            if prim.IsPseudoRoot():
                continue
            imageable = UsdGeom.Imageable(prim)
            if imageable and imageable.ComputePurpose() not in self.purposes:
                it.PruneChildren()
                continue
            try:
                with reading(prim.GetPath()):
                    handled = self._add_prim(prim)
            except EyeRenderError as e:  # this prim cannot be rendered: the rest of the stage still can
                self._forget(prim.GetPath().pathString)
                self.warnings.append(f"{e} (skipped)")
                handled = True
            if handled:
                it.PruneChildren()

    def _forget(self, prim_id):
        """Removes what a prim that failed part-way through being added left in the store and the lists."""
        self.store.remove_prim(prim_id)
        for known in (self.cameras, self.eyes, self.lights):
            if prim_id in known:
                known.remove(prim_id)

    def set_time(self, time):
        """Moves to `time`, pushing only what varies; returns (and keeps in last_update) the counts by kind."""
        self.time = Usd.TimeCode(time)
        self._xforms.SetTime(self.time)
        self.last_update = collections.Counter()
        with reading(f"time {self.time.GetValue():g}"):
            for kind, update in self._updaters:
                update(self.time)
                self.last_update[kind] += 1
        return self.last_update

    # -- dispatch ----------------------------------------------------------------------------------------------

    def _add_prim(self, prim):
        """Adds a prim; returns True when its children are handled too (or must not be rendered)."""
        if prim.IsA(UsdGeom.PointInstancer):
            self._add_point_instancer(prim)
            return True
        if prim.IsA(UsdGeom.Mesh):
            self._add_mesh(prim, prim.GetPath().pathString, self._world_of(prim))
            self._track_transform(prim)
            return False
        if prim.IsA(UsdGeom.Camera):
            self._add_camera(prim)
        elif lights.light_type(prim):
            self._add_light(prim)
        elif prim.IsA(UsdGeom.Gprim):
            self._add_gprim(prim)
        elif eyes.is_eye(prim) and prim.IsA(UsdGeom.Xformable):
            self._add_analytic_eye(prim)
        return False

    def _world_of(self, prim):
        return check_transform(prim.GetPath(), self._xforms.GetLocalToWorldTransform(prim))

    @staticmethod
    def _transform_varies(prim):
        """Whether prim's local-to-world transform may change: its own or an ancestor's xform ops are animated."""
        p = prim
        while p and not p.IsPseudoRoot():
            xformable = UsdGeom.Xformable(p)
            if xformable and xformable.TransformMightBeTimeVarying():
                return True
            p = p.GetParent()
        return False

    def _track_transform(self, prim):
        if self._transform_varies(prim):
            prim_id = prim.GetPath().pathString
            self._updaters.append(
                ("transform", lambda t: self.store.set_transform(prim_id, _matrix(self._world_of(prim)))))

    def _track_visibility(self, prim, prim_id):
        imageable = UsdGeom.Imageable(prim)
        visible = imageable.ComputeVisibility(self.time) != UsdGeom.Tokens.invisible
        if not visible:
            self.store.set_visible(prim_id, False)
        p = prim
        while p and not p.IsPseudoRoot():
            vis = UsdGeom.Imageable(p).GetVisibilityAttr() if UsdGeom.Imageable(p) else None
            if _varies([vis]):
                self._updaters.append(("visibility", lambda t: self.store.set_visible(
                    prim_id, imageable.ComputeVisibility(t) != UsdGeom.Tokens.invisible)))
                break
            p = p.GetParent()

    # -- meshes ------------------------------------------------------------------------------------------------

    def _topology(self, prim, mesh, time):
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

    def _add_mesh(self, prim, prim_id, world):
        mesh = UsdGeom.Mesh(prim)
        path = prim.GetPath()
        check_transform(prim_id, world)  # an instance's transform composes the instancer's
        counts, indices, points = self._topology(prim, mesh, self.time)
        scheme = str(mesh.GetSubdivisionSchemeAttr().Get())
        if scheme not in SUBDIVISION_SCHEMES:
            raise EyeRenderError(f"{path}: subdivisionScheme '{scheme}' is not one of {', '.join(SUBDIVISION_SCHEMES)}")
        if scheme in ("loop", "bilinear"):
            self.warnings.append(f"{path}: subdivisionScheme '{scheme}' renders as its control polygons")
        level = self.refine_level if scheme == "catmullClark" else 0
        left = mesh.GetOrientationAttr().Get() == UsdGeom.Tokens.leftHanded
        material_id, st_name = self._bind_material(prim)
        if eyes.is_eye(prim):
            eye = self._eye_mesh_params(prim, self.time)
            self.store.add_eye_mesh(prim_id, counts, indices, points, eye, _matrix(world), material_id, level, left)
            self.eyes.append(prim_id)
            self._track_eye(prim, prim_id, mesh=True)
        else:
            self.store.add_mesh(prim_id, counts, indices, points, _matrix(world), material_id, level, left)
        names = {"st": st_name, **{n: n for n in PRIMVARS}}
        names["rest"] = self._rest_source(prim)
        for name, source in names.items():
            self._push_primvar(prim, prim_id, name, source, self.time)
        if names["rest"] is None:
            self._push_rest_time_points(prim, prim_id, mesh, len(points))
        self._track_visibility(prim, prim_id)

        points_attr = mesh.GetPointsAttr()
        if _varies([mesh.GetFaceVertexCountsAttr(), mesh.GetFaceVertexIndicesAttr()]):
            def update_topology(t):
                c, i, p = self._topology(prim, mesh, t)
                self.store.set_topology(prim_id, c, i, p, level, left)
            self._updaters.append(("topology", update_topology))
        elif _varies([points_attr]):
            self._updaters.append(("points", lambda t: self.store.set_points(
                prim_id, _array(points_attr.Get(t), 3, f"{path}: points"))))
        for name, source in names.items():
            if source is not None and _varies(self._primvar_attrs(prim, source)):
                self._updaters.append(
                    ("primvar", lambda t, n=name, s=source: self._push_primvar(prim, prim_id, n, s, t)))

    def _primvar_attrs(self, prim, name):
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

    def _push_rest_time_points(self, prim, prim_id, mesh, count):
        """An eye mesh with eye:restTime and no rest/Pref primvar: its points at that time code are its rest pose
        (sent as the vertex primvar "rest"). Nothing for other meshes, or without eye:restTime."""
        if not eyes.is_eye(prim):
            return
        attr = prim.GetAttribute("eye:restTime")
        rest_time = attr.Get() if attr and attr.HasAuthoredValue() else None
        if rest_time is None:
            return
        if not np.isfinite(rest_time):
            raise EyeRenderError(f"{prim.GetPath()}: eye:restTime = {rest_time} is not finite")
        rest = mesh.GetPointsAttr().Get(Usd.TimeCode(rest_time))
        if rest is None or len(rest) != count:
            raise EyeRenderError(f"{prim.GetPath()}: eye:restTime = {rest_time:g} has "
                                 f"{0 if rest is None else len(rest)} points, the mesh has {count}")
        self.store.set_primvar(prim_id, "rest", "vertex", _array(rest, 3, f"{prim.GetPath()}: points at eye:restTime"))

    def _eye_mesh_params(self, prim, time):
        """An eye mesh's EyeParams at `time`, with its iris projection (eye:irisProjection) resolved."""
        eye = eyes.read_eye_params(prim, time, self.cornea_model)
        projection = self._iris_projection(prim, time)
        if projection is not None:
            eye.iris_projection = projection
        return eye

    def _iris_projection_target(self, prim):
        """The Xformable prim eye:irisProjection names, or None when the relationship has no target."""
        rel = prim.GetRelationship("eye:irisProjection")
        targets = rel.GetForwardedTargets() if rel else []
        if not targets:
            return None
        if len(targets) > 1:
            raise EyeRenderError(f"{prim.GetPath()}: eye:irisProjection has {len(targets)} targets (needs one)")
        target = self.stage.GetPrimAtPath(targets[0])
        if not target or not target.IsValid():
            raise EyeRenderError(f"{prim.GetPath()}: eye:irisProjection target {targets[0]} does not exist")
        if not target.IsA(UsdGeom.Xformable):
            raise EyeRenderError(f"{prim.GetPath()}: eye:irisProjection target {targets[0]} is a "
                                 f"{target.GetTypeName() or 'typeless prim'}, not an Xform or Camera")
        return target

    def _iris_projection(self, prim, time):
        """eye:irisProjection's target frame relative to the eye prim's local space at `time` (USD's row-vector
        layout: target-to-world x inverse eye-to-world), as the 4x4 float64 array EyeParams.iris_projection takes;
        None without a target. Its [-1, 1]^2 xy square is the iris texture square (docs/deformed_eyes.md)."""
        target = self._iris_projection_target(prim)
        if target is None:
            return None
        cache = UsdGeom.XformCache(time)
        relative = cache.GetLocalToWorldTransform(target) * cache.GetLocalToWorldTransform(prim).GetInverse()
        m = _matrix(relative)
        if not np.isfinite(m).all() or abs(relative.GetDeterminant3()) < 1e-300:
            raise EyeRenderError(f"{prim.GetPath()}: eye:irisProjection target {target.GetPath()} has a singular "
                                 f"transform relative to the eye")
        return m

    def _push_primvar(self, prim, prim_id, name, source, time):
        """Sends primvar `source` of prim to the store under `name`, indices expanded; skips unauthored ones."""
        if source is None:
            return
        primvar = UsdGeom.PrimvarsAPI(prim).GetPrimvar(source)
        if primvar and primvar.HasValue():
            values, interpolation = primvar.ComputeFlattened(time), primvar.GetInterpolation()
        elif name == "normals" and UsdGeom.Mesh(prim).GetNormalsAttr().HasValue():
            mesh = UsdGeom.Mesh(prim)
            values, interpolation = mesh.GetNormalsAttr().Get(time), mesh.GetNormalsInterpolation()
        else:
            return
        if values is None or (hasattr(values, "__len__") and len(values) == 0):
            return
        try:
            values = _array(values, {"st": 2}.get(name, 3), f"{prim.GetPath()}: primvars:{source}")
        except EyeRenderError as e:  # the prim renders without it (normals: smooth shading)
            self.warnings.append(f"{e}: ignored")
            return
        self.store.set_primvar(prim_id, name, str(interpolation), values)

    def _add_gprim(self, prim):
        tessellated = tessellate_gprim(prim, self.time)
        if tessellated is None:
            self.warnings.append(f"{prim.GetPath()}: {prim.GetTypeName()} is not rendered (not supported)")
            return
        counts, indices, points = tessellated
        prim_id = prim.GetPath().pathString
        material_id, _ = self._bind_material(prim)
        self.store.add_mesh(prim_id, counts, indices, points, _matrix(self._world_of(prim)), material_id, 0, False)
        self._push_primvar(prim, prim_id, "displayColor", "displayColor", self.time)
        self._track_transform(prim)
        self._track_visibility(prim, prim_id)

    # -- point instancers --------------------------------------------------------------------------------------

    def _add_point_instancer(self, prim):
        """Flattens a PointInstancer: every instance of every mesh under its prototypes becomes a mesh prim."""
        instancer = UsdGeom.PointInstancer(prim)
        ids = self._add_instances(prim, instancer, self.time)
        attrs = [instancer.GetPositionsAttr(), instancer.GetOrientationsAttr(), instancer.GetScalesAttr(),
                 instancer.GetProtoIndicesAttr(), instancer.GetInvisibleIdsAttr()]
        if _varies(attrs) or self._transform_varies(prim):
            def update(t):
                for prim_id in ids:
                    self.store.remove_prim(prim_id)
                ids[:] = self._add_instances(prim, instancer, t)
            self._updaters.append(("instancer", update))

    def _add_instances(self, prim, instancer, time):
        prototypes = instancer.GetPrototypesRel().GetTargets()
        transforms = instancer.ComputeInstanceTransformsAtTime(time, time)
        proto_indices = instancer.GetProtoIndicesAttr().Get(time) or []
        mask = instancer.ComputeMaskAtTime(time)
        world = self._xforms.GetLocalToWorldTransform(prim)
        ids = []
        for k, (proto, instance) in enumerate(zip(proto_indices, transforms)):
            if (mask and not mask[k]) or not 0 <= proto < len(prototypes):
                continue
            root = self.stage.GetPrimAtPath(prototypes[proto])
            for mesh_prim in Usd.PrimRange(root, Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)):
                if not mesh_prim.IsA(UsdGeom.Mesh):
                    continue
                relative, _ = self._xforms.ComputeRelativeTransform(mesh_prim, root.GetParent())
                relative_path = mesh_prim.GetPath().MakeRelativePath(root.GetPath().GetParentPath())
                prim_id = f"{prim.GetPath()}/instance_{k}/{relative_path}"
                ids.append(prim_id)
                try:
                    self._add_mesh(mesh_prim, prim_id, relative * instance * world)
                except Exception:  # the instancer is skipped whole: none of its instances stays
                    for added in ids:
                        self.store.remove_prim(added)
                    raise
        return ids

    # -- cameras, lights, materials, eyes ----------------------------------------------------------------------

    def _add_camera(self, prim):
        camera = UsdGeom.Camera(prim)
        prim_id = prim.GetPath().pathString
        self.store.add_camera(prim_id, cameras.read_camera(camera, self.time), _matrix(self._world_of(prim)))
        self.cameras.append(prim_id)
        self._track_transform(prim)
        if _varies(prim.GetAttributes()):
            self._updaters.append(
                ("camera", lambda t: self.store.set_camera_params(prim_id, cameras.read_camera(camera, t))))

    def _add_light(self, prim):
        prim_id = prim.GetPath().pathString
        self.store.add_light(prim_id, lights.light_type(prim), lights.read_light(prim, self._world_of(prim), self.time),
                             _matrix(self._world_of(prim)))
        self.lights.append(prim_id)
        self.warnings.extend(lights.unsupported_light_features(prim, self.time))
        self._track_transform(prim)
        if _varies(prim.GetAttributes()):
            self._updaters.append(("light", lambda t: self.store.set_light_params(
                prim_id, lights.read_light(prim, self._world_of(prim), t))))

    def _bind_material(self, prim):
        """(material id, st primvar name) of prim's bound material, adding the material on first use."""
        material = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()[0]
        if not material:
            return "", "st"
        path = material.GetPath().pathString
        if path not in self._materials:
            params, st_name, ignored = materials.read_material(material, self.time)
            self.store.add_material(path, params)
            self.warnings.extend(ignored)
            self._materials[path] = st_name
            if any(_varies(p.GetAttributes()) for p in Usd.PrimRange(material.GetPrim())):
                self._updaters.append(("material", lambda t: self.store.set_material_params(
                    path, materials.read_material(material, t)[0])))
        return path, self._materials[path]

    def _add_analytic_eye(self, prim):
        prim_id = prim.GetPath().pathString
        self.store.add_analytic_eye(prim_id, eyes.read_eye_params(prim, self.time, self.cornea_model),
                                    _matrix(self._world_of(prim)))
        self.eyes.append(prim_id)
        self._track_transform(prim)
        self._track_eye(prim, prim_id)

    def _track_eye(self, prim, prim_id, mesh=False):
        if not mesh:
            if eyes.eye_attributes_vary(prim):
                self._updaters.append(("eye", lambda t: self.store.set_eye_params(
                    prim_id, eyes.read_eye_params(prim, t, self.cornea_model))))
            return
        # Eye meshes also carry the iris projection: it varies when its target's or the eye's transform does.
        target = self._iris_projection_target(prim)
        if eyes.eye_attributes_vary(prim) or (target is not None and (self._transform_varies(target) or
                                                                      self._transform_varies(prim))):
            self._updaters.append(("eye", lambda t: self.store.set_eye_params(prim_id, self._eye_mesh_params(prim, t))))

