"""The USD scene delegate (UsdImagingDelegate's role): populates the hdeye render index from a Usd.Stage and keeps
it current as time moves.

Every supported prim becomes one delegate prim with the same path; instances (PointInstancers, instanceable prims)
become hdeye instancers over prototype prims added once (instancing.py). `populate` reads the
stage once at the current time; `set_time` re-reads only what may vary in time (attributes with time samples,
transforms under animated xforms) and pushes it through the scene store's Set* calls, which mark exactly the
matching dirty bits. What each `set_time` pushed is counted in `last_update`. Under a shutter that spans time
(`set_shutter`), what moves is pushed as samples over it through the *_samples calls (motion.py). Edits made to
the stage after `populate` are queued by a Usd.Notice.ObjectsChanged listener and applied by `apply_stage_changes`
(stage_notices.py, counted in `last_changes`); UsdSkel skinning comes from skinning.py. docs/usd_support.md tables
what is read and how.

Supported: Xform hierarchies, Mesh (points, topology, subdivisionScheme and tags and holes (mesh_topology.py),
materialBind GeomSubsets, orientation, normals, primvars st /
displayColor / rest (or Pref; eye meshes: else their points at eye:restTime)), BasisCurves and Points (curves.py),
implicit gprims (Sphere, Cube, Plane, Cylinder, Cone, Capsule and the _1 forms, tessellated: gprims.py),
Camera, UsdLux sphere / distant / rect / disk / dome
lights, UsdShade UsdPreviewSurface materials, the EyeAPI on meshes and xforms (eye meshes: eye:irisProjection's
target resolved relative to the eye; eye:corneaShell's meshes left out, eye_rigs.py), purposes, visibility, instanceable
references and PointInstancers, UsdSkel (skinned points, blend shapes, rigid bindings). Anything else is skipped
and listed once in `warnings`.
"""
import collections
import contextlib

import numpy as np
from pxr import Usd, UsdGeom, UsdSkel

from . import cameras, curves, eye_rigs, eyes, lights, materials, mesh_topology, motion, stage_notices
from .errors import EyeRenderError
from .gprims import tessellate_gprim
from .instancing import Instancing
from .shutter import SHARP
from .skinning import SkinningError, StageSkinning
from .textures import TextureWarning
from .usd_values import scalar_as_array
from .usd_values import to_float_array as _array
from .usd_values import to_matrix as _matrix
from .usd_values import varies as _varies
from .validation import check_transform, reading

PRIMVARS = ("displayColor", "normals", "rest")


def _array_of_points(values, what):
    return _array(values, 3, what)


def _has_skel_binding(prim):
    """Whether prim has joint influences or blend shapes authored (UsdSkel.BindingAPI)."""
    if not prim.HasAPI(UsdSkel.BindingAPI):
        return False
    api = UsdSkel.BindingAPI(prim)
    return api.GetJointIndicesPrimvar().HasAuthoredValue() or bool(api.GetBlendShapeTargetsRel().GetTargets())


