"""UsdGeom.Camera as a delegate camera (HdCamera): its CameraParams carry the render's shutter (shutter.py)."""
from pxr import UsdGeom

from .. import cameras
from ..stage_notices import PARAMS
from ..usd_values import to_matrix as _matrix
from ..usd_values import varies as _varies
from .base import PrimAdapter


class CameraAdapter(PrimAdapter):

    @staticmethod
    def handles(prim):
        return prim.IsA(UsdGeom.Camera)

    def params(self, camera, time):
        """A camera's CameraParams at `time` with the render's shutter (the render camera's; shutter.py)."""
        params = cameras.read_camera(camera, time)
        params.shutter_open, params.shutter_close = self.delegate.shutter.open, self.delegate.shutter.close
        return params

    def populate(self, prim):
        d = self.delegate
        camera = UsdGeom.Camera(prim)
        prim_id = prim.GetPath().pathString
        d.store.add_camera(prim_id, self.params(camera, d.time), _matrix(d.world_of(prim)))
        d.cameras.append(prim_id)
        d.own_prim(prim_id)
        if cameras.depth_of_field_note(camera, d.time):
            d.warnings.append(cameras.depth_of_field_note(camera, d.time))
        d.track_transform(prim)
        if _varies(prim.GetAttributes()):
            d.add_updater("camera", lambda t: d.store.set_camera_params(prim_id, self.params(camera, t)))
        return False

    def push_all(self):
        """Re-sends every camera's params at the current time (the shutter changed)."""
        d = self.delegate
        for prim_id in d.cameras:
            d.store.set_camera_params(prim_id, self.params(UsdGeom.Camera(d.stage.GetPrimAtPath(prim_id)), d.time))

    def process_property_change(self, prim, prim_id, kind):
        if kind == PARAMS:
            self.delegate.store.set_camera_params(prim_id, self.params(UsdGeom.Camera(prim), self.delegate.time))
            return True
        return super().process_property_change(prim, prim_id, kind)
