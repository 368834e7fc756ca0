"""The USD scene delegate (UsdImagingDelegate's role): populates the hdeye render index from a Usd.Stage and keeps
it current as time moves.

Every supported prim becomes one delegate prim with the same path (instance proxies and point-instanced copies
get their own paths: instancing is flattened into separate prims that share nothing yet). `populate` reads the
stage once at the current time; `set_time` re-reads only what may vary in time (attributes with time samples,
transforms under animated xforms) and pushes it through the scene store's Set* calls, which mark exactly the
matching dirty bits. What each `set_time` pushed is counted in `last_update`. Edits made to the stage after
`populate` are queued by a Usd.Notice.ObjectsChanged listener and applied by `apply_stage_changes`
(stage_notices.py, counted in `last_changes`); UsdSkel skinning comes from skinning.py. docs/usd_support.md tables
what is read and how.

Supported: Xform hierarchies, Mesh (points, topology, subdivisionScheme and tags and holes (mesh_topology.py),
materialBind GeomSubsets, orientation, normals, primvars st /
displayColor / rest (or Pref; eye meshes: else their points at eye:restTime)), BasisCurves and Points (curves.py),
Sphere and Cube gprims (tessellated),
Camera, UsdLux sphere / distant / rect / disk / dome
lights, UsdShade UsdPreviewSurface materials, the EyeAPI on meshes and xforms (eye meshes: eye:irisProjection's
target resolved relative to the eye; eye:corneaShell's meshes left out, eye_rigs.py), purposes, visibility, instanceable
references and PointInstancers, UsdSkel (skinned points, blend shapes, rigid bindings). Anything else is skipped
and listed once in `warnings`.
"""
import collections

import numpy as np
from pxr import Usd, UsdGeom, UsdShade, UsdSkel

from . import cameras, curves, eye_rigs, eyes, lights, materials, mesh_topology, stage_notices
from .errors import EyeRenderError
from .gprims import tessellate_gprim
from .skinning import SkinningError, StageSkinning
from .textures import TextureWarning
from .usd_values import to_float_array as _array
from .usd_values import to_matrix as _matrix
from .usd_values import varies as _varies

PRIMVARS = ("displayColor", "normals", "rest")


