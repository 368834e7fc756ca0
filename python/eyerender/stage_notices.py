"""Following a stage's edits (UsdImagingDelegate's notice handling): a Usd.Notice.ObjectsChanged listener queues
what changed, and the scene delegate applies the queue before the next frame.

Resynced prim paths (prims added, removed, re-typed, re-referenced, activated) re-populate that subtree. Changed
properties (values changed, or properties created or removed) are classified by `property_kind` into the dirty
bits they set; a property the delegate cannot update in place re-populates its prim (correct, only slower).
"""
import collections

from pxr import Sdf, Tf, Usd, UsdGeom

from . import lights, motion
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


class StageFollower:
    """Applies a stage's edits to a UsdSceneDelegate's store (UsdImagingDelegate's change processing), through the
    delegate's public bookkeeping (usd_scene_delegate.py lists it: `owned`, `updaters`, `instance_sources`,
    `skipped`, `populate_subtree`, `skip`, `forget_id`, ...) and its adapters' process_property_change."""

    def __init__(self, delegate):
        self.delegate = delegate
        self.queue = StageChangeQueue(delegate.stage)
        self.last_changes = collections.Counter()  # what the last apply did, by kind

    def discard_pending(self):
        """Forgets the edits queued so far (populate has just read them)."""
        self.queue.take()

    def apply(self):
        """Applies the stage edits made since the last call (or populate), as UsdImaging's delegate does on its
        ObjectsChanged notices: resynced paths are re-populated, value changes update in place. Returns (and keeps
        in last_changes) the counts by kind."""
        d = self.delegate
        self.last_changes = collections.Counter()
        if not self.queue.pending():
            return self.last_changes
        resynced, changed = self.queue.take()
        d.reread_time()  # new values
        # Skinning reads a whole SkelRoot: an edit inside one re-populates it, with its UsdSkel cache rebuilt.
        for path in resynced + changed:
            root = skel_root_of(self._nearest_prim(path))
            if root:
                resynced.append(root.GetPath())
        changed = [p for p in changed if not skel_root_of(self._nearest_prim(p))]
        done = []
        for path in sorted(set(resynced)):
            for root in self._resync_roots(path):
                if not any(root.HasPrefix(r) for r in done):
                    self._resync(root)
                    done.append(root)
        for path in changed:
            if not any(path.HasPrefix(r) for r in done):
                try:
                    with reading(path):
                        self._apply_property_change(path)
                except EyeRenderError as e:  # a bad value where no prim owns it (a material): the edit only
                    if d.strict:  # an unreadable texture it brought in (its warning is above)
                        raise
                    d.warnings.append(f"{e} (edit ignored)")
        if d.shutter_at and d.shutter_at(d.time) != d.shutter:  # a camera's shutter was edited
            d.set_shutter(d.shutter_at)
        d.raise_refused_eyes()  # every edit applied first: the session stays in step with the stage
        return self.last_changes

    def _nearest_prim(self, path):
        """The prim at path's prim path, or its nearest existing ancestor (for paths just removed)."""
        d = self.delegate
        path = path.GetPrimPath()
        while not d.stage.GetPrimAtPath(path) and path != Sdf.Path.absoluteRootPath:
            path = path.GetParentPath()
        return d.stage.GetPrimAtPath(path)

    def _resync_roots(self, *paths):
        """The paths to re-populate for a resync of `paths` (none under another): each one's nearest PointInstancer
        ancestor (which owns its prototypes), else itself; and, until none is left, the owner of every instancer
        that reads a prim at, above or under one of them (a prototype root elsewhere, a native instance) or the
        prototype of a native instance under one (so that a new instance joins its prototype's group)."""
        d = self.delegate
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
            for source, owners in d.instance_sources.items():
                if source not in met and not any(source.HasPrefix(r) or r.HasPrefix(source) for r in roots):
                    continue
                for owner in owners:
                    if not any(owner.HasPrefix(r) for r in roots):
                        roots = [r for r in roots if not r.HasPrefix(owner)] + [owner]
                        grown = True
        return sorted(roots)

    def _prototypes_under(self, path):
        """The prototype paths of the native instances at or under `path` (none when instances are flattened)."""
        d = self.delegate
        prim = d.stage.GetPrimAtPath(path)
        if not prim or d.flatten_instances:
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
        d = self.delegate
        prim = d.stage.GetPrimAtPath(path)
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
        d = self.delegate
        owners = set()
        for source, source_owners in d.instance_sources.items():
            if path.HasPrefix(source):
                owners |= source_owners
            elif inherited and source.HasPrefix(path):
                owners |= {o for o in source_owners if not o.HasPrefix(path)}
        return self._resync_roots(*sorted(owners)) if owners else []

    def _resync(self, path):
        """Removes every delegate prim added for prims at or under `path`, then re-adds what the stage holds there."""
        d = self.delegate
        removed = 0
        for owner in [o for o in d.owned if o.HasPrefix(path)]:
            for prim_id in d.owned.pop(owner):
                d.store.remove_prim(prim_id)
                removed += 1
                d.forget_id(prim_id)
        d.updaters = [u for u in d.updaters if not u[0].HasPrefix(path)]
        for source in list(d.instance_sources):
            owners = {o for o in d.instance_sources[source] if not o.HasPrefix(path)}
            if owners:
                d.instance_sources[source] = owners
            else:
                del d.instance_sources[source]
        d.skinning.remove_under(path)
        d.skipped = {o for o in d.skipped if not o.HasPrefix(path)}
        before = sum(len(ids) for ids in d.owned.values())
        prim = d.stage.GetPrimAtPath(path)
        if prim and prim.IsActive() and not self._pruned_above(prim):
            d.populate_subtree(prim)
            if d.motion_sampler.blurred:  # populate pushed the frame's values: the samples over the shutter
                for owner, kind, update in d.updaters:
                    if kind in motion.MOTION_KINDS and owner.HasPrefix(path):
                        update(d.time)
        added = sum(len(ids) for ids in d.owned.values()) - before
        for kind, count in (("removed prims", removed), ("added prims", added)):
            if count:
                self.last_changes[kind] += count

    def _pruned_above(self, prim):
        """Whether populate would not have reached prim: an ancestor is inactive, a PointInstancer, or of a
        purpose not rendered."""
        d = self.delegate
        p = prim.GetParent()
        while p and not p.IsPseudoRoot():
            imageable = UsdGeom.Imageable(p)
            if not p.IsActive() or p.IsA(UsdGeom.PointInstancer) or \
                    (imageable and imageable.ComputePurpose() not in d.purposes):
                return True
            p = p.GetParent()
        return False

    def _apply_property_change(self, path):
        """Pushes one changed property value to the store through the Set* call its kind needs."""
        d = self.delegate
        prim = d.stage.GetPrimAtPath(path.GetPrimPath())
        if not prim:
            return
        # A skipped prim at, under or above the edit may render now: populated again (and skipped again if not).
        for owner in [o for o in d.skipped if o.HasPrefix(prim.GetPath()) or prim.GetPath().HasPrefix(o)]:
            for root in self._resync_roots(owner):
                self._resync(root)
        material = d.adapters.material.material_at(path)
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
            d.adapters.material.push(material)
        elif kind in (TRANSFORM, VISIBILITY):  # inherited: every prim below follows
            for owner in [o for o in d.owned if o.HasPrefix(prim.GetPath())]:
                self._refresh(d.stage.GetPrimAtPath(owner), kind)
            if kind == TRANSFORM:
                d.adapters.eye.refresh_iris_projections()
        elif prim.GetPath() in d.owned:
            self._refresh(prim, kind)
        else:
            return  # a prim that renders nothing (an Xform's own attribute, an unused material)
        self.last_changes[kind] += 1

    def _refresh(self, prim, kind):
        """Re-reads one aspect (a kind above) of an owner prim into the store; what cannot be updated in place (a
        PointInstancer's copies, topology, primvar layout, a skinned mesh's inputs) re-populates the prim."""
        d = self.delegate
        prim_id = prim.GetPath().pathString
        in_place = prim_id in d.owned.get(prim.GetPath(), []) and not prim.IsA(UsdGeom.PointInstancer)
        try:
            with reading(prim.GetPath()):
                done = in_place and self._refresh_in_place(prim, prim_id, kind)
        except EyeRenderError as e:  # the edit made the prim unrenderable: skipped, as populate would
            d.skip(prim.GetPath(), e)
            return
        if not done:
            self._resync(prim.GetPath())

    def _refresh_in_place(self, prim, prim_id, kind):
        """Sends the Set* call for `kind` through the prim's adapter; False when it cannot take it in place."""
        adapter = self.delegate.adapters.for_prim(prim)
        return adapter is not None and adapter.process_property_change(prim, prim_id, kind)


__all__ = ["StageChangeQueue", "StageFollower", "property_kind"]
