"""The USD scene delegate (UsdImagingDelegate's role): populates the hdeye render index from a Usd.Stage and keeps
it current as time moves.

Every supported prim becomes one delegate prim with the same path, added by the adapter of its kind (adapters/, one
per prim kind as in UsdImaging: this module keeps the traversal, the adapter registry and the bookkeeping they
share); instances (PointInstancers, instanceable prims) become hdeye instancers over prototype prims added once
(instancing.py). `populate` reads the stage once at the current time; `set_time` re-reads only what may vary in time
(attributes with time samples, transforms under animated xforms) and pushes it through the scene store's Set* calls,
which mark exactly the matching dirty bits. What each `set_time` pushed is counted in `last_update`. Under a shutter
that spans time (`set_shutter`), what moves is pushed as samples over it through the *_samples calls (motion.py).
Edits made to the stage after `populate` are queued by a Usd.Notice.ObjectsChanged listener and applied by
`apply_stage_changes` (stage_notices.py, counted in `last_changes`); UsdSkel skinning comes from skinning.py.
docs/usd_support.md tables what is read and how.

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

from pxr import Usd, UsdGeom, UsdSkel

from . import eye_rigs, eyes, materials, motion, stage_notices
from .adapters import AdapterRegistry
from .errors import EyeRenderError
from .instancing import Instancing
from .shutter import SHARP
from .skinning import SkinningError, StageSkinning
from .textures import TextureWarning
from .usd_values import to_matrix as _matrix
from .usd_values import varies as _varies
from .validation import check_transform, reading


class UsdSceneDelegate:
    """Populates a SceneStore from a Usd.Stage (see the module doc).

    It keeps the traversal, the adapter registry (`adapters`, adapters/__init__.py) and the bookkeeping the adapters,
    instancing.py and the stage follower (stage_notices.py) share, all public:

    - `owned`: owner prim path (Sdf.Path) -> the delegate prim ids it added; `own_prim` adds to the current owner
      (the prim being added, or the one `owning` names), `own_top_level` for a prim added for itself;
    - `updaters`: [(owner prim path, kind, update(time))] for what varies in time (`add_updater`), run by set_time;
    - `instance_sources`: prim path an instancer reads -> the owner paths it re-populates (`owning`);
    - `skipped`: owner paths skipped (a later edit may fix them: stage_notices re-adds them);
    - `rprims`: rprim id -> the prim path it came from (light linking's membership);
    - `cameras`, `eyes`, `lights`: delegate prim ids, in traversal order; `warnings`: one line each;
    - the frame's readers: `time`, `xform_cache`, `motion_sampler`, `shutter`, `skinning` (StageSkinning), and
      `world_of`, `transform_varies`, `track_transform`, `push_transform`, `track_visibility`, `warn_once`.
    """

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
        self.xform_cache = UsdGeom.XformCache(self.time)
        self.updaters = []       # (owner prim path, kind, callable(time)) for what varies in time
        self.owned = {}          # owner prim path -> delegate prim ids it added
        # Instanced rprims: the prim they were made from, the prim whose material they bind, and each instance's
        # name (cryptomatte.py); an rprim of a prim of its own is named by its id, the prim's path.
        self.instanced_prims = {}  # rprim id -> (prim, binding prim)
        self.instance_names = {}  # rprim id -> [name of instance 0, 1, ...]
        self._owner = None       # the prim _add_prim is adding
        self.instance_sources = {}  # prim path an instancer reads -> owner prim paths it re-populates (owning)
        self.skipped = set()     # owner prim paths skipped (a later edit may fix them: stage_notices re-adds)
        self._refused_eyes = []  # errors of eyes that could not be rendered: raised when this read ends
        self.follower = stage_notices.StageFollower(self)  # applies the stage's edits (apply_stage_changes)
        self.skinning = StageSkinning(self.warnings)  # filled as populate meets SkelRoots
        self._rigs = None        # eye_rigs.EyeRigs: the cornea shells left out, found by populate
        self._warned = set()     # warnings given once per stage (mesh_topology's)
        self.rprims = {}         # rprim id -> the prim path it came from (light linking's membership)
        self._populated = False
        self.instancing = Instancing(self, flatten=flatten_instances)
        self.adapters = AdapterRegistry(self)
        self.shutter = SHARP       # the render's shutter at the current time (shutter.py)
        self.shutter_at = None     # callable(Usd.TimeCode) -> Shutter, from set_shutter
        self._motion_warned = set()  # (prim path, kind) motion warnings given
        self.motion_sampler = motion.MotionSampler(self.time, SHARP)  # this frame's (shutter interval, caches)

    # -- public ------------------------------------------------------------------------------------------------

    def populate(self):
        if self._populated:
            raise RuntimeError("populate() was already called")
        self._populated = True
        self._rigs = eye_rigs.EyeRigs(self.stage, self.warnings, self.time)
        self.populate_subtree(self.stage.GetPseudoRoot())
        self._rigs.warn_look_alikes(list(self.adapters.mesh.points.counts))
        self.follower.discard_pending()  # edits before now are in what was just read
        self.raise_refused_eyes()

    @property
    def cornea_shells(self):
        """{shell mesh path: eye prim path} of the cornea shells left out (eye:corneaShell; eye_rigs.py)."""
        return dict(self._rigs.shell_of) if self._rigs else {}

    @property
    def flatten_instances(self):
        """Whether every instance is its own prims (no shared instancers)."""
        return self.instancing.flatten

    @property
    def last_changes(self):
        """What the last apply_stage_changes did, by kind (a Counter)."""
        return self.follower.last_changes

    def apply_stage_changes(self):
        """Applies the stage edits made since the last call (or populate): stage_notices.StageFollower.apply."""
        return self.follower.apply()

    def populate_subtree(self, root):
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
                    if prim.IsInstance() and not self.instancing.flatten:
                        self.instancing.add_native_instance(prim)
                        handled = True
                    else:
                        handled = self._add_prim(prim)
            except EyeRenderError as e:  # this prim cannot be rendered: the rest of the stage still can
                self.skip(prim.GetPath(), e)
                handled = True
            if handled:
                it.PruneChildren()
        self.instancing.finish()
        unreadable = [w for w in self.warnings[known:] if isinstance(w, TextureWarning)]
        if self.strict and unreadable:
            raise EyeRenderError(str(unreadable[0]).split("; ")[0])
        self.adapters.light.link_all()

    def skip(self, owner, error):
        """Drops what prim `owner` added (it failed part-way through, or an edit made it unreadable) with one
        warning ending '(skipped)'. An eye is never skipped: its error is raised when this read of the stage ends
        (raise_refused_eyes), as rendering the shot without it would hide the problem in a plausible image."""
        self._forget(owner)
        self.skipped.add(owner)
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
        `own_prim` records it), its updaters, and its ids in the lists and the adapters' tables."""
        for prim_id in dict.fromkeys(self.owned.pop(owner, []) + [owner.pathString]):
            self.store.remove_prim(prim_id)
            self.forget_id(prim_id)
        self.updaters = [u for u in self.updaters if u[0] != owner]

    def set_time(self, time):
        """Moves to `time`, pushing only what varies; returns (and keeps in last_update) the counts by kind."""
        self.time = Usd.TimeCode(time)
        self.xform_cache.SetTime(self.time)
        self.last_update = collections.Counter()
        self._follow_shutter()
        with reading(f"time {self.time.GetValue():g}"):
            for _, kind, update in self.updaters:
                update(self.time)
                self.last_update[kind] += 1
        return self.last_update

    def set_shutter(self, shutter_at):
        """Renders under the shutter shutter_at(Usd.TimeCode) gives (a shutter.Shutter) at each frame: every
        camera's CameraParams carry it, and what moves within it is pushed as samples (motion.py). Re-pushes what
        moves at the current time when the shutter spans time; a sharp shutter changes nothing."""
        self.shutter_at = shutter_at
        before = self.shutter
        self._follow_shutter()
        if self.motion_sampler.blurred or before.blurred:
            with reading(f"time {self.time.GetValue():g}"):
                for _, kind, update in self.updaters:
                    if kind in motion.MOTION_KINDS:
                        update(self.time)
        return self.shutter

    def _follow_shutter(self):
        """The shutter and motion sampler of the current time; cameras re-pushed when the shutter changed."""
        shutter = self.shutter_at(self.time) if self.shutter_at else SHARP
        self.motion_sampler = motion.MotionSampler(self.time, shutter, self.warnings, self._motion_warned)
        if shutter != self.shutter:
            self.shutter = shutter
            self.adapters.camera.push_all()

    def reread_time(self):
        """New XformCache and motion sampler at the current time and shutter (the stage's values were edited)."""
        self.xform_cache = UsdGeom.XformCache(self.time)
        self.motion_sampler = motion.MotionSampler(self.time, self.shutter, self.warnings, self._motion_warned)

    def add_updater(self, kind, update, owner=None):
        """Registers update(time), called by set_time and counted under `kind` in last_update; owned by `owner`
        (default: the prim being added, see owning): re-populating the owner drops it."""
        self.updaters.append((owner or self._owner, kind, update))

    def own_prim(self, prim_id):
        """Owns delegate prim `prim_id` by the current owner (the prim being added, or the one `owning` names)."""
        self.owned.setdefault(self._owner, []).append(prim_id)

    def own_top_level(self, prim, prim_id):
        """Owns a prim added for itself (an instance copy is owned by add_instanced_prim, as its instancer is)."""
        if prim_id == prim.GetPath().pathString:
            self.own_prim(prim_id)

    def forget_id(self, prim_id):
        """Drops a removed delegate prim from the lists and the adapters' tables that name it."""
        for ids in (self.eyes, self.cameras, self.lights):
            if prim_id in ids:
                ids.remove(prim_id)
        self.rprims.pop(prim_id, None)
        for adapter in self.adapters:
            adapter.forget(prim_id)

    def warn_once(self, warnings):
        """Adds warnings not given yet (a prototype's mesh is added once per point-instanced copy)."""
        self.warnings.extend(w for w in warnings if w not in self._warned and not self._warned.add(w))

    # -- dispatch ----------------------------------------------------------------------------------------------

    def _add_prim(self, prim):
        """Adds a prim through its kind's adapter; returns True when its children are handled too (or must not be
        rendered)."""
        self._owner = prim.GetPath()
        if self._rigs is not None and self._rigs.is_shell(prim):  # the analytic cornea replaces it
            return True
        if prim.IsA(UsdSkel.Root):  # its skinned prims, before they are added
            self.skinning.add_root(prim)
        adapter = self.adapters.for_prim(prim)
        return adapter.populate(prim) if adapter is not None else False

    # -- what instancing.py uses --------------------------------------------------------------------------------

    @contextlib.contextmanager
    def owning(self, owner, sources=()):
        """Within it, every delegate prim and updater added (instancers included, see own_prim) belongs to prim path
        `owner` and goes when it re-populates; an edit at, above or under a path in `sources` (prototype roots and
        instance prims the owner reads) re-populates the owner (stage_notices.py)."""
        previous, self._owner = self._owner, owner
        for source in sources:
            self.instance_sources.setdefault(source, set()).add(owner)
        try:
            yield
        finally:
            self._owner = previous

    def is_cornea_shell(self, prim):
        """Whether prim is an eye's cornea shell, left out of the render index (eye_rigs.py)."""
        return bool(prim) and self._rigs is not None and self._rigs.is_shell(prim)

    def add_instanced_prim(self, prim, prim_id, transform, instancer_id, binding):
        """A prim of an instance prototype (instancing.py): `transform` is relative to the instancer's instances
        (or the world, with no instancer_id); `binding`: the prim whose bound material it gets. One that cannot be
        rendered is left out with one warning; the rest of the prototype still renders."""
        self.instanced_prims[prim_id] = (prim, binding or prim)
        updaters = len(self.updaters)
        try:
            with reading(prim.GetPath()):
                if not self.adapters.for_prim(prim).populate_instanced(prim, prim_id, transform, instancer_id,
                                                                       binding):
                    return
        except EyeRenderError as e:
            self.store.remove_prim(prim_id)  # whatever part of it was added
            self.forget_id(prim_id)
            del self.updaters[updaters:]
            instanced = binding is not None and binding.GetPath() != prim.GetPath()
            if eyes.is_eye(prim):  # never skipped (see skip)
                where = f" (instanced as {binding.GetPath()})" if instanced else ""
                self._refused_eyes.append(EyeRenderError(f"{e}{where}"))
            else:
                self.warn_once([f"{e} (skipped{f'; instanced as {binding.GetPath()}' if instanced else ''})"])
            return
        self.own_prim(prim_id)  # by the instancer's owner (owning): a copy is not its prim's own

    # -- transforms and visibility, for every adapter ---------------------------------------------------------------

    def world_of(self, prim, time=None, cache=None):
        """prim's local-to-world transform at `time` (a time code, default the current time; `cache`: the
        XformCache at it), skinned when it or an ancestor is rigidly bound to a joint; raises EyeRenderError for
        one no prim can use (validation.check_transform)."""
        time, cache = (self.time, self.xform_cache) if time is None else (Usd.TimeCode(time), cache)
        try:
            world = self.skinning.world(prim, cache, time)
        except SkinningError as e:
            self.skinning.drop(self.skinning.rigid_anchor(prim), e)
            world = cache.GetLocalToWorldTransform(prim)
        what = "transform" if time == self.time else f"transform at time {time.GetValue():g}"
        return check_transform(prim.GetPath(), world, what)

    def transform_varies(self, prim):
        """Whether prim's local-to-world transform may change: animated xform ops, or animated joints it or an
        ancestor is rigidly bound to."""
        anchor = self.skinning.rigid_anchor(prim)
        return (anchor is not None and anchor.might_vary(self.xforms_vary)) or self.xforms_vary(prim)

    @staticmethod
    def xforms_vary(prim):
        """Whether prim's own or an ancestor's xform ops are animated."""
        p = prim
        while p and not p.IsPseudoRoot():
            xformable = UsdGeom.Xformable(p)
            if xformable and xformable.TransformMightBeTimeVarying():
                return True
            p = p.GetParent()
        return False

    def track_transform(self, prim):
        """Registers prim's transform updater where it may vary."""
        if self.transform_varies(prim):
            prim_id = prim.GetPath().pathString
            kind = "transform" if self.skinning.rigid_anchor(prim) is None else "skinned transform"
            self.add_updater(kind, lambda t: self.push_transform(prim, prim_id))

    def push_transform(self, prim, prim_id):
        """Sends prim's transform at the current time: its samples over the shutter when it spans time and the
        prim moves within it, else the one value (a sample that cannot be used: one warning, sharp)."""
        sampler = self.motion_sampler
        if sampler.blurred:
            try:
                anchor = self.skinning.rigid_anchor(prim)
                extra = motion.skinning_times(anchor, sampler.interval()) if anchor is not None else ()
                samples = motion.transform_samples(sampler, prim, lambda t, cache: self.world_of(prim, t, cache),
                                                   extra)
                if not samples.static:
                    self.store.set_transform_samples(prim_id, samples.times, samples.values)
                    return
            except EyeRenderError as e:
                sampler.warn(prim.GetPath(), "transform", f"{e}: rendered without motion blur")
        self.store.set_transform(prim_id, _matrix(self.world_of(prim)))

    def track_visibility(self, prim, prim_id):
        """Hides an invisible prim and registers its visibility updater where it or an ancestor's varies."""
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
                self.add_updater("visibility", lambda t: self.store.set_visible(
                    prim_id, imageable.ComputeVisibility(t) != UsdGeom.Tokens.invisible))
                break
            p = p.GetParent()