class UsdSceneDelegate(stage_notices.StageFollowing):
    """Populates a SceneStore from a Usd.Stage (see the module doc)."""

    def __init__(self, stage, store, *, time=Usd.TimeCode.Default(), purposes=("proxy",), refine_level=2,
                 cornea_model=None, strict=False):
        """purposes: the UsdGeom purposes to render ("default" is always included); refine_level: Catmull-Clark
        refinement level for subdivision meshes (usdrecord's --complexity); cornea_model: overrides every eye's
        eye:corneaModel ("ellipsoidCone" or "paraboloid") for A/B renders; strict: a texture that cannot be read
        fails populate() (EyeRenderError) instead of being a warning."""
        self.stage, self.store = stage, store
        self.time = Usd.TimeCode(time)
        self.purposes = tuple(dict.fromkeys(("default",) + tuple(purposes)))
        self.refine_level = refine_level
        self.cornea_model = cornea_model
        self.strict = strict
        self.cameras = []        # camera prim paths, in traversal order
        self.eyes = []           # eye prim paths (meshes and analytic)
        self.warnings = []       # one line each: what was skipped or ignored
        self.last_update = collections.Counter()
        self._xforms = UsdGeom.XformCache(self.time)
        self._updaters = []      # (owner prim path, kind, callable(time)) for what varies in time
        self._owned = {}         # owner prim path -> delegate prim ids it added
        self._owner = None       # the prim _add_prim is adding
        self._point_counts = {}  # mesh id -> number of points its topology was built for
        self._changes = stage_notices.StageChangeQueue(stage)
        self.last_changes = collections.Counter()  # what the last apply_stage_changes did, by kind
        self._materials = {}     # material path -> st primvar name
        self._skinning = StageSkinning(self.warnings)  # filled as populate meets SkelRoots
        self._rigs = None        # eye_rigs.EyeRigs: the cornea shells left out, found by populate
        self._warned = set()     # warnings given once per stage (mesh_topology's)
        self._populated = False

    # -- public ------------------------------------------------------------------------------------------------

    def populate(self):
        if self._populated:
            raise RuntimeError("populate() was already called")
        self._populated = True
        self._rigs = eye_rigs.EyeRigs(self.stage, self.warnings, self.time)
        self._add_subtree(self.stage.GetPseudoRoot())
        self._rigs.warn_look_alikes(list(self._point_counts))
        self._changes.take()  # edits before now are in what was just read

    @property
    def cornea_shells(self):
        """{shell mesh path: eye prim path} of the cornea shells left out (eye:corneaShell; eye_rigs.py)."""
        return dict(self._rigs.shell_of) if self._rigs else {}

    def _add_subtree(self, root):
        """Adds every prim under root; strict: a texture found unreadable under it is an EyeRenderError."""
        known = len(self.warnings)
        it = iter(Usd.PrimRange(root, Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)))
        for prim in it:
            if prim.IsPseudoRoot():
                continue
            imageable = UsdGeom.Imageable(prim)
            if imageable and imageable.ComputePurpose() not in self.purposes:
                it.PruneChildren()
                continue
            if self._add_prim(prim):
                it.PruneChildren()
        unreadable = [w for w in self.warnings[known:] if isinstance(w, TextureWarning)]
        if self.strict and unreadable:
            raise EyeRenderError(str(unreadable[0]).split("; ")[0])

    def set_time(self, time):
        """Moves to `time`, pushing only what varies; returns (and keeps in last_update) the counts by kind."""
        self.time = Usd.TimeCode(time)
        self._xforms.SetTime(self.time)
        self.last_update = collections.Counter()
        for _, kind, update in self._updaters:
            update(self.time)
            self.last_update[kind] += 1
        return self.last_update

    def _track(self, entry, owner=None):
        """Registers (kind, callable(time)) for what varies in time, owned by `owner` (default: the prim being
        added): re-populating the owner drops it."""
        self._updaters.append((owner or self._owner,) + tuple(entry))

    def _own(self, prim_id):
        self._owned.setdefault(self._owner, []).append(prim_id)

    # -- dispatch ----------------------------------------------------------------------------------------------

    def _add_prim(self, prim):
        """Adds a prim; returns True when its children are handled too (or must not be rendered)."""
        self._owner = prim.GetPath()
        if self._rigs is not None and self._rigs.is_shell(prim):  # the analytic cornea replaces it
            return True
        if prim.IsA(UsdSkel.Root):  # its skinned prims, before they are added
            self._skinning.add_root(prim)
        if prim.IsA(UsdGeom.PointInstancer):
            self._add_point_instancer(prim)
            return True
        if prim.IsA(UsdGeom.Mesh):
            self._add_mesh(prim, prim.GetPath().pathString, self._world_of(prim))
            self._track_transform(prim)
            return False
        if prim.IsA(UsdGeom.BasisCurves) or prim.IsA(UsdGeom.Points):
            self._add_curves_or_points(prim)
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
        """prim's local-to-world transform, skinned when it or an ancestor is rigidly bound to a joint."""
        try:
            return self._skinning.world(prim, self._xforms, self.time)
        except SkinningError as e:
            self._skinning.drop(self._skinning.rigid_anchor(prim), e)
            return self._xforms.GetLocalToWorldTransform(prim)

    def _transform_varies(self, prim):
        """Whether prim's local-to-world transform may change: animated xform ops, or animated joints it or an
        ancestor is rigidly bound to."""
        anchor = self._skinning.rigid_anchor(prim)
        return (anchor is not None and anchor.might_vary(self._xforms_vary)) or self._xforms_vary(prim)

    @staticmethod
    def _xforms_vary(prim):
        """Whether prim's own or an ancestor's xform ops are animated."""
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
            kind = "transform" if self._skinning.rigid_anchor(prim) is None else "skinned transform"
            self._track((kind, lambda t: self.store.set_transform(prim_id, _matrix(self._world_of(prim)))))

    def _track_visibility(self, prim, prim_id):
        imageable = UsdGeom.Imageable(prim)
        visible = imageable.ComputeVisibility(self.time) != UsdGeom.Tokens.invisible
        if not visible:
            self.store.set_visible(prim_id, False)
        p = prim
        while p and not p.IsPseudoRoot():
            vis = UsdGeom.Imageable(p).GetVisibilityAttr() if UsdGeom.Imageable(p) else None
            if _varies([vis]):
                self._track(("visibility", lambda t: self.store.set_visible(
                    prim_id, imageable.ComputeVisibility(t) != UsdGeom.Tokens.invisible)))
                break
            p = p.GetParent()

    # -- meshes ------------------------------------------------------------------------------------------------

    def _topology(self, prim, mesh, time):
        path = prim.GetPath()
        counts = np.asarray(mesh.GetFaceVertexCountsAttr().Get(time) or [], dtype=np.int32)
        indices = np.asarray(mesh.GetFaceVertexIndicesAttr().Get(time) or [], dtype=np.int32)
        points = mesh.GetPointsAttr().Get(time)
        if points is None or len(points) == 0 or len(counts) == 0:
            raise EyeRenderError(f"{path}: mesh has no points or no faces")
        points = _array(points, 3, f"{path}: points")
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
        counts, indices, points = self._topology(prim, mesh, self.time)
        skinned = self._skinned_points_of(prim, prim_id)
        if skinned is not None:
            points = self._skinned_points(skinned, self.time, points)
            if self._skinning.get(prim) is None and skinned.moves_frame:  # dropped: its bind frame, unskinned
                world = self._xforms.GetLocalToWorldTransform(prim)
        subdivision = mesh_topology.Subdivision(mesh, counts, indices, len(points), self.time)
        self._warn_once(subdivision.warnings)
        level = self.refine_level if subdivision.refines else 0
        self._point_counts[prim_id] = len(points)
        left = mesh.GetOrientationAttr().Get() == UsdGeom.Tokens.leftHanded
        material_id, st_name = self._bind_material(prim)
        if eyes.is_eye(prim):
            eye = self._eye_mesh_params(prim, self.time, self.warnings)
            self.store.add_eye_mesh(prim_id, counts, indices, points, eye, _matrix(world), material_id, level, left)
            self.eyes.append(prim_id)
            self._own_top_level(prim, prim_id)
            self._track_eye(prim, prim_id, mesh=True)
        else:
            self.store.add_mesh(prim_id, counts, indices, points, _matrix(world), material_id, level, left)
            self._own_top_level(prim, prim_id)
        self._push_mesh_tags(prim, prim_id, subdivision, len(counts))
        names = {"st": st_name, **{n: n for n in PRIMVARS}}
        names["rest"] = self._rest_source(prim)
        # Authored normals shade polygon meshes only (refined ones use limit normals). A skinned polygon mesh's
        # normals are skinned with its points; ones that cannot be would be stale: smooth normals instead.
        skin_normals = None
        authored_normals = any(a.HasAuthoredValue() for a in self._primvar_attrs(prim, "normals"))
        if skinned is not None and level == 0 and authored_normals:
            names["normals"] = None
            if skinned.skinnable_normals():
                skin_normals = prim_id
            else:
                self.warnings.append(f"{path}: {skinned.normals_interpolation()} normals cannot follow per-vertex "
                                     f"skinning (rendered with smooth normals)")
        for name, source in names.items():
            self._push_primvar(prim, prim_id, name, source, self.time)
        if skin_normals:
            self._skinned_points(skinned, self.time, points, normals_id=skin_normals)
        if names["rest"] is None:
            self._push_rest_time_points(prim, prim_id, mesh, len(points), skinned)
        self._track_visibility(prim, prim_id)

        points_attr = mesh.GetPointsAttr()
        if _varies([mesh.GetFaceVertexCountsAttr(), mesh.GetFaceVertexIndicesAttr()]):
            def update_topology(t):
                c, i, p = self._topology(prim, mesh, t)
                self.store.set_topology(prim_id, c, i, p, level, left)
                self._push_mesh_tags(prim, prim_id, mesh_topology.Subdivision(mesh, c, i, len(p), t), len(c))
                self._point_counts[prim_id] = len(p)
            self._track(("topology", update_topology))
        elif skinned is not None:
            if skinned.might_vary(self._xforms_vary):
                self._track(("skinned points", lambda t: self.store.set_points(
                    prim_id, self._skinned_points(skinned, t, None, normals_id=skin_normals))))
        elif _varies([points_attr]):
            self._track(("points", lambda t: self.store.set_points(
                prim_id, _array(points_attr.Get(t), 3, f"{path}: points"))))
        for name, source in names.items():
            if source is not None and _varies(self._primvar_attrs(prim, source)):
                self._track(("primvar", lambda t, n=name, s=source: self._push_primvar(prim, prim_id, n, s, t)))

    def _push_mesh_tags(self, prim, prim_id, subdivision, face_count):
        """A mesh's subdivision tags and holes, and its materialBind GeomSubsets (per-face materials)."""
        if subdivision.authored():
            subdivision.push(self.store, prim_id)
        subsets, warnings = mesh_topology.material_subsets(prim, face_count, self.time,
                                                           lambda subset: self._bind_material(subset)[0])
        self._warn_once(warnings)
        if subsets:
            self.store.set_geom_subsets(prim_id, subsets)

    def _warn_once(self, warnings):
        """Adds warnings not given yet (a prototype's mesh is added once per point-instanced copy)."""
        self.warnings.extend(w for w in warnings if w not in self._warned and not self._warned.add(w))

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

    def _own_top_level(self, prim, prim_id):
        """Owns a mesh added for itself (not as a PointInstancer's copy, which its instancer owns)."""
        if prim_id == prim.GetPath().pathString:
            self._own(prim_id)

    def _skinned_points_of(self, prim, prim_id):
        """The SkinnedPrim deforming this mesh's points, or None (also for instanced copies: not skinned)."""
        skinned = self._skinning.get(prim)
        if skinned is None or not skinned.deforms_points:
            return None
        if prim_id != prim.GetPath().pathString:
            warning = f"{prim.GetPath()}: point-instanced copies of a skinned mesh render unskinned"
            if warning not in self.warnings:
                self.warnings.append(warning)
            return None
        return skinned

    def _skinned_points(self, skinned, time, fallback, normals_id=None):
        """A skinned mesh's points at `time` (and, with normals_id, its skinned normals sent to that prim); after
        bad skel data (one warning) its authored points, unskinned."""
        if self._skinning.get(skinned.prim) is skinned:
            try:
                cache = self._xforms if time == self.time else UsdGeom.XformCache(time)
                points, normals = skinned.deform(time, cache, with_normals=normals_id is not None)
                if normals is not None:
                    self.store.set_primvar(normals_id, "normals", str(skinned.normals_interpolation()), normals)
                return points
            except SkinningError as e:
                self._skinning.drop(skinned, e)
        if fallback is not None:
            return fallback
        return _array(skinned.rest_points(time), 3, f"{skinned.prim.GetPath()}: points")

    def _push_rest_time_points(self, prim, prim_id, mesh, count, skinned=None):
        """An eye mesh with eye:restTime and no rest/Pref primvar: its points (skinned, for a skinned mesh) at that
        time code are its rest pose (sent as the vertex primvar "rest"). A skinned eye mesh without eye:restTime
        rests in its bind pose (its authored points). Nothing for other meshes."""
        if not eyes.is_eye(prim):
            return
        attr = prim.GetAttribute("eye:restTime")
        rest_time = attr.Get() if attr and attr.HasAuthoredValue() else None
        if rest_time is None:
            if skinned is not None:
                bind = skinned.rest_points(self.time)
                self.store.set_primvar(prim_id, "rest", "vertex", _array(bind, 3, f"{prim.GetPath()}: bind points"))
            return
        if not np.isfinite(rest_time):
            raise EyeRenderError(f"{prim.GetPath()}: eye:restTime = {rest_time} is not finite")
        if skinned is not None:
            rest = self._skinned_points(skinned, Usd.TimeCode(rest_time), None)
        else:
            rest = mesh.GetPointsAttr().Get(Usd.TimeCode(rest_time))
        if rest is None or len(rest) != count:
            raise EyeRenderError(f"{prim.GetPath()}: eye:restTime = {rest_time:g} has "
                                 f"{0 if rest is None else len(rest)} points, the mesh has {count}")
        self.store.set_primvar(prim_id, "rest", "vertex", _array(rest, 3, f"{prim.GetPath()}: points at eye:restTime"))

    def _eye_mesh_params(self, prim, time, warnings=None):
        """An eye mesh's EyeParams at `time`, with its iris projection (eye:irisProjection) resolved."""
        eye = eyes.read_eye_params(prim, time, self.cornea_model, warnings)
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
        if values is None or len(values) == 0:
            return
        components = {"st": 2}.get(name, 3)
        self.store.set_primvar(prim_id, name, str(interpolation),
                               _array(values, components, f"{prim.GetPath()}: primvars:{source}"))

    def _add_gprim(self, prim):
        tessellated = tessellate_gprim(prim, self.time)
        if tessellated is None:
            self.warnings.append(f"{prim.GetPath()}: {prim.GetTypeName()} is not rendered (not supported)")
            return
        counts, indices, points = tessellated
        prim_id = prim.GetPath().pathString
        material_id, _ = self._bind_material(prim)
        self.store.add_mesh(prim_id, counts, indices, points, _matrix(self._world_of(prim)), material_id, 0, False)
        self._own(prim_id)
        self._push_primvar(prim, prim_id, "displayColor", "displayColor", self.time)
        self._track_transform(prim)
        self._track_visibility(prim, prim_id)

    def _add_curves_or_points(self, prim):
        """BasisCurves as tubes or ribbons, Points as spheres (curves.py); bad data skips the prim with a warning."""
        prim_id = prim.GetPath().pathString
        material_id, _ = self._bind_material(prim)
        add = curves.add_basis_curves if prim.IsA(UsdGeom.BasisCurves) else curves.add_points
        try:
            animated = add(self.store, prim, prim_id, _matrix(self._world_of(prim)), material_id, self.time)
        except EyeRenderError as e:
            self.warnings.append(f"{e}; not rendered")
            return
        self._own(prim_id)
        self._track_transform(prim)
        self._track_visibility(prim, prim_id)
        if _varies(animated):
            self._track(("points", lambda t: curves.update(self.store, prim, prim_id, t)))

    # -- point instancers --------------------------------------------------------------------------------------

    def _add_point_instancer(self, prim):
        """Flattens a PointInstancer: every instance of every mesh under its prototypes becomes a mesh prim."""
        instancer = UsdGeom.PointInstancer(prim)
        ids = self._add_instances(prim, instancer, self.time)
        self._owned[prim.GetPath()] = ids  # the same list: updates replace its contents
        attrs = [instancer.GetPositionsAttr(), instancer.GetOrientationsAttr(), instancer.GetScalesAttr(),
                 instancer.GetProtoIndicesAttr(), instancer.GetInvisibleIdsAttr()]
        if _varies(attrs) or self._transform_varies(prim):
            def update(t):
                for prim_id in ids:
                    self.store.remove_prim(prim_id)
                ids[:] = self._add_instances(prim, instancer, t)
            self._track(("instancer", update))

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
                if not mesh_prim.IsA(UsdGeom.Mesh) or (self._rigs and self._rigs.is_shell(mesh_prim)):
                    continue
                relative, _ = self._xforms.ComputeRelativeTransform(mesh_prim, root.GetParent())
                relative_path = mesh_prim.GetPath().MakeRelativePath(root.GetPath().GetParentPath())
                prim_id = f"{prim.GetPath()}/instance_{k}/{relative_path}"
                self._add_mesh(mesh_prim, prim_id, relative * instance * world)
                ids.append(prim_id)
        return ids

    # -- cameras, lights, materials, eyes ----------------------------------------------------------------------

    def _add_camera(self, prim):
        camera = UsdGeom.Camera(prim)
        prim_id = prim.GetPath().pathString
        self.store.add_camera(prim_id, cameras.read_camera(camera, self.time), _matrix(self._world_of(prim)))
        self.cameras.append(prim_id)
        self._own(prim_id)
        self._track_transform(prim)
        if _varies(prim.GetAttributes()):
            self._track(("camera", lambda t: self.store.set_camera_params(prim_id, cameras.read_camera(camera, t))))

    def _add_light(self, prim):
        prim_id = prim.GetPath().pathString
        params = lights.read_light(prim, self._world_of(prim), self.time, self.warnings)
        self.store.add_light(prim_id, lights.light_type(prim), params, _matrix(self._world_of(prim)))
        self._own(prim_id)
        self.warnings.extend(lights.unsupported_light_features(prim, self.time))
        self._track_transform(prim)
        if _varies(prim.GetAttributes()):
            self._track(("light", lambda t: self.store.set_light_params(
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
                self._track(("material", lambda t: self.store.set_material_params(
                    path, materials.read_material(material, t)[0])), owner=material.GetPath())
        return path, self._materials[path]

    def _add_analytic_eye(self, prim):
        prim_id = prim.GetPath().pathString
        self.store.add_analytic_eye(prim_id, eyes.read_eye_params(prim, self.time, self.cornea_model, self.warnings),
                                    _matrix(self._world_of(prim)))
        self.eyes.append(prim_id)
        self._own(prim_id)
        self._track_transform(prim)
        self._track_eye(prim, prim_id)

    def _track_eye(self, prim, prim_id, mesh=False):
        if not mesh:
            if eyes.eye_attributes_vary(prim):
                self._track(("eye", lambda t: self.store.set_eye_params(
                    prim_id, eyes.read_eye_params(prim, t, self.cornea_model))))
            return
        # Eye meshes also carry the iris projection: it varies when its target's or the eye's transform does.
        target = self._iris_projection_target(prim)
        if eyes.eye_attributes_vary(prim) or (target is not None and (self._transform_varies(target) or
                                                                      self._transform_varies(prim))):
            self._track(("eye", lambda t: self.store.set_eye_params(prim_id, self._eye_mesh_params(prim, t))))

