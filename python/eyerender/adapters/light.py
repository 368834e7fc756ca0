"""UsdLux lights as delegate lights (HdLight), with their light and shadow link collections resolved over the
rprims once every rprim is known; the light kinds the delegate cannot render are skipped with one warning."""
from .. import lights
from ..stage_notices import PARAMS
from ..usd_values import to_matrix as _matrix
from ..usd_values import varies as _varies
from .base import PrimAdapter


class LightAdapter(PrimAdapter):

    def __init__(self, delegate):
        super().__init__(delegate)
        self.prims = {}          # light prim path -> its prim
        self.link_excludes = {}  # light prim path -> (not lit, not shadowing) rprim ids, where linked

    @staticmethod
    def handles(prim):
        return bool(lights.light_type(prim) or lights.skipped_light(prim))

    def populate(self, prim):
        d = self.delegate
        if not lights.light_type(prim):
            d.warnings.append(lights.skipped_light(prim))
            return False
        prim_id = prim.GetPath().pathString
        self.prims[prim_id] = prim
        params = self.params(prim, d.time, d.warnings)
        d.store.add_light(prim_id, lights.light_type(prim), params, _matrix(d.world_of(prim)))
        d.own_prim(prim_id)
        d.lights.append(prim_id)
        d.warnings.extend(lights.unsupported_light_features(prim, d.time))
        d.track_transform(prim)
        if _varies(prim.GetAttributes()):
            d.add_updater("light", lambda t: d.store.set_light_params(prim_id, self.params(prim, t)))
        return False

    def link_all(self):
        """Resolves each light's light and shadow link collections over the rprims, once every rprim is known (after
        populate and after every re-population by a stage edit, which may add or remove rprims)."""
        for prim_id, prim in self.prims.items():
            if self.link(prim_id, prim):
                self.delegate.store.set_light_params(prim_id, self.params(prim, self.delegate.time))

    def link(self, prim_id, prim):
        """Re-resolves one light's link collections into link_excludes; returns whether they changed."""
        excludes = lights.link_excludes(prim, self.delegate.rprims)
        before = self.link_excludes.pop(prim_id, None)
        if any(excludes):
            self.link_excludes[prim_id] = excludes
        return self.link_excludes.get(prim_id) != before

    def params(self, prim, time, warnings=None):
        """A light's LightParams at `time` with the rprims its link collections leave out (texture warnings go to
        `warnings`, a list, if given)."""
        return lights.with_links(lights.read_light(prim, time, warnings),
                                 self.link_excludes.get(prim.GetPath().pathString))

    def process_property_change(self, prim, prim_id, kind):
        if kind == PARAMS:  # its link collections may be what changed
            self.link(prim_id, prim)
            self.delegate.store.set_light_params(prim_id, self.params(prim, self.delegate.time))
            return True
        return super().process_property_change(prim, prim_id, kind)

    def forget(self, prim_id):
        self.prims.pop(prim_id, None)
        self.link_excludes.pop(prim_id, None)
