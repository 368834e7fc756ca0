"""The interface every prim adapter implements (UsdImagingPrimAdapter's role, reduced to what this delegate needs).

An adapter turns one kind of USD prim into delegate prims in the scene store and keeps them current:

- `handles(prim)`: whether the prim is of its kind (the registry in __init__.py asks the adapters in order);
- `populate(prim)`: adds the prim at the delegate's current time and registers, through the delegate's
  `add_updater`, a callable for each aspect that varies in time (UsdImaging's TrackVariability; the callables are
  its UpdateForTime, run by `set_time`); returns whether the prim's children are handled too;
- `populate_instanced(...)`: adds a copy of a prototype's prim for an instancer (instancing.py);
- `process_property_change(prim, prim_id, kind)`: pushes one edited property in place (`kind`: one of
  stage_notices' kinds) and returns False when the prim must be populated again instead (UsdImaging's
  ProcessPropertyChange returning AllDirty);
- `forget(prim_id)`: drops what the adapter keeps about a delegate prim that was removed (ProcessPrimRemoval).

Adapters hold no reference to one another's state: what they share goes through the delegate's public interface
(usd_scene_delegate.UsdSceneDelegate documents it) and the other adapters' public methods (delegate.adapters).
"""
from pxr import UsdGeom

from ..stage_notices import TRANSFORM, VISIBILITY


class PrimAdapter:
    """The default adapter: transform and visibility edits in place, nothing kept per prim."""

    def __init__(self, delegate):
        self.delegate = delegate

    @staticmethod
    def handles(prim):
        return False

    def populate(self, prim):
        """Adds `prim` (and its updaters); returns True when its children are handled too (or must not render)."""
        raise NotImplementedError

    def populate_instanced(self, prim, prim_id, transform, instancer_id, binding):
        """Adds delegate prim `prim_id`, a copy of prototype prim `prim` (see UsdSceneDelegate.add_instanced_prim);
        returns False when it is not rendered (a warning says why)."""
        raise NotImplementedError(f"{type(self).__name__} has no instanced prims")

    def process_property_change(self, prim, prim_id, kind):
        """Sends the Set* call for a `kind` edit of owner prim `prim`; False when it cannot be taken in place."""
        d = self.delegate
        if kind == TRANSFORM:  # samples over the shutter where it moves within it
            d.push_transform(prim, prim_id)
        elif kind == VISIBILITY:
            d.store.set_visible(prim_id, UsdGeom.Imageable(prim).ComputeVisibility(d.time) != UsdGeom.Tokens.invisible)
        else:
            return False
        return True

    def forget(self, prim_id):
        """Drops what this adapter keeps about delegate prim `prim_id` (removed from the store)."""
