"""UsdGeom.Points as spheres (HdPoints; read by eyerender.curves, followed in time as curves are)."""
from pxr import UsdGeom

from .. import curves
from .basis_curves import BasisCurvesAdapter


class PointsAdapter(BasisCurvesAdapter):
    add = staticmethod(curves.add_points)

    @staticmethod
    def handles(prim):
        return prim.IsA(UsdGeom.Points)
