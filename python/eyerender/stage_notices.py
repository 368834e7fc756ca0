"""Following a stage's edits (UsdImagingDelegate's notice handling): a Usd.Notice.ObjectsChanged listener queues
what changed, and the scene delegate applies the queue before the next frame.

Resynced prim paths (prims added, removed, re-typed, re-referenced, activated) re-populate that subtree. Changed
properties (values changed, or properties created or removed) are classified by `property_kind` into the dirty
bits they set; a property the delegate cannot update in place re-populates its prim (correct, only slower).
"""
import collections

from pxr import Sdf, Tf, Usd, UsdGeom, UsdShade

from . import eyes, lights, materials, motion
from .errors import EyeRenderError
from .skinning import skel_root_of
from .validation import reading

# What a changed property updates; anything not listed re-populates its prim.
TRANSFORM, VISIBILITY, POINTS, PRIMVAR, EYE, PARAMS, RESYNC = \
    "transform", "visibility", "points", "primvar", "eye", "params", "resync"


def property_kind(name, is_light, is_camera, in_material):
    """The kind of update a change to property `name` needs (one of the constants above)."""
    if name == "xformOpOrder" or name.startswith("xformOp:"):
        return TRANSFORM
    if name == "visibility":
        return VISIBILITY
    if in_material or is_light or is_camera:
        return PARAMS
    if name.startswith("eye:"):
        return EYE
    if name == "points":
        return POINTS
    if name.startswith("primvars:") and not name.startswith("primvars:skel:") or name == "normals":
        return PRIMVAR
    if name == "extent":
        return None  # bounds do not change what renders
    return RESYNC


class StageChangeQueue:
    """Collects the paths a stage's ObjectsChanged notices name until `take()`. `revoke()` stops listening."""

    def __init__(self, stage):
        self._resynced, self._changed = set(), set()
        self._listener = Tf.Notice.Register(Usd.Notice.ObjectsChanged, self._on_objects_changed, stage)

    def _on_objects_changed(self, notice, sender):
        # As UsdImaging does: prims resync, properties update (a property created or removed is read again like a
        # changed value; the kind of update it needs decides whether its prim re-populates).
        for path in notice.GetResyncedPaths():
            (self._changed if path.IsPropertyPath() else self._resynced).add(path)
        for path in notice.GetChangedInfoOnlyPaths():
            if path.IsPropertyPath():
                self._changed.add(path)

    def pending(self):
        return bool(self._resynced or self._changed)

    def take(self):
        """(resynced prim paths with no resynced ancestor, sorted; changed property paths not under them)."""
        roots = []
        for path in sorted(self._resynced):
            if not any(path.HasPrefix(root) for root in roots):
                roots.append(path)
        changed = sorted(p for p in self._changed if not any(p.HasPrefix(root) for root in roots))
        self._resynced, self._changed = set(), set()
        return roots, changed

    def revoke(self):
        if self._listener is not None:
            self._listener.Revoke()
            self._listener = None


