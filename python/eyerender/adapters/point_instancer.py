"""UsdGeom.PointInstancer as delegate instancers over its prototypes' prims (HdInstancer; instancing.py groups the
instances and follows them in time). Its prototypes are its children: the adapter handles them."""
from pxr import UsdGeom

from .base import PrimAdapter


class PointInstancerAdapter(PrimAdapter):

    @staticmethod
    def handles(prim):
        return prim.IsA(UsdGeom.PointInstancer)

    def populate(self, prim):
        self.delegate.instancing.add_point_instancer(prim)
        return True

    def process_property_change(self, prim, prim_id, kind):
        return False  # its copies are read again: re-populated