class UsdSceneDelegate(stage_notices.StageFollowing):
    """Populates a SceneStore from a Usd.Stage (see the module doc)."""

    def __init__(self, stage, store, *, time=Usd.TimeCode.Default(), purposes=("proxy",), refine_level=2,
                 cornea_model=None, strict=False, flatten_instances=False,
                 material_purposes=materials.DEFAULT_BINDING_PURPOSES):
        """purposes: the UsdGeom purposes to render ("default" is always included); material_purposes: the material
        binding purposes, in order ("" all-purpose; UsdRender's materialBindingPurposes); refine_level: Catmull-Clark
        refinement level for subdivision meshes (usdrecord's --complexity); cornea_model: overrides every eye's
        eye:corneaModel ("ellipsoidCone" or "paraboloid") for A/B renders; strict: a texture that cannot be read
        fails populate() (EyeRenderError) instead of being a warning; flatten_instances: every instance as its
        own prims (the reference instancing is compared with) instead of shared instancers."""
        self.stage, self.store = stage, store
        self.time = Usd.TimeCode(time)
        self.purposes = tuple(dict.fromkeys(("default",) + tuple(purposes)))
        self.material_purposes = tuple(material_purposes)
        self.refine_level = refine_level
        self.cornea_model = cornea_model
        self.strict = strict
        self.cameras = []        # camera prim paths, in traversal order
        self.eyes = []           # eye prim paths (meshes and analytic)
        self.lights = []         # light prim paths
        self.warnings = []       # one line each: what was skipped or ignored
        self.last_update = collections.Counter()
        self._xforms = UsdGeom.XformCache(self.time)
        self._updaters = []      # (owner prim path, kind, callable(time)) for what varies in time
        self._owned = {}         # owner prim path -> delegate prim ids it added
        # Instanced rprims: the prim they were made from, the prim whose material they bind, and each instance's
        # name (cryptomatte.py); an rprim of a prim of its own is named by its id, the prim's path.
        self.instanced_prims = {}  # rprim id -> (prim, binding prim)
        self.instance_names = {}  # rprim id -> [name of instance 0, 1, ...]
        self._owner = None       # the prim _add_prim is adding
        self._instance_sources = {}  # prim path an instancer reads -> owner prim paths it re-populates (owning)
        self._skipped = set()    # owner prim paths skipped (a later edit may fix them: stage_notices re-adds)
        self._refused_eyes = []  # errors of eyes that could not be rendered: raised when this read ends
        self._point_counts = {}  # mesh id -> number of points its topology was built for
        self._element_counts = {}  # mesh id -> {interpolation: elements a primvar of it needs} (_push_primvar)
        self._changes = stage_notices.StageChangeQueue(stage)
        self.last_changes = collections.Counter()  # what the last apply_stage_changes did, by kind
        self._materials = {}     # material path -> st primvar name
        self._skinning = StageSkinning(self.warnings)  # filled as populate meets SkelRoots
        self._rigs = None        # eye_rigs.EyeRigs: the cornea shells left out, found by populate
        self._warned = set()     # warnings given once per stage (mesh_topology's)
        self._rprims = {}        # rprim id -> the prim path it came from (light linking's membership)
        self._lights = {}        # light prim path -> its prim
        self._link_excludes = {}  # light prim path -> (not lit, not shadowing) rprim ids, where linked
        self._populated = False
        self._instancing = Instancing(self, flatten=flatten_instances)
        self.shutter = SHARP       # the render's shutter at the current time (shutter.py)
        self._shutter_at = None    # callable(Usd.TimeCode) -> Shutter, from set_shutter
        self._motion_warned = set()  # (prim path, kind) motion warnings given
        self._motion = motion.MotionSampler(self.time, SHARP)

    # -- public ------------------------------------------------------------------------------------------------

    def populate(self):
        if self._populated:
            raise RuntimeError("populate() was already called")
        self._populated = True
        self._rigs = eye_rigs.EyeRigs(self.stage, self.warnings, self.time)
        self._add_subtree(self.stage.GetPseudoRoot())
        self._rigs.warn_look_alikes(list(self._point_counts))
        self._changes.take()  # edits before now are in what was just read
        self.raise_refused_eyes()

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
                continue  # not pruned: a child's own purpose overrides the one it inherits
            try:
                with reading(prim.GetPath()):
                    if prim.IsInstance() and not self._instancing.flatten:
                        self._instancing.add_native_instance(prim)
                        handled = True
                    else:
                        handled = self._add_prim(prim)
            except EyeRenderError as e:  # this prim cannot be rendered: the rest of the stage still can
                self._skip(prim.GetPath(), e)
                handled = True
            if handled:
                it.PruneChildren()
        self._instancing.finish()
        unreadable = [w for w in self.warnings[known:] if isinstance(w, TextureWarning)]
        if self.strict and unreadable:
            raise EyeRenderError(str(unreadable[0]).split("; ")[0])
        self._link_lights()

    def _skip(self, owner, error):
        """Drops what prim `owner` added (it failed part-way through, or an edit made it unreadable) with one
        warning ending '(skipped)'. An eye is never skipped: its error is raised when this read of the stage ends
        (raise_refused_eyes), as rendering the shot without it would hide the problem in a plausible image."""
        self._forget(owner)
        self._skipped.add(owner)
        prim = self.stage.GetPrimAtPath(owner)
        if prim and eyes.is_eye(prim):
            self._refused_eyes.append(error)
        else:
            self.warnings.append(f"{error} (skipped)")

    def raise_refused_eyes(self):
        """Raises the first error of an eye that could not be rendered since the last call (EyeRenderError, one
        line, the count of any others appended); the rest of the stage was read, and a later edit that fixes the
        eye adds it back."""
        refused, self._refused_eyes = self._refused_eyes, []
        if refused:
            others = f" (and {len(refused) - 1} more eye(s) that cannot be rendered)" if len(refused) > 1 else ""
            raise EyeRenderError(f"{refused[0]}{others}")

    def _forget(self, owner):
        """Removes every delegate prim owner prim `owner` added (its own id too, which the store may hold before
        `_own` records it), its updaters, and its ids in the lists and light-linking tables."""
        for prim_id in dict.fromkeys(self._owned.pop(owner, []) + [owner.pathString]):
            self.store.remove_prim(prim_id)
            self._forget_id(prim_id)
        self._updaters = [u for u in self._updaters if u[0] != owner]

    def _link_lights(self):
        """Resolves each light's light and shadow link collections over the rprims, once every rprim is known (after
        populate and after every re-population by a stage edit, which may add or remove rprims)."""
        for prim_id, prim in self._lights.items():
            if self._link_light(prim_id, prim):
                self.store.set_light_params(prim_id, self._light_params(prim, self.time))

    def _link_light(self, prim_id, prim):
        """Re-resolves one light's link collections into _link_excludes; returns whether they changed."""
        excludes = lights.link_excludes(prim, self._rprims)
        before = self._link_excludes.pop(prim_id, None)
        if any(excludes):
            self._link_excludes[prim_id] = excludes
        return self._link_excludes.get(prim_id) != before

    def _light_params(self, prim, time, warnings=None):
        """A light's LightParams at `time` with the rprims its link collections leave out (texture warnings go to
        `warnings`, a list, if given)."""
        return lights.with_links(lights.read_light(prim, time, warnings),
                                 self._link_excludes.get(prim.GetPath().pathString))

    def set_time(self, time):
        """Moves to `time`, pushing only what varies; returns (and keeps in last_update) the counts by kind."""
        self.time = Usd.TimeCode(time)
        self._xforms.SetTime(self.time)
        self.last_update = collections.Counter()
        self._follow_shutter()
        with reading(f"time {self.time.GetValue():g}"):
            for _, kind, update in self._updaters:
                update(self.time)
                self.last_update[kind] += 1
        return self.last_update

    def set_shutter(self, shutter_at):
        """Renders under the shutter shutter_at(Usd.TimeCode) gives (a shutter.Shutter) at each frame: every
        camera's CameraParams carry it, and what moves within it is pushed as samples (motion.py). Re-pushes what
        moves at the current time when the shutter spans time; a sharp shutter changes nothing."""
        self._shutter_at = shutter_at
        before = self.shutter
        self._follow_shutter()
        if self._motion.blurred or before.blurred:
            with reading(f"time {self.time.GetValue():g}"):
                for _, kind, update in self._updaters:
                    if kind in motion.MOTION_KINDS:
                        update(self.time)
        return self.shutter

    def _follow_shutter(self):
        """The shutter and motion sampler of the current time; cameras re-pushed when the shutter changed."""
        shutter = self._shutter_at(self.time) if self._shutter_at else SHARP
        self._motion = motion.MotionSampler(self.time, shutter, self.warnings, self._motion_warned)
        if shutter != self.shutter:
            self.shutter = shutter
            for prim_id in self.cameras:
                self.store.set_camera_params(prim_id, self._camera_params(UsdGeom.Camera(
                    self.stage.GetPrimAtPath(prim_id)), self.time))

    def _track(self, entry, owner=None):
        """Registers (kind, callable(time)) for what varies in time, owned by `owner` (default: the prim being
        added): re-populating the owner drops it."""
        self._updaters.append((owner or self._owner,) + tuple(entry))

    def _own(self, prim_id):
        self._owned.setdefault(self._owner, []).append(prim_id)

    def _forget_id(self, prim_id):
        """Drops a removed delegate prim from the lists and light-linking tables that name it."""
        self._point_counts.pop(prim_id, None)
        self._element_counts.pop(prim_id, None)
        for ids in (self.eyes, self.cameras, self.lights):
            if prim_id in ids:
                ids.remove(prim_id)
        self._rprims.pop(prim_id, None)
        self._lights.pop(prim_id, None)
        self._link_excludes.pop(prim_id, None)

    # -- dispatch ----------------------------------------------------------------------------------------------

    def _add_prim(self, prim):
        """Adds a prim; returns True when its children are handled too (or must not be rendered)."""
        self._owner = prim.GetPath()
        if self._rigs is not None and self._rigs.is_shell(prim):  # the analytic cornea replaces it
            return True
        if prim.IsA(UsdSkel.Root):  # its skinned prims, before they are added
            self._skinning.add_root(prim)
        if prim.IsA(UsdGeom.PointInstancer):
            self._instancing.add_point_instancer(prim)
            return True
        if prim.IsA(UsdGeom.Mesh):
            self._add_mesh(prim, prim.GetPath().pathString, self._world_of(prim))
            self._track_transform(prim)
            return False
        if curves.is_curves_or_points(prim):
            self._add_curves_or_points(prim)
            return False
        if prim.IsA(UsdGeom.Camera):
            self._add_camera(prim)
        elif lights.light_type(prim):
            self._add_light(prim)
        elif lights.skipped_light(prim):
            self.warnings.append(lights.skipped_light(prim))
        elif prim.IsA(UsdGeom.Gprim):
            self._add_gprim(prim)
        elif eyes.is_eye(prim) and prim.IsA(UsdGeom.Xformable):
            self._add_analytic_eye(prim)
        return False

    # -- what instancing.py uses --------------------------------------------------------------------------------

    def world_of(self, prim):
        """prim's local-to-world transform at the current time (Gf.Matrix4d)."""
        return self._world_of(prim)

    @property
    def motion_sampler(self):
        """This frame's motion.MotionSampler (its shutter interval, XformCaches at its times, warnings once)."""
        return self._motion

    @property
    def xform_cache(self):
        """The UsdGeom.XformCache at the current time."""
        return self._xforms

    def add_updater(self, kind, update):
        """Registers update(time), called by set_time and counted under `kind` in last_update; owned by the prim
        being added (see owning)."""
        self._track((kind, update))

    @contextlib.contextmanager
    def owning(self, owner, sources=()):
        """Within it, every delegate prim and updater added (instancers included, see own_prim) belongs to prim path
        `owner` and goes when it re-populates; an edit at, above or under a path in `sources` (prototype roots and
        instance prims the owner reads) re-populates the owner (stage_notices.py)."""
        previous, self._owner = self._owner, owner
        for source in sources:
            self._instance_sources.setdefault(source, set()).add(owner)
        try:
            yield
        finally:
            self._owner = previous

    def own_prim(self, prim_id):
        """Owns a delegate prim that has no prim of its own (an instancer) by the current owner."""
        self._own(prim_id)

    def is_cornea_shell(self, prim):
        """Whether prim is an eye's cornea shell, left out of the render index (eye_rigs.py)."""
        return bool(prim) and self._rigs is not None and self._rigs.is_shell(prim)

    def transform_varies(self, prim):
        return self._transform_varies(prim)

    def add_instanced_prim(self, prim, prim_id, transform, instancer_id, binding):
        """A prim of an instance prototype (instancing.py): `transform` is relative to the instancer's instances
        (or the world, with no instancer_id); `binding`: the prim whose bound material it gets. One that cannot be
        rendered is left out with one warning; the rest of the prototype still renders."""
        self.instanced_prims[prim_id] = (prim, binding or prim)
        updaters = len(self._updaters)
        try:
            with reading(prim.GetPath()):
                if prim.IsA(UsdGeom.Mesh):
                    self._add_mesh(prim, prim_id, transform, instancer_id, binding)
                elif curves.is_curves_or_points(prim):  # copied per instance: never under an instancer
                    self._add_curves_or_points(prim, prim_id, transform, binding)
                elif prim.IsA(UsdGeom.Gprim):
                    if not self._add_gprim(prim, prim_id, transform, instancer_id, binding):
                        return
                else:
                    self._add_analytic_eye(prim, prim_id, transform)
        except EyeRenderError as e:
            self.store.remove_prim(prim_id)  # whatever part of it was added
            self._forget_id(prim_id)
            del self._updaters[updaters:]
            instanced = binding is not None and binding.GetPath() != prim.GetPath()
            if eyes.is_eye(prim):  # never skipped (see _skip)
                where = f" (instanced as {binding.GetPath()})" if instanced else ""
                self._refused_eyes.append(EyeRenderError(f"{e}{where}"))
            else:
                self._warn_once([f"{e} (skipped{f'; instanced as {binding.GetPath()}' if instanced else ''})"])
            return
        self._own(prim_id)  # by the instancer's owner (owning): a copy is not its prim's own

    def _world_of(self, prim, time=None, cache=None):
        """prim's local-to-world transform at `time` (a time code, default the current time; `cache`: the
        XformCache at it), skinned when it or an ancestor is rigidly bound to a joint; raises EyeRenderError for
        one no prim can use (validation.check_transform)."""
        time, cache = (self.time, self._xforms) if time is None else (Usd.TimeCode(time), cache)
        try:
            world = self._skinning.world(prim, cache, time)
        except SkinningError as e:
            self._skinning.drop(self._skinning.rigid_anchor(prim), e)
            world = cache.GetLocalToWorldTransform(prim)
        what = "transform" if time == self.time else f"transform at time {time.GetValue():g}"
        return check_transform(prim.GetPath(), world, what)

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
            self._track((kind, lambda t: self.push_transform(prim, prim_id)))

    def push_transform(self, prim, prim_id):
        """Sends prim's transform at the current time: its samples over the shutter when it spans time and the
        prim moves within it, else the one value (a sample that cannot be used: one warning, sharp)."""
        if self._motion.blurred:
            try:
                anchor = self._skinning.rigid_anchor(prim)
                extra = motion.skinning_times(anchor, self._motion.interval()) if anchor is not None else ()
                samples = motion.transform_samples(self._motion, prim, lambda t, cache: self._world_of(prim, t, cache),
                                                   extra)
                if not samples.static:
                    self.store.set_transform_samples(prim_id, samples.times, samples.values)
                    return
            except EyeRenderError as e:
                self._motion.warn(prim.GetPath(), "transform", f"{e}: rendered without motion blur")
        self.store.set_transform(prim_id, _matrix(self._world_of(prim)))

    def _track_visibility(self, prim, prim_id):
        if prim_id != prim.GetPath().pathString:  # a prototype's prim: instancing.py judged it within its prototype
            return
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
        self._rprims[prim_id] = prim.GetPath()
        mesh = UsdGeom.Mesh(prim)
        path = prim.GetPath()
        check_transform(prim_id, world)  # an instance's transform composes the instancer's
        counts, indices, points = self._topology(prim, mesh, self.time)
        skinned = self._skinned_points_of(prim, prim_id)
        if skinned is not None:
            points = self._skinned_points(skinned, self.time, points)
            if self._skinning.get(prim) is None and skinned.moves_frame:  # dropped: its bind frame, unskinned
                world = check_transform(prim_id, self._xforms.GetLocalToWorldTransform(prim))
        subdivision = mesh_topology.Subdivision(mesh, counts, indices, len(points), self.time)
        self._warn_once(subdivision.warnings)
        level = self.refine_level if subdivision.refines else 0
        self._point_counts[prim_id] = len(points)
        self._count_elements(prim_id, counts, indices, points)
        left = mesh.GetOrientationAttr().Get() == UsdGeom.Tokens.leftHanded
        material_id, st_name = self._bind_material(binding or prim)
        if eyes.is_eye(prim):
            eye = self._eye_mesh_params(prim, self.time, self.warnings)
            self.store.add_eye_mesh(prim_id, counts, indices, points, eye, _matrix(world), material_id, level, left)
            self.eyes.append(prim_id)
            self._own_top_level(prim, prim_id)
            self._track_eye(prim, prim_id, mesh=True)
        else:
            self.store.add_mesh(prim_id, counts, indices, points, _matrix(world), material_id, level, left,
                                instancer_id=instancer_id)
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
                self._count_elements(prim_id, c, i, p)
            self._track(("topology", update_topology))
        elif skinned is not None:
            if skinned.might_vary(self._xforms_vary):
                self._track(("skinned points", lambda t: self._push_skinned_points(skinned, prim_id, skin_normals)))
        elif _varies([points_attr, mesh.GetVelocitiesAttr(), mesh.GetAccelerationsAttr()]) or \
                mesh.GetVelocitiesAttr().HasAuthoredValue():
            self._track(("points", lambda t: self.push_points(prim, prim_id)))
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
        """Owns a prim added for itself (an instance copy is owned by add_instanced_prim, as its instancer is)."""
        if prim_id == prim.GetPath().pathString:
            self._own(prim_id)

    def _skinned_points_of(self, prim, prim_id):
        """The SkinnedPrim deforming this mesh's points, or None (also for instanced copies: not skinned, one
        warning; a native instance's prototype prims, which no SkelRoot populate reaches, warn on their joint
        influences)."""
        skinned = self._skinning.get(prim)
        if prim_id != prim.GetPath().pathString:
            if (skinned is not None and skinned.deforms_points) or (prim.IsInPrototype() and _has_skel_binding(prim)):
                warning = f"{prim.GetPath()}: instanced copies of a skinned mesh render unskinned"
                if warning not in self.warnings:
                    self.warnings.append(warning)
            return None
        if skinned is None or not skinned.deforms_points:
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

    def push_points(self, prim, prim_id):
        """Sends a mesh's points at the current time: their samples over the shutter (velocities and accelerations
        applied) when it spans time and they move within it, else the authored points (a sample that cannot be
        used: one warning, sharp)."""
        path = prim.GetPath()
        if self._motion.blurred:
            try:
                samples = motion.points_samples(self._motion, prim, self._point_counts.get(prim_id), _array_of_points)
                if not samples.static:
                    self.store.set_points_samples(prim_id, samples.times, samples.values)
                    return
            except EyeRenderError as e:
                self._motion.warn(path, "points", f"{e}: rendered without motion blur")
        self.store.set_points(prim_id, _array(UsdGeom.PointBased(prim).GetPointsAttr().Get(self.time), 3,
                                              f"{path}: points"))

    def _push_skinned_points(self, skinned, prim_id, normals_id):
        """A skinned mesh's points (and skinned normals at the frame) at the current time, as samples over the
        shutter when it spans time and they move within it."""
        points = self._skinned_points(skinned, self.time, None, normals_id=normals_id)
        if self._motion.blurred and self._skinning.get(skinned.prim) is skinned:
            try:
                samples = motion.skinned_points_samples(self._motion, skinned, lambda t, cache: _array_of_points(
                    skinned.points(Usd.TimeCode(t), cache), f"{skinned.prim.GetPath()}: skinned points at time {t:g}"))
                if not samples.static:
                    self.store.set_points_samples(prim_id, samples.times, samples.values)
                    return
            except (EyeRenderError, SkinningError) as e:
                self._motion.warn(skinned.prim.GetPath(), "points", f"{e}: rendered without motion blur")
        self.store.set_points(prim_id, points)

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
            raise EyeRenderError(f"{prim.GetPath()}: eye:restTime = {rest_time} is outside its valid range: a finite "
                                 "time code")
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

    def _count_elements(self, prim_id, counts, indices, points):
        self._element_counts[prim_id] = {"constant": 1, "uniform": len(counts), "vertex": len(points),
                                         "varying": len(points), "faceVarying": len(indices)}

    def _push_primvar(self, prim, prim_id, name, source, time):
        """Sends primvar `source` of prim to the store under `name`, indices expanded; skips unauthored ones, and with
        one warning one whose element count does not fit the mesh (the mesh renders without it, as in Storm)."""
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
            self.warnings.append(f"{e}: ignored")
            return
        needed = self._element_counts.get(prim_id, {}).get(str(interpolation))
        if needed is not None and len(values) != needed:
            self._warn_once([f"{prim.GetPath()}: primvars:{source}: {interpolation} needs {needed} elements, got "
                             f"{len(values)}: ignored"])
            return
        self.store.set_primvar(prim_id, name, str(interpolation), values)

    def _add_gprim(self, prim, prim_id=None, world=None, instancer_id="", binding=None):
        tessellated = tessellate_gprim(prim, self.time)
        if tessellated is None:
            self.warnings.append(f"{prim.GetPath()}: {prim.GetTypeName()} is not rendered (not supported)")
            return False
        counts, indices, points = tessellated
        material_id, _ = self._bind_material(binding or prim)
        own = prim_id is None
        prim_id = prim.GetPath().pathString if own else prim_id
        self._rprims[prim_id] = prim.GetPath()
        world = self._world_of(prim) if world is None else world
        self.store.add_mesh(prim_id, counts, indices, points, _matrix(world), material_id, 0, False,
                            instancer_id=instancer_id)
        self._own_top_level(prim, prim_id)
        self._count_elements(prim_id, counts, indices, points)
        self._push_primvar(prim, prim_id, "displayColor", "displayColor", self.time)
        if own:
            self._track_transform(prim)
        self._track_visibility(prim, prim_id)
        return True

    def _add_curves_or_points(self, prim, prim_id=None, world=None, binding=None):
        """BasisCurves as tubes or ribbons, Points as spheres (curves.py); bad data raises EyeRenderError (the prim
        is skipped). prim_id, world, binding: an instance's copy of a prototype's prim (see add_instanced_prim)."""
        own = prim_id is None
        prim_id = prim.GetPath().pathString if own else prim_id
        material_id, _ = self._bind_material(binding or prim)
        add = curves.add_basis_curves if prim.IsA(UsdGeom.BasisCurves) else curves.add_points
        self._rprims[prim_id] = prim.GetPath()
        warn = lambda message: self._warn_once([message])  # noqa: E731
        world = self._world_of(prim) if world is None else world
        animated = add(self.store, prim, prim_id, _matrix(world), material_id, self.time, warn)
        self._own_top_level(prim, prim_id)
        if own:
            self._track_transform(prim)
        self._track_visibility(prim, prim_id)
        if _varies(animated):
            self._track(("points", lambda t: curves.update(self.store, prim, prim_id, t, warn)))

    # -- cameras, lights, materials, eyes ----------------------------------------------------------------------

    def _camera_params(self, camera, time):
        """A camera's CameraParams at `time` with the render's shutter (the render camera's; shutter.py)."""
        params = cameras.read_camera(camera, time)
        params.shutter_open, params.shutter_close = self.shutter.open, self.shutter.close
        return params

    def _add_camera(self, prim):
        camera = UsdGeom.Camera(prim)
        prim_id = prim.GetPath().pathString
        self.store.add_camera(prim_id, self._camera_params(camera, self.time), _matrix(self._world_of(prim)))
        self.cameras.append(prim_id)
        self._own(prim_id)
        if cameras.depth_of_field_note(camera, self.time):
            self.warnings.append(cameras.depth_of_field_note(camera, self.time))
        self._track_transform(prim)
        if _varies(prim.GetAttributes()):
            self._track(("camera", lambda t: self.store.set_camera_params(prim_id, self._camera_params(camera, t))))

    def _add_light(self, prim):
        prim_id = prim.GetPath().pathString
        self._lights[prim_id] = prim
        params = self._light_params(prim, self.time, self.warnings)
        self.store.add_light(prim_id, lights.light_type(prim), params, _matrix(self._world_of(prim)))
        self._own(prim_id)
        self.lights.append(prim_id)
        self.warnings.extend(lights.unsupported_light_features(prim, self.time))
        self._track_transform(prim)
        if _varies(prim.GetAttributes()):
            self._track(("light", lambda t: self.store.set_light_params(prim_id, self._light_params(prim, t))))

    def _bind_material(self, prim):
        """(material id, st primvar name) of prim's bound material, adding the material on first use."""
        material = materials.bound_material(prim, self.material_purposes)
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

    def _add_analytic_eye(self, prim, prim_id=None, world=None):
        own = prim_id is None
        prim_id = prim.GetPath().pathString if own else prim_id
        self._rprims[prim_id] = prim.GetPath()
        world = self._world_of(prim) if world is None else world
        self.store.add_analytic_eye(prim_id, eyes.read_eye_params(prim, self.time, self.cornea_model, self.warnings),
                                    _matrix(world))
        self.eyes.append(prim_id)
        self._own_top_level(prim, prim_id)
        if own:
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