class StageFollowing:
    """The part of UsdSceneDelegate that applies a StageChangeQueue (its `_changes`) to the store; it uses the
    delegate's bookkeeping: `_owned` (owner prim path -> delegate prim ids), `_updaters` (owner, kind, update),
    `_instance_sources` (prim path an instancer reads -> its owners' paths), `_point_counts` (mesh id -> points
    sent), `_skipped` (owner paths skipped), `_add_subtree`, `_skip`, `raise_refused_eyes`, `_forget_id`,
    `warnings`, `_world_of`, `_link_light`, `_light_params`, the eye, camera and material readers, and the
    shutter's: `_motion` (this frame's motion.MotionSampler), `shutter`, `set_shutter`, `push_transform` and
    `push_points` (samples over the shutter where a prim moves within it)."""

    def apply_stage_changes(self):
        """Applies the stage edits made since the last call (or populate), as UsdImaging's delegate does on its
        ObjectsChanged notices: resynced paths are re-populated, value changes update in place. Returns (and keeps
        in last_changes) the counts by kind."""
        self.last_changes = collections.Counter()
        if not self._changes.pending():
            return self.last_changes
        resynced, changed = self._changes.take()
        self._xforms = UsdGeom.XformCache(self.time)
        self._motion = motion.MotionSampler(self.time, self.shutter, self.warnings, self._motion_warned)  # new values
        # Skinning reads a whole SkelRoot: an edit inside one re-populates it, with its UsdSkel cache rebuilt.
        for path in resynced + changed:
            root = skel_root_of(self._nearest_prim(path))
            if root:
                resynced.append(root.GetPath())
        changed = [p for p in changed if not skel_root_of(self._nearest_prim(p))]
        done = []
        for path in sorted(set(resynced)):
            for root in self._resync_roots(path):
                if not any(root.HasPrefix(d) for d in done):
                    self._resync(root)
                    done.append(root)
        for path in changed:
            if not any(path.HasPrefix(d) for d in done):
                try:
                    with reading(path):
                        self._apply_property_change(path)
                except EyeRenderError as e:  # a bad value where no prim owns it (a material): the edit only
                    if self.strict:  # an unreadable texture it brought in (its warning is above)
                        raise
                    self.warnings.append(f"{e} (edit ignored)")
        if self._shutter_at and self._shutter_at(self.time) != self.shutter:  # a camera's shutter was edited
            self.set_shutter(self._shutter_at)
        self.raise_refused_eyes()  # every edit applied first: the session stays in step with the stage
        return self.last_changes

    def _nearest_prim(self, path):
        """The prim at path's prim path, or its nearest existing ancestor (for paths just removed)."""
        path = path.GetPrimPath()
        while not self.stage.GetPrimAtPath(path) and path != Sdf.Path.absoluteRootPath:
            path = path.GetParentPath()
        return self.stage.GetPrimAtPath(path)

    def _resync_roots(self, *paths):
        """The paths to re-populate for a resync of `paths` (none under another): each one's nearest PointInstancer
        ancestor (which owns its prototypes), else itself; and, until none is left, the owner of every instancer
        that reads a prim at, above or under one of them (a prototype root elsewhere, a native instance) or the
        prototype of a native instance under one (so that a new instance joins its prototype's group)."""
        roots = []
        for path in paths:
            root = self._point_instancer_root(path)
            if not any(root.HasPrefix(r) for r in roots):
                roots = [r for r in roots if not r.HasPrefix(root)] + [root]
        prototypes = {}  # root -> the prototypes of the native instances under it
        grown = True
        while grown:
            grown = False
            for r in roots:
                if r not in prototypes:
                    prototypes[r] = self._prototypes_under(r)
            met = set().union(*(prototypes[r] for r in roots))
            for source, owners in self._instance_sources.items():
                if source not in met and not any(source.HasPrefix(r) or r.HasPrefix(source) for r in roots):
                    continue
                for owner in owners:
                    if not any(owner.HasPrefix(r) for r in roots):
                        roots = [r for r in roots if not r.HasPrefix(owner)] + [owner]
                        grown = True
        return sorted(roots)

    def _prototypes_under(self, path):
        """The prototype paths of the native instances at or under `path` (none when instances are flattened)."""
        prim = self.stage.GetPrimAtPath(path)
        if not prim or self._instancing.flatten:
            return set()
        found = set()
        it = iter(Usd.PrimRange(prim))
        for p in it:
            if p.IsInstance():
                found.add(p.GetPrototype().GetPath())
                it.PruneChildren()
        return found

    def _point_instancer_root(self, path):
        """path's nearest PointInstancer ancestor, else path."""
        prim = self.stage.GetPrimAtPath(path)
        p = prim if prim else None
        while p and not p.IsPseudoRoot():
            if p.IsA(UsdGeom.PointInstancer):
                return p.GetPath()
            p = p.GetParent()
        return path

    def _instanced_roots(self, path, inherited):
        """The paths to re-populate when a property of the prim at `path` changes because instancers read it: the
        owners of those that read it or an ancestor (a prototype, a native instance) and, for an inherited property
        (`inherited`: transform, visibility), those reading a prim under it that are not themselves under it (the
        ones under it re-populate as its other owners do); none when no instancer reads it."""
        owners = set()
        for source, source_owners in self._instance_sources.items():
            if path.HasPrefix(source):
                owners |= source_owners
            elif inherited and source.HasPrefix(path):
                owners |= {o for o in source_owners if not o.HasPrefix(path)}
        return self._resync_roots(*sorted(owners)) if owners else []

    def _resync(self, path):
        """Removes every delegate prim added for prims at or under `path`, then re-adds what the stage holds there."""
        removed = 0
        for owner in [o for o in self._owned if o.HasPrefix(path)]:
            for prim_id in self._owned.pop(owner):
                self.store.remove_prim(prim_id)
                removed += 1
                self._forget_id(prim_id)
        self._updaters = [u for u in self._updaters if not u[0].HasPrefix(path)]
        for source in list(self._instance_sources):
            owners = {o for o in self._instance_sources[source] if not o.HasPrefix(path)}
            if owners:
                self._instance_sources[source] = owners
            else:
                del self._instance_sources[source]
        self._skinning.remove_under(path)
        self._skipped = {o for o in self._skipped if not o.HasPrefix(path)}
        before = sum(len(ids) for ids in self._owned.values())
        prim = self.stage.GetPrimAtPath(path)
        if prim and prim.IsActive() and not self._pruned_above(prim):
            self._add_subtree(prim)
            if self._motion.blurred:  # populate pushed the frame's values: the samples over the shutter
                for owner, kind, update in self._updaters:
                    if kind in motion.MOTION_KINDS and owner.HasPrefix(path):
                        update(self.time)
        added = sum(len(ids) for ids in self._owned.values()) - before
        for kind, count in (("removed prims", removed), ("added prims", added)):
            if count:
                self.last_changes[kind] += count

    def _pruned_above(self, prim):
        """Whether populate would not have reached prim: an ancestor is inactive, a PointInstancer, or of a
        purpose not rendered."""
        p = prim.GetParent()
        while p and not p.IsPseudoRoot():
            imageable = UsdGeom.Imageable(p)
            if not p.IsActive() or p.IsA(UsdGeom.PointInstancer) or \
                    (imageable and imageable.ComputePurpose() not in self.purposes):
                return True
            p = p.GetParent()
        return False

    def _apply_property_change(self, path):
        """Pushes one changed property value to the store through the Set* call its kind needs."""
        prim = self.stage.GetPrimAtPath(path.GetPrimPath())
        if not prim:
            return
        # A skipped prim at, under or above the edit may render now: populated again (and skipped again if not).
        for owner in [o for o in self._skipped if o.HasPrefix(prim.GetPath()) or prim.GetPath().HasPrefix(o)]:
            for root in self._resync_roots(owner):
                self._resync(root)
        material = next((m for m in self._materials if path.HasPrefix(Sdf.Path(m))), None)
        kind = property_kind(path.name, bool(lights.light_type(prim)), prim.IsA(UsdGeom.Camera), material is not None)
        if kind is None:
            return
        instanced = [] if material else self._instanced_roots(prim.GetPath(), inherited=kind in (TRANSFORM, VISIBILITY))
        if instanced:  # instancers read it (a prototype's prim, a native instance): their instances are read again
            for root in instanced:
                self._resync(root)
            self.last_changes["instancer"] += 1
            if kind not in (TRANSFORM, VISIBILITY) or any(prim.GetPath().HasPrefix(r) for r in instanced):
                return
        attr = prim.GetAttribute(path.name)
        if attr and attr.ValueMightBeTimeVarying() and material is None:
            # Now animated: what set_time re-reads was decided at populate, so the prim (and what inherits from
            # it) is populated again, with its updaters.
            for root in self._resync_roots(prim.GetPath()):
                self._resync(root)
            return
        if material is not None:
            self.store.set_material_params(material, materials.read_material(
                UsdShade.Material(self.stage.GetPrimAtPath(material)), self.time)[0])
        elif kind in (TRANSFORM, VISIBILITY):  # inherited: every prim below follows
            for owner in [o for o in self._owned if o.HasPrefix(prim.GetPath())]:
                self._refresh(self.stage.GetPrimAtPath(owner), kind)
            if kind == TRANSFORM:
                self._refresh_iris_projections()
        elif prim.GetPath() in self._owned:
            self._refresh(prim, kind)
        else:
            return  # a prim that renders nothing (an Xform's own attribute, an unused material)
        self.last_changes[kind] += 1

    def _refresh(self, prim, kind):
        """Re-reads one aspect (a kind above) of an owner prim into the store; what cannot be updated in place (a
        PointInstancer's copies, topology, primvar layout, a skinned mesh's inputs) re-populates the prim."""
        prim_id = prim.GetPath().pathString
        in_place = prim_id in self._owned.get(prim.GetPath(), []) and not prim.IsA(UsdGeom.PointInstancer)
        try:
            with reading(prim.GetPath()):
                done = in_place and self._refresh_in_place(prim, prim_id, kind)
        except EyeRenderError as e:  # the edit made the prim unrenderable: skipped, as populate would
            self._skip(prim.GetPath(), e)
            return
        if not done:
            self._resync(prim.GetPath())

    def _refresh_in_place(self, prim, prim_id, kind):
        """Sends the Set* call for `kind`; False when this prim cannot take it in place."""
        is_light = bool(lights.light_type(prim))
        if kind == TRANSFORM:  # samples over the shutter where it moves within it
            self.push_transform(prim, prim_id)
        elif kind == VISIBILITY:
            self.store.set_visible(prim_id, UsdGeom.Imageable(prim).ComputeVisibility(self.time) !=
                                   UsdGeom.Tokens.invisible)
        elif kind == PARAMS and is_light:  # its link collections may be what changed
            self._link_light(prim_id, prim)
            self.store.set_light_params(prim_id, self._light_params(prim, self.time))
        elif kind == PARAMS and prim.IsA(UsdGeom.Camera):
            self.store.set_camera_params(prim_id, self._camera_params(UsdGeom.Camera(prim), self.time))
        elif kind == EYE and eyes.is_eye(prim):
            self.store.set_eye_params(prim_id, self._eye_mesh_params(prim, self.time) if prim.IsA(UsdGeom.Mesh)
                                      else eyes.read_eye_params(prim, self.time, self.cornea_model))
        elif kind == POINTS and prim.IsA(UsdGeom.Mesh) and not self._skinning.get(prim):
            points = UsdGeom.Mesh(prim).GetPointsAttr().Get(self.time)
            if points is None or len(points) != self._point_counts.get(prim_id):
                return False  # a new point count needs new topology
            self.push_points(prim, prim_id)
        else:
            return False
        return True

    def _refresh_iris_projections(self):
        """Eye meshes' iris projections are transforms relative to the eye: any moved prim may be a target."""
        for eye_id in self.eyes:
            prim = self.stage.GetPrimAtPath(eye_id)
            if prim and prim.IsA(UsdGeom.Mesh) and self._iris_projection_target(prim) is not None:
                self.store.set_eye_params(eye_id, self._eye_mesh_params(prim, self.time))


__all__ = ["StageChangeQueue", "StageFollowing", "property_kind"]
